/* The page's server, through libmicrohttpd: fixed routes only (nothing
 * from the request reaches the file system), a thread per connection with
 * the connections bounded (in all and per address), each request's memory
 * bounded and idle connections closed.
 *
 *   GET /                the page (page.html)
 *   GET /events          Server-Sent Events: the state as JSON at each change
 *   GET /frame.png       the latest image, as the output's view shows it
 *   GET /exposure?stops=X  the page's exposure, on top of the output's
 *   GET /denoise?on=1|0  the page's denoised preview, on or off */
#include "live/live_module.h"

#include <errno.h>
#include <math.h>
#include <microhttpd.h>
#include <netdb.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

enum {
    CONNECTIONS = 32,          /* in all */
    CONNECTIONS_PER_IP = 16,
    TIMEOUT_SECONDS = 10,      /* idle connections close */
    REQUEST_SECONDS = 10,      /* from a connection or a response to the next request's end */
    MEMORY_PER_CONNECTION = 16 * 1024, /* a request's headers and more */
    THREAD_STACK = 256 * 1024,
    KEEPALIVE_SECONDS = 2,
    EVENT_SIZE = 1024,
    FRAME_BLOCK = 4096,        /* a /frame.png response's writes, within the memory above */
};

/* One connection, from its start to its close. */
typedef struct Connection {
    int fd;
    double deadline; /* for the request under way to be read; 0: answering one */
    struct Connection *next;
} Connection;

/* The connections, for the watchdog. */
typedef struct Http {
    pthread_mutex_t lock;
    pthread_cond_t wake;
    Connection *connections;
    pthread_t watchdog;
    int stop;
} Http;

static void notify_connection(void *cls, struct MHD_Connection *connection,
                              void **socket_context, enum MHD_ConnectionNotificationCode code)
{
    Http *http = ((PtrLiveSession *)cls)->http;
    if (code == MHD_CONNECTION_NOTIFY_STARTED) {
        const union MHD_ConnectionInfo *info =
            MHD_get_connection_info(connection, MHD_CONNECTION_INFO_CONNECTION_FD);
        Connection *c = info ? calloc(1, sizeof *c) : NULL;
        if (!c)
            return; /* unwatched: the idle timeout still holds */
        c->fd = info->connect_fd;
        c->deadline = ptr_live_now() + REQUEST_SECONDS;
        pthread_mutex_lock(&http->lock);
        c->next = http->connections;
        http->connections = c;
        pthread_mutex_unlock(&http->lock);
        *socket_context = c;
    } else if (*socket_context) {
        /* Before libmicrohttpd closes the socket: once off the list, the
         * watchdog never touches its descriptor. */
        pthread_mutex_lock(&http->lock);
        for (Connection **at = &http->connections; *at; at = &(*at)->next)
            if (*at == *socket_context) {
                *at = (*at)->next;
                break;
            }
        pthread_mutex_unlock(&http->lock);
        free(*socket_context);
        *socket_context = NULL;
    }
}

/* A request was read (answering): 0; a response was sent: the next
 * request has REQUEST_SECONDS. */
static void set_deadline(PtrLiveSession *s, struct MHD_Connection *connection, double deadline)
{
    Http *http = s->http;
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(connection, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    Connection *c = info ? info->socket_context : NULL;
    if (!c)
        return;
    pthread_mutex_lock(&http->lock);
    c->deadline = deadline;
    pthread_mutex_unlock(&http->lock);
}

static void request_completed(void *cls, struct MHD_Connection *connection, void **request,
                              enum MHD_RequestTerminationCode code)
{
    (void)request;
    (void)code;
    set_deadline(cls, connection, ptr_live_now() + REQUEST_SECONDS);
}

static void *watch_requests(void *arg)
{
    Http *http = arg;
    pthread_mutex_lock(&http->lock);
    while (!http->stop) {
        struct timespec t;
        clock_gettime(CLOCK_MONOTONIC, &t);
        t.tv_nsec += 500000000L;
        if (t.tv_nsec >= 1000000000L) {
            t.tv_sec++;
            t.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&http->wake, &http->lock, &t);
        double now = ptr_live_now();
        for (Connection *c = http->connections; c; c = c->next)
            if (c->deadline > 0 && now > c->deadline) {
                shutdown(c->fd, SHUT_RDWR); /* the connection's thread sees it and closes */
                c->deadline = now + REQUEST_SECONDS;
            }
    }
    pthread_mutex_unlock(&http->lock);
    return NULL;
}

static Http *http_new(void)
{
    Http *http = calloc(1, sizeof *http);
    if (!http)
        return NULL;
    pthread_mutex_init(&http->lock, NULL);
    ptr_live_cond_init(&http->wake);
    if (pthread_create(&http->watchdog, NULL, watch_requests, http)) {
        pthread_cond_destroy(&http->wake);
        pthread_mutex_destroy(&http->lock);
        free(http);
        return NULL;
    }
    return http;
}

static void http_free(Http *http)
{
    if (!http)
        return;
    pthread_mutex_lock(&http->lock);
    http->stop = 1;
    pthread_cond_broadcast(&http->wake);
    pthread_mutex_unlock(&http->lock);
    pthread_join(http->watchdog, NULL);
    pthread_cond_destroy(&http->wake);
    pthread_mutex_destroy(&http->lock);
    free(http);
}

/* One /events stream. */
typedef struct Stream {
    PtrLiveSession *session;
    uint64_t event; /* the last one sent */
    struct Stream *next; /* in session->streams */
} Stream;

int ptr_live_http_pages_behind(const PtrLiveSession *s)
{
    for (const Stream *stream = s->streams; stream; stream = stream->next)
        if (stream->event != s->event)
            return 1;
    return 0;
}

static void json_string(char *out, size_t size, const char *text)
{
    size_t n = 0;
    for (const unsigned char *c = (const unsigned char *)text; *c && n + 7 < size; c++) {
        if (*c == '"' || *c == '\\')
            n += (size_t)snprintf(out + n, size - n, "\\%c", *c);
        else if (*c < 0x20)
            n += (size_t)snprintf(out + n, size - n, "\\u%04x", *c);
        else
            out[n++] = (char)*c;
    }
    out[n] = '\0';
}

static const char *state_name(int state)
{
    return state == PTR_LIVE_DONE ? "done" : state == PTR_LIVE_FAILED ? "stopped" : "rendering";
}

/* One event with the whole state (the lock held). */
static int format_event(const PtrLiveSession *s, char *buf, size_t size)
{
    char scene[2 * sizeof s->scene], output[2 * sizeof s->output];
    json_string(scene, sizeof scene, s->scene);
    json_string(output, sizeof output, s->output);
    const PtrLiveStatus *st = &s->status;
    return snprintf(buf, size,
                    "data: {\"render\":%llu,\"scene\":\"%s\",\"output\":\"%s\",\"width\":%d,"
                    "\"height\":%d,\"frame\":%llu,\"samples\":%u,\"total\":%u,"
                    "\"elapsed\":%.2f,\"remaining\":%.2f,\"mrays\":%.2f,\"state\":\"%s\","
                    "\"stops\":%g,\"preview\":%s,\"denoised\":%s}\n\n",
                    (unsigned long long)s->render, scene, output, s->width, s->height,
                    (unsigned long long)s->png_id, st->samples_done, st->samples_total,
                    st->elapsed, st->remaining, st->mrays_per_second, state_name(st->state),
                    (double)s->stops, s->preview_denoised ? "true" : "false",
                    s->png_denoised ? "true" : "false");
}

static ssize_t read_events(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    Stream *stream = cls;
    PtrLiveSession *s = stream->session;
    pthread_mutex_lock(&s->lock);
    if (stream->event == s->event && !s->stopping)
        ptr_live_wait(s, KEEPALIVE_SECONDS);
    ssize_t n;
    if (stream->event != s->event) { /* even when stopping: the last state too */
        char event[EVENT_SIZE];
        int len = format_event(s, event, sizeof event);
        if (len > 0 && (size_t)len < sizeof event && (size_t)len <= max) {
            memcpy(buf, event, (size_t)len);
            stream->event = s->event;
            n = len;
            pthread_cond_broadcast(&s->changed); /* stop() waits for the last one */
        } else {
            n = 0; /* no room now: again at the next call */
        }
    } else if (s->stopping) {
        n = MHD_CONTENT_READER_END_OF_STREAM;
    } else {
        static const char keepalive[] = ": keepalive\n\n";
        n = max >= sizeof keepalive - 1 ? (ssize_t)(sizeof keepalive - 1) : 0;
        memcpy(buf, keepalive, (size_t)n);
    }
    pthread_mutex_unlock(&s->lock);
    return n;
}

static void close_events(void *cls)
{
    Stream *stream = cls;
    PtrLiveSession *s = stream->session;
    pthread_mutex_lock(&s->lock);
    s->pages--;
    for (Stream **at = (Stream **)&s->streams; *at; at = &(*at)->next)
        if (*at == stream) {
            *at = stream->next;
            break;
        }
    pthread_cond_broadcast(&s->changed);
    pthread_mutex_unlock(&s->lock);
    free(stream);
}

static enum MHD_Result send_response(struct MHD_Connection *connection, unsigned status,
                                     struct MHD_Response *response, const char *type)
{
    if (!response)
        return MHD_NO;
    if (type)
        MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    MHD_add_response_header(response, "X-Content-Type-Options", "nosniff");
    enum MHD_Result r = MHD_queue_response(connection, status, response);
    MHD_destroy_response(response);
    return r;
}

static enum MHD_Result send_text(struct MHD_Connection *connection, unsigned status,
                                 const char *text)
{
    return send_response(connection, status,
                         MHD_create_response_from_buffer(strlen(text), (void *)text,
                                                         MHD_RESPMEM_PERSISTENT),
                         "text/plain; charset=utf-8");
}

/* A setting taken: no content. */
static enum MHD_Result send_done(struct MHD_Connection *connection)
{
    return send_response(connection, MHD_HTTP_NO_CONTENT,
                         MHD_create_response_from_buffer(0, NULL, MHD_RESPMEM_PERSISTENT), NULL);
}

static enum MHD_Result serve_page(struct MHD_Connection *connection)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(
        strlen(ptr_live_page), (void *)ptr_live_page, MHD_RESPMEM_PERSISTENT);
    if (r)
        MHD_add_response_header(r, "Content-Security-Policy",
                                "default-src 'self'; script-src 'unsafe-inline'; "
                                "style-src 'unsafe-inline'; img-src 'self' blob:");
    return send_response(connection, MHD_HTTP_OK, r, "text/html; charset=utf-8");
}

static enum MHD_Result serve_events(PtrLiveSession *s, struct MHD_Connection *connection)
{
    Stream *stream = calloc(1, sizeof *stream);
    if (!stream)
        return MHD_NO;
    stream->session = s;
    struct MHD_Response *r =
        MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, EVENT_SIZE, read_events, stream,
                                          close_events);
    if (!r) {
        free(stream);
        return MHD_NO;
    }
    pthread_mutex_lock(&s->lock);
    s->pages++;
    stream->next = s->streams;
    s->streams = stream;
    pthread_cond_broadcast(&s->changed); /* the encoder has a page to encode for */
    pthread_mutex_unlock(&s->lock);
    return send_response(connection, MHD_HTTP_OK, r, "text/event-stream");
}

/* A /frame.png response: a copy of the PNG, counted in frames_sending
 * until the server releases it (sent in full, or the connection gone), so
 * that stopping waits for the last image to leave instead of cutting it
 * off when it closes the connections. */
typedef struct FrameResponse {
    PtrLiveSession *session;
    unsigned char *png;
    size_t size;
    int denoised;
} FrameResponse;

static ssize_t read_frame(void *cls, uint64_t pos, char *buf, size_t max)
{
    const FrameResponse *f = cls;
    if (pos >= f->size)
        return MHD_CONTENT_READER_END_OF_STREAM;
    size_t n = f->size - (size_t)pos < max ? f->size - (size_t)pos : max;
    memcpy(buf, f->png + pos, n);
    return (ssize_t)n;
}

static void release_frame(void *cls)
{
    FrameResponse *f = cls;
    PtrLiveSession *s = f->session;
    pthread_mutex_lock(&s->lock);
    s->frames_sending--;
    pthread_cond_broadcast(&s->changed); /* stop() waits for the last one */
    pthread_mutex_unlock(&s->lock);
    free(f->png);
    free(f);
}

static enum MHD_Result serve_frame(PtrLiveSession *s, struct MHD_Connection *connection)
{
    FrameResponse *f = malloc(sizeof *f);
    pthread_mutex_lock(&s->lock);
    unsigned char *copy = f && s->png ? malloc(s->png_size) : NULL;
    size_t size = s->png_size;
    if (copy) {
        memcpy(copy, s->png, size);
        if (s->png_frame > s->served_frame)
            s->served_frame = s->png_frame;
        s->frames_sending++;
        pthread_cond_broadcast(&s->changed);
    }
    int none = !s->png, denoised = s->png_denoised;
    pthread_mutex_unlock(&s->lock);
    if (!copy) {
        free(f);
        return none ? send_text(connection, MHD_HTTP_NOT_FOUND, "no image yet\n") : MHD_NO;
    }
    *f = (FrameResponse){ s, copy, size, denoised };
    struct MHD_Response *r =
        MHD_create_response_from_callback(size, FRAME_BLOCK, read_frame, f, release_frame);
    if (!r)
        release_frame(f);
    else
        MHD_add_response_header(r, "X-Ptr-Denoised", denoised ? "1" : "0");
    return send_response(connection, MHD_HTTP_OK, r, "image/png");
}

static enum MHD_Result set_exposure(PtrLiveSession *s, struct MHD_Connection *connection)
{
    const char *text = MHD_lookup_connection_value(connection, MHD_GET_ARGUMENT_KIND, "stops");
    char *end;
    double stops = text ? strtod(text, &end) : NAN;
    if (!text || end == text || *end || !(fabs(stops) <= 16))
        return send_text(connection, MHD_HTTP_BAD_REQUEST, "stops: a number from -16 to 16\n");
    pthread_mutex_lock(&s->lock);
    if ((float)stops != s->stops) {
        s->stops = (float)stops;
        s->stops_version++;
        s->event++;
        pthread_cond_broadcast(&s->changed);
    }
    pthread_mutex_unlock(&s->lock);
    return send_done(connection);
}

static enum MHD_Result set_preview(PtrLiveSession *s, struct MHD_Connection *connection)
{
    const char *text = MHD_lookup_connection_value(connection, MHD_GET_ARGUMENT_KIND, "on");
    if (!text || (strcmp(text, "0") && strcmp(text, "1")))
        return send_text(connection, MHD_HTTP_BAD_REQUEST, "on: 1 or 0\n");
    pthread_mutex_lock(&s->lock);
    int on = text[0] == '1';
    if (on != s->preview_denoised) {
        s->preview_denoised = on;
        s->event++;
        pthread_cond_broadcast(&s->changed);
    }
    pthread_mutex_unlock(&s->lock);
    return send_done(connection);
}

static enum MHD_Result handle(void *cls, struct MHD_Connection *connection, const char *url,
                              const char *method, const char *version, const char *upload_data,
                              size_t *upload_data_size, void **request)
{
    (void)version;
    (void)upload_data;
    static int seen;
    PtrLiveSession *s = cls;
    if (strcmp(method, MHD_HTTP_METHOD_GET) && strcmp(method, MHD_HTTP_METHOD_HEAD)) {
        set_deadline(s, connection, 0);
        return send_text(connection, MHD_HTTP_METHOD_NOT_ALLOWED, "GET only\n");
    }
    if (!*request) { /* the headers: answer once any body has arrived */
        *request = &seen;
        set_deadline(s, connection, 0);
        return MHD_YES;
    }
    if (*upload_data_size)
        return MHD_NO; /* no route takes a body: close */
    if (!strcmp(url, "/"))
        return serve_page(connection);
    if (!strcmp(url, "/events"))
        return serve_events(s, connection);
    if (!strcmp(url, "/frame.png"))
        return serve_frame(s, connection);
    if (!strcmp(url, "/exposure"))
        return set_exposure(s, connection);
    if (!strcmp(url, "/denoise"))
        return set_preview(s, connection);
    return send_text(connection, MHD_HTTP_NOT_FOUND, "not found\n");
}

static int is_loopback(const struct sockaddr *a)
{
    if (a->sa_family == AF_INET)
        return (ntohl(((const struct sockaddr_in *)a)->sin_addr.s_addr) >> 24) == 127;
    if (a->sa_family == AF_INET6) {
        const struct in6_addr *v6 = &((const struct sockaddr_in6 *)a)->sin6_addr;
        return IN6_IS_ADDR_LOOPBACK(v6) ||
               (IN6_IS_ADDR_V4MAPPED(v6) && v6->s6_addr[12] == 127);
    }
    return 0;
}

/* Binds and listens at the address given, the socket into *out: PTR_OK,
 * else PTR_ERR_USAGE. */
static PtrResult bind_socket(const char *option, char *host, const char *port, int *family,
                             char *url, size_t url_size, int *out, PtrError *err)
{
    struct addrinfo hints = { .ai_socktype = SOCK_STREAM, .ai_flags = AI_NUMERICSERV }, *list;
    int gai = getaddrinfo(host, port, &hints, &list);
    if (gai)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s: cannot use host '%s': %s", option, host,
                              gai_strerror(gai));
    int fd = -1, why = 0;
    for (struct addrinfo *a = list; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
        if (fd < 0) {
            why = errno;
            continue;
        }
        int one = 1;
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        if (bind(fd, a->ai_addr, a->ai_addrlen) || listen(fd, CONNECTIONS)) {
            why = errno;
            close(fd);
            fd = -1;
            continue;
        }
        *family = a->ai_family;
        if (!is_loopback(a->ai_addr))
            fprintf(stderr, "ptr: warning: %s %s:%s is not the loopback address: anyone who "
                            "can reach this machine can see the render\n", option, host, port);
    }
    freeaddrinfo(list);
    if (fd < 0)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s %s:%s: %s%s", option, host, port,
                              strerror(why),
                              why == EADDRINUSE ? " (another program listens there; try another "
                                                  "port, or 0 for a free one)" : "");
    struct sockaddr_storage bound;
    socklen_t len = sizeof bound;
    char name[1025] = "", service[32] = "";
    if (getsockname(fd, (struct sockaddr *)&bound, &len) == 0)
        getnameinfo((struct sockaddr *)&bound, len, name, sizeof name, service, sizeof service,
                    NI_NUMERICHOST | NI_NUMERICSERV);
    snprintf(url, url_size, strchr(name, ':') ? "http://[%s]:%s/" : "http://%s:%s/", name,
             service);
    *out = fd;
    return PTR_OK;
}

PtrResult ptr_live_http_start(PtrLiveSession *s, PtrError *err)
{
    char host[256], port[16];
    int family = AF_INET;
    PtrResult res = ptr_live_parse_address("--live", s->options.http, host, sizeof host, port,
                                           sizeof port, err);
    if (res != PTR_OK)
        return res;
    res = bind_socket("--live", host, port, &family, s->url, sizeof s->url, &s->listen_fd, err);
    if (res != PTR_OK)
        return res;
    s->http = http_new();
    if (!s->http) {
        close(s->listen_fd);
        s->listen_fd = -1;
        return ptr_error_set(err, PTR_ERR_NOMEM, "--live: out of memory");
    }
    unsigned flags = MHD_USE_THREAD_PER_CONNECTION | MHD_USE_INTERNAL_POLLING_THREAD;
    if (family == AF_INET6)
        flags |= MHD_USE_IPv6;
    s->daemon = MHD_start_daemon(
        flags, 0, NULL, NULL, handle, s,
        MHD_OPTION_LISTEN_SOCKET, (MHD_socket)s->listen_fd,
        MHD_OPTION_CONNECTION_LIMIT, (unsigned)CONNECTIONS,
        MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)CONNECTIONS_PER_IP,
        MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)TIMEOUT_SECONDS,
        MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)MEMORY_PER_CONNECTION,
        MHD_OPTION_THREAD_STACK_SIZE, (size_t)THREAD_STACK,
        MHD_OPTION_NOTIFY_CONNECTION, notify_connection, s,
        MHD_OPTION_NOTIFY_COMPLETED, request_completed, s,
        MHD_OPTION_END);
    if (!s->daemon) {
        http_free(s->http);
        s->http = NULL;
        close(s->listen_fd);
        s->listen_fd = -1;
        return ptr_error_set(err, PTR_ERR_INTERNAL, "--live %s: cannot start the server", s->url);
    }
    s->listen_fd = -1; /* the server's now: it closes it */
    return PTR_OK;
}

void ptr_live_http_stop(PtrLiveSession *s)
{
    if (s->daemon)
        MHD_stop_daemon(s->daemon);
    s->daemon = NULL;
    http_free(s->http);
    s->http = NULL;
    if (s->listen_fd >= 0)
        close(s->listen_fd);
    s->listen_fd = -1;
}
