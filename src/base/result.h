/* Result codes shared by every layer, and the process exit codes they map to.
 * One list generates the enum, the exit codes and the descriptions, so the
 * three cannot drift apart. */
#ifndef PTR_RESULT_H
#define PTR_RESULT_H

#ifdef __cplusplus
extern "C" {
#endif

/*        name                  exit  description */
#define PTR_RESULT_MAP(X)                                                     \
    X(PTR_OK,                   0,   "success")                               \
    X(PTR_ERR_INTERNAL,         1,   "internal error")                        \
    X(PTR_ERR_USAGE,            2,   "invalid command line")                  \
    X(PTR_ERR_SCENE_UNREADABLE, 3,   "scene file cannot be read")             \
    X(PTR_ERR_SCENE_INVALID,    4,   "scene file is malformed or invalid")    \
    X(PTR_ERR_OUTPUT,           5,   "output image cannot be written")        \
    X(PTR_ERR_NOMEM,            6,   "out of memory")                         \
    X(PTR_ERR_COLOR,            7,   "colour configuration cannot be used")  \
    X(PTR_ERR_INTERRUPTED,      8,   "interrupted: the image holds the samples done") \
    X(PTR_ERR_BATCH,            9,   "some scenes of a batch failed")          \
    X(PTR_ERR_INSTALL,          10,  "a module of ptr cannot be loaded (a broken installation)")

typedef enum PtrResult {
#define PTR_RESULT_ENUM(name, code, text) name,
    PTR_RESULT_MAP(PTR_RESULT_ENUM)
#undef PTR_RESULT_ENUM
    PTR_RESULT_COUNT
} PtrResult;

/* The process exit code for a result. */
int ptr_result_exit_code(PtrResult result);

/* A short description, e.g. for --help's list of exit codes. */
const char *ptr_result_description(PtrResult result);

/* Where an operation records what went wrong: the code plus a one-line
 * message that names the file and the problem. */
typedef struct PtrError {
    PtrResult code;
    char message[512];
} PtrError;

/* Fills err with code and a printf-formatted message, folding any newline
 * into a space so the message stays one line. Returns code. */
PtrResult ptr_error_set(PtrError *err, PtrResult code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#ifdef __cplusplus
}
#endif

#endif /* PTR_RESULT_H */
