#include "builder.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <emmintrin.h> /* SSE2, which every x86-64 CPU has */

#include "base/cpu.h"
#include "base/threads.h"

void ptr_builder_init(PtrSceneBuilder *builder, PtrScene *scene, const PtrImportOptions *options)
{
    memset(builder, 0, sizeof *builder);
    builder->scene = scene;
    builder->material_size = scene->spheres.material_size;
    atomic_init(&builder->lost, 0);
    if (options) {
        builder->override = options->camera;
        builder->auto_projection = options->auto_projection;
        builder->auto_aspect = options->auto_aspect;
        builder->orbit_degrees = options->orbit_degrees;
    }
}

/* The optional per-sphere arrays (bytes a sphere, and the bits of each
 * 4-byte word of a sphere that has none: see ptr_entries_fill): they exist
 * from the first sphere that has one. The attributes' entries are the
 * scene's (colours: 6 bytes, not 12 floats'). */
enum {
#define OPTIONAL_INDEX(name, type, per_sphere, none, hashed) OPTIONAL_##name,
    PTR_SPHERE_ATTRIBUTES(OPTIONAL_INDEX)
#undef OPTIONAL_INDEX
    OPTIONAL_VALUES
};
static const struct {
    size_t offset;
    size_t bytes;
    uint32_t none;
} optional_arrays[] = {
#define OPTIONAL_ENTRY(name, type, per_sphere, none, hashed)                               \
    [OPTIONAL_##name] = { offsetof(PtrSceneBuilder, name), (per_sphere) * sizeof(type), (none) },
    PTR_SPHERE_ATTRIBUTES(OPTIONAL_ENTRY)
#undef OPTIONAL_ENTRY
    [OPTIONAL_VALUES] = { offsetof(PtrSceneBuilder, values), sizeof(float), 0x7fc00000u }, /* NaN */
};

enum { OPTIONAL_ARRAYS = sizeof optional_arrays / sizeof optional_arrays[0] };

static void **optional_array(PtrSceneBuilder *b, size_t k)
{
    return (void **)((char *)b + optional_arrays[k].offset);
}

void ptr_builder_free(PtrSceneBuilder *builder)
{
    free(builder->spheres.data);
    free(builder->materials);
    builder->spheres = (PtrBuilderSpheres){ 0 };
    builder->materials = NULL;
    for (size_t k = 0; k < OPTIONAL_ARRAYS; k++) {
        free(*optional_array(builder, k));
        *optional_array(builder, k) = NULL;
    }
    builder->count = builder->capacity = 0;
}

/* Entries from .. to - 1 of optional array k get its value for none. */
static void fill_none(PtrSceneBuilder *b, size_t k, size_t from, size_t to)
{
    ptr_entries_fill(*optional_array(b, k), optional_arrays[k].bytes, optional_arrays[k].none,
                     from, to);
}

static PtrResult no_room(size_t count, PtrError *err)
{
    return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for %zu spheres", count);
}

/* Starts optional array k for the builder's capacity, its first filled
 * spheres none (the others are the caller's to fill). */
static PtrResult start_optional(PtrSceneBuilder *b, size_t k, size_t filled, PtrError *err)
{
    void **array = optional_array(b, k);
    *array = malloc((b->capacity ? b->capacity : 1) * optional_arrays[k].bytes);
    if (!*array)
        return no_room(b->capacity, err);
    fill_none(b, k, 0, filled);
    return PTR_OK;
}

/* Bytes of a sphere's centre and radius. */
static size_t sphere_bytes(const PtrSceneBuilder *b)
{
    return 4 * (b->spheres.wide ? sizeof(double) : sizeof(float));
}

/* Whether the builder can keep x, y, z and radius as they are: doubles
 * always, floats where each is one exactly (NaN is not, and so stays
 * NaN for the checks that refuse it). */
static int keeps(const PtrSceneBuilder *b, const double centre[3], double radius)
{
    return b->spheres.wide ||
           ((double)(float)centre[0] == centre[0] && (double)(float)centre[1] == centre[1] &&
            (double)(float)centre[2] == centre[2] && (double)(float)radius == radius);
}

static void set_sphere(PtrSceneBuilder *b, size_t i, const double centre[3], double radius)
{
    if (b->spheres.wide) {
        double *d = (double *)b->spheres.data + 4 * i;
        memcpy(d, centre, 3 * sizeof *d);
        d[3] = radius;
        return;
    }
    float *f = (float *)b->spheres.data + 4 * i;
    for (int k = 0; k < 3; k++)
        f[k] = (float)centre[k];
    f[3] = (float)radius;
}

/* Resizes every array to capacity spheres (count stays below it). */
static PtrResult resize(PtrSceneBuilder *b, size_t capacity, PtrError *err)
{
    if (capacity > SIZE_MAX / (4 * sizeof(double)))
        return no_room(capacity, err);
    const size_t entries = capacity ? capacity : 1;
    void *spheres = realloc(b->spheres.data, entries * sphere_bytes(b));
    if (!spheres)
        return no_room(capacity, err);
    b->spheres.data = spheres;
    void *materials = realloc(b->materials, entries * b->material_size);
    if (!materials)
        return no_room(capacity, err);
    b->materials = materials;
    for (size_t k = 0; k < OPTIONAL_ARRAYS; k++) {
        void **array = optional_array(b, k);
        if (!*array)
            continue;
        void *resized = realloc(*array, entries * optional_arrays[k].bytes);
        if (!resized)
            return no_room(capacity, err);
        *array = resized;
    }
    b->capacity = capacity;
    return PTR_OK;
}

PtrResult ptr_builder_reserve(PtrSceneBuilder *b, size_t count, PtrError *err)
{
    return count > b->capacity ? resize(b, count, err) : PTR_OK;
}

/* The builder's materials, read and written as the scene's are. */
static PtrSpheres material_column(const PtrSceneBuilder *b)
{
    return (PtrSpheres){ .material = b->materials, .material_size = b->material_size };
}

/* Makes the builder's material entries as wide as the scene's, which the
 * materials it gained since the last spheres were added may have widened:
 * at 10^8 spheres of at most 256 materials, 100 MB where 4-byte entries
 * took 400. */
static PtrResult widen_to_scene(PtrSceneBuilder *b, PtrError *err)
{
    const size_t size = b->scene->spheres.material_size;
    if (size <= b->material_size)
        return PTR_OK;
    void *wide = malloc((b->capacity ? b->capacity : 1) * size);
    if (!wide)
        return no_room(b->capacity, err);
    const PtrSpheres narrow = material_column(b);
    b->materials = wide;
    b->material_size = size;
    PtrSpheres to = material_column(b);
    ptr_spheres_copy_materials(&to, &narrow, b->count);
    free(narrow.material);
    return PTR_OK;
}

/* Makes the builder keep doubles: the floats of spheres 0 .. filled - 1
 * (those after hold nothing yet) become the doubles they were given as, in
 * place, from the last back (double k covers floats 2k and 2k + 1, read by
 * then; each through memcpy, which tells the compiler that a double's store
 * may change the floats it reads next). The spheres a lost fill left
 * unwritten are converted too, from whatever their bytes were: they are
 * filled again. */
static PtrResult widen_spheres(PtrSceneBuilder *b, size_t filled, PtrError *err)
{
    if (b->spheres.wide)
        return PTR_OK;
    const size_t entries = b->capacity ? b->capacity : 1;
    unsigned char *spheres = realloc(b->spheres.data, entries * 4 * sizeof(double));
    if (!spheres)
        return no_room(b->capacity, err);
    for (size_t k = 4 * (filled < b->count ? filled : b->count); k-- > 0;) {
        float f;
        memcpy(&f, spheres + k * sizeof f, sizeof f);
        const double d = f;
        memcpy(spheres + k * sizeof d, &d, sizeof d);
    }
    b->spheres = (PtrBuilderSpheres){ spheres, 1 };
    return PTR_OK;
}

PtrResult ptr_builder_refill(PtrSceneBuilder *b, size_t filled, int *refill, PtrError *err)
{
    *refill = atomic_load(&b->lost);
    if (!*refill)
        return PTR_OK;
    /* Lost stays set where widening fails: the spheres are not all kept. */
    const PtrResult r = widen_spheres(b, filled, err);
    if (r == PTR_OK)
        atomic_store(&b->lost, 0);
    return r;
}

PtrResult ptr_builder_fill_blocks(PtrSceneBuilder *b, size_t first, size_t count, int threads,
                                  void (*fill)(void *, size_t, size_t),
                                  int (*done)(void *, size_t, size_t), void *arg)
{
    for (size_t begin = 0; begin < count;) {
        const size_t end = ptr_builder_block_end(begin, count);
        ptr_parallel_ranges(threads, begin, end, fill, arg);
        int refill;
        if (ptr_builder_refill(b, first + end, &refill, NULL) != PTR_OK)
            return PTR_ERR_NOMEM;
        if (refill)
            continue;
        if (done && !done(arg, begin, end))
            break;
        begin = end;
    }
    return PTR_OK;
}

PtrResult ptr_builder_add_sphere(PtrSceneBuilder *b, const double centre[3], double radius,
                                 uint32_t material, PtrError *err)
{
    assert(material < b->scene->material_count);
    PtrResult r = widen_to_scene(b, err);
    if (r == PTR_OK && !keeps(b, centre, radius))
        r = widen_spheres(b, b->count, err);
    if (r != PTR_OK)
        return r;
    if (b->count == b->capacity) {
        r = resize(b, b->capacity ? 2 * b->capacity : 64, err);
        if (r != PTR_OK)
            return r;
    }
    for (size_t k = 0; k < OPTIONAL_ARRAYS; k++)
        if (*optional_array(b, k))
            fill_none(b, k, b->count, b->count + 1);
    set_sphere(b, b->count, centre, radius);
    PtrSpheres column = material_column(b);
    ptr_sphere_set_material(&column, b->count++, material);
    return PTR_OK;
}

PtrResult ptr_builder_add_spheres(PtrSceneBuilder *b, size_t count, int with_colors,
                                  size_t *first, PtrError *err)
{
    PtrResult r = widen_to_scene(b, err);
    if (r != PTR_OK)
        return r;
    if (b->count + count > b->capacity) {
        r = resize(b, b->count + count, err);
        if (r != PTR_OK)
            return r;
    }
    if (with_colors && !*optional_array(b, OPTIONAL_color)) {
        /* The earlier spheres only: the caller writes the new ones' (at
         * 10^8 spheres, 800 MB), and each later one fills its own. */
        r = start_optional(b, OPTIONAL_color, b->count, err);
        if (r != PTR_OK)
            return r;
    }
    for (size_t k = 0; k < OPTIONAL_ARRAYS; k++)
        if (*optional_array(b, k) && !(k == OPTIONAL_color && with_colors))
            fill_none(b, k, b->count, b->count + count);
    *first = b->count;
    b->count += count;
    return PTR_OK;
}

static void quantize_color(const double rgb[3], uint16_t *entry)
{
    ptr_color_quantize(v3((float)rgb[0], (float)rgb[1], (float)rgb[2]), entry);
}

void ptr_builder_fill_sphere(PtrSceneBuilder *b, size_t n, const double centre[3], double radius,
                             uint32_t material, const double *rgb)
{
    if (keeps(b, centre, radius))
        set_sphere(b, n, centre, radius);
    else
        atomic_store_explicit(&b->lost, 1, memory_order_relaxed);
    /* A material added since the spheres were would not fit their entries. */
    assert(material < b->scene->material_count);
    PtrSpheres column = material_column(b);
    ptr_sphere_set_material(&column, n, material);
    if (rgb)
        quantize_color(rgb, &b->color[3 * n]);
}

/* Optional array k's entry for the sphere added last, the array created if
 * it is the first. NULL if memory runs out. */
static void *last_entry(PtrSceneBuilder *b, size_t k)
{
    void **array = optional_array(b, k);
    const size_t bytes = optional_arrays[k].bytes;
    if (!*array) {
        *array = malloc(b->capacity * bytes);
        if (!*array)
            return NULL;
        fill_none(b, k, 0, b->capacity);
    }
    return (char *)*array + (b->count - 1) * bytes;
}

PtrResult ptr_builder_set_color(PtrSceneBuilder *b, const double rgb[3], PtrError *err)
{
    uint16_t *entry = last_entry(b, OPTIONAL_color);
    if (!entry)
        return no_room(b->capacity, err);
    quantize_color(rgb, entry);
    return PTR_OK;
}

PtrResult ptr_builder_set_value(PtrSceneBuilder *b, double value, PtrError *err)
{
    float *entry = last_entry(b, OPTIONAL_VALUES);
    if (!entry)
        return no_room(b->capacity, err);
    *entry = (float)value;
    return PTR_OK;
}

static void place_camera(PtrSceneBuilder *b, const double eye[3], const double target[3],
                         const double up[3], const PtrCamera *lens)
{
    memcpy(b->eye, eye, sizeof b->eye);
    memcpy(b->target, target, sizeof b->target);
    memcpy(b->up, up, sizeof b->up);
    b->lens = *lens;
    b->has_camera = 1;
}

void ptr_builder_set_camera(PtrSceneBuilder *b, const double eye[3], const double target[3],
                            const double up[3], const PtrCamera *lens)
{
    if (!b->override)
        place_camera(b, eye, target, up, lens);
}

PtrCamera ptr_camera_lens(const PtrCameraSpec *c)
{
    double d2 = 0;
    for (int k = 0; k < 3; k++)
        d2 += (c->lookat[k] - c->lookfrom[k]) * (c->lookat[k] - c->lookfrom[k]);
    return (PtrCamera){
        .projection = c->ortho_height > 0 ? PTR_PROJECTION_ORTHOGRAPHIC
                                          : PTR_PROJECTION_PERSPECTIVE,
        .vfov_deg = (float)c->vfov_deg, .aperture = (float)c->aperture,
        .focus_distance = (float)(c->focus_distance > 0 ? c->focus_distance : sqrt(d2)),
        .ymag = (float)(0.5 * c->ortho_height),
    };
}

static void use_override(PtrSceneBuilder *b)
{
    const PtrCameraSpec *c = b->override;
    const PtrCamera lens = ptr_camera_lens(c);
    place_camera(b, c->lookfrom, c->lookat, c->up, &lens);
}

/* Share of the image's height or width (whichever binds) the automatic
 * camera gives the spheres: a little margin, as molecular viewers leave. */
#define FRAME_FILL 0.95
#define DEG_TO_RAD (3.14159265358979323846 / 180.0)

/* Which spheres the framing, the turntable's axis and the choice of huge
 * spheres (below) consider: those whose radius is within SMALL_RATIO of the
 * smallest. A ground of radius 1000 under spheres of 0.5 is not what a
 * camera should frame. */
#define SMALL_RATIO 16.0

/* fmin and fmax for the loops over every sphere: inline where the library's
 * are calls (they order NaN, which no sphere that renders has). */
static inline double least(double a, double b) { return b < a ? b : a; }
static inline double most(double a, double b) { return b > a ? b : a; }

/* The passes below over every sphere run on all cores, a result a piece
 * (ptr_parallel_pieces), taken in the pieces' order: minima and maxima,
 * and the huge choice (choose_huge), which do not depend on how the spheres
 * are grouped. (NaN aside, where the framed box may differ: add_sphere
 * refuses such a scene either way.) */
enum { PIECES_MAX = 64 };

/* Runs fn over the builder's spheres in pieces, one a thread; returns how
 * many pieces. */
static size_t over_pieces(const PtrSceneBuilder *b,
                          void (*fn)(void *arg, size_t piece, size_t from, size_t to), void *arg)
{
    const int threads = ptr_usable_cpus();
    const size_t pieces = threads < PIECES_MAX ? (size_t)threads : PIECES_MAX;
    ptr_parallel_pieces(threads, b->count, pieces, fn, arg);
    return pieces;
}

/* The smallest and the largest radius. */
typedef struct Radii {
    double smallest, largest;
} Radii;

typedef struct RadiiPass {
    PtrBuilderSpheres spheres;
    Radii radii[PIECES_MAX];
} RadiiPass;

static void radii_of_piece(void *arg, size_t piece, size_t from, size_t to)
{
    RadiiPass *p = arg;
    Radii r = { INFINITY, -INFINITY };
    const PtrBuilderSpheres spheres = p->spheres;
    for (size_t i = from; i < to; i++) {
        double s[4];
        ptr_builder_sphere(spheres, i, s);
        r.smallest = least(r.smallest, s[3]);
        r.largest = most(r.largest, s[3]);
    }
    p->radii[piece] = r;
}

static Radii radii_of(const PtrSceneBuilder *b)
{
    RadiiPass p = { .spheres = b->spheres };
    const size_t pieces = over_pieces(b, radii_of_piece, &p);
    Radii r = { INFINITY, -INFINITY };
    for (size_t k = 0; k < pieces; k++) {
        r.smallest = least(r.smallest, p.radii[k].smallest);
        r.largest = most(r.largest, p.radii[k].largest);
    }
    return r;
}

/* The origin of the file's coordinates, for the passes that run before the
 * scene's origin is known (and for the scene's, when not recentred). */
static const double world_origin[3] = { 0, 0, 0 };

static int is_framed(double radius, double smallest)
{
    return !(radius > SMALL_RATIO * smallest);
}

typedef struct BoxPass {
    PtrBuilderSpheres spheres;
    const double *origin; /* the box is of the spheres less this */
    double smallest;
    double lo[PIECES_MAX][3], hi[PIECES_MAX][3];
    int any[PIECES_MAX];
} BoxPass;

/* Two lanes at a time, in SSE2 registers: x and y, then z and the radius
 * (that lane unused). _mm_min_pd(v, box) and _mm_max_pd(v, box) are
 * least(box, v) and most(box, v) lane by lane, and the box starts from its
 * first sphere, so it has the scalar fold's bits for every value but NaN
 * (whose sign and payload the compiler may choose either way; add_sphere
 * refuses such a sphere). The scalar fold took 1.6 times as long: the pass
 * compares and selects more than it reads (10^7 spheres, 320 MB: 60 ms on
 * one thread in scalar code, 37 ms so; reading the radii alone takes 27). */
static void box_of_piece(void *arg, size_t piece, size_t from, size_t to)
{
    BoxPass *p = arg;
    const __m128d origin_xy = _mm_loadu_pd(p->origin), origin_z = _mm_set_pd(0.0, p->origin[2]);
    __m128d lo_xy = _mm_setzero_pd(), lo_z = lo_xy, hi_xy = lo_xy, hi_z = lo_xy;
    int any = 0;
    const PtrBuilderSpheres spheres = p->spheres;
    for (size_t i = from; i < to; i++) {
        /* Loaded as vectors: the four doubles stored one by one and loaded
         * two at a time took two and a half times as long. */
        __m128d xy, zr;
        if (spheres.wide) {
            xy = _mm_loadu_pd((const double *)spheres.data + 4 * i);
            zr = _mm_loadu_pd((const double *)spheres.data + 4 * i + 2);
        } else {
            const __m128 f = _mm_loadu_ps((const float *)spheres.data + 4 * i);
            xy = _mm_cvtps_pd(f);
            zr = _mm_cvtps_pd(_mm_movehl_ps(f, f));
        }
        const __m128d r = _mm_unpackhi_pd(zr, zr);
        if (!is_framed(_mm_cvtsd_f64(r), p->smallest))
            continue;
        const __m128d c_xy = _mm_sub_pd(xy, origin_xy);
        const __m128d c_z = _mm_sub_pd(zr, origin_z);
        const __m128d l_xy = _mm_sub_pd(c_xy, r), l_z = _mm_sub_pd(c_z, r);
        const __m128d h_xy = _mm_add_pd(c_xy, r), h_z = _mm_add_pd(c_z, r);
        lo_xy = any ? _mm_min_pd(l_xy, lo_xy) : l_xy;
        lo_z = any ? _mm_min_pd(l_z, lo_z) : l_z;
        hi_xy = any ? _mm_max_pd(h_xy, hi_xy) : h_xy;
        hi_z = any ? _mm_max_pd(h_z, hi_z) : h_z;
        any = 1;
    }
    _mm_storeu_pd(p->lo[piece], lo_xy);
    _mm_storel_pd(&p->lo[piece][2], lo_z);
    _mm_storeu_pd(p->hi[piece], hi_xy);
    _mm_storel_pd(&p->hi[piece][2], hi_z);
    p->any[piece] = any;
}

/* The box around the spheres the framing considers (smallest: the smallest
 * radius), their centres taken relative to origin (as add_sphere takes
 * them: each centre less origin, in double, then the radius); 0 if there
 * are none. */
static int framed_box(const PtrSceneBuilder *b, double smallest, const double origin[3],
                      double lo[3], double hi[3])
{
    BoxPass p = { .spheres = b->spheres, .origin = origin, .smallest = smallest };
    const size_t pieces = over_pieces(b, box_of_piece, &p);
    int any = 0;
    for (size_t piece = 0; piece < pieces; piece++) {
        if (!p.any[piece])
            continue;
        for (int k = 0; k < 3; k++) {
            lo[k] = any ? least(lo[k], p.lo[piece][k]) : p.lo[piece][k];
            hi[k] = any ? most(hi[k], p.hi[piece][k]) : p.hi[piece][k];
        }
        any = 1;
    }
    return any;
}

typedef struct PlanesPass {
    PtrBuilderSpheres spheres;
    double smallest, ca, sa;
    int axis;
    double hi[PIECES_MAX], lo[PIECES_MAX];
} PlanesPass;

static void planes_of_piece(void *arg, size_t piece, size_t from, size_t to)
{
    PlanesPass *p = arg;
    const int axis = p->axis;
    double hi = -INFINITY, lo = -INFINITY;
    const PtrBuilderSpheres spheres = p->spheres;
    for (size_t i = from; i < to; i++) {
        double s[4];
        ptr_builder_sphere(spheres, i, s);
        if (!is_framed(s[3], p->smallest))
            continue;
        hi = most(hi, s[axis] * p->ca + s[2] * p->sa + s[3]);
        lo = most(lo, -s[axis] * p->ca + s[2] * p->sa + s[3]);
    }
    p->hi[piece] = hi;
    p->lo[piece] = lo;
}

/* How a perspective camera looking down -Z with half-angle half_angle (in
 * the plane of axis and Z) sees the spheres: the least eye z at which all of
 * them lie inside the two planes bounding the view along that axis, and the
 * eye's coordinate on the axis that centres them. A sphere (c, r) is inside
 * the plane through the eye E with outward normal (cos a, sin a) iff
 * (c_axis - E_axis) cos a + (c_z - E_z) sin a + r <= 0; the two planes give
 * E_z sin a >= hi - E_axis cos a and E_z sin a >= lo + E_axis cos a, least
 * when both hold with equality. */
static void fit_axis(const PtrSceneBuilder *b, double smallest, int axis, double half_angle,
                     double *eye_axis, double *eye_z)
{
    PlanesPass p = { .spheres = b->spheres, .smallest = smallest,
                     .ca = cos(half_angle), .sa = sin(half_angle), .axis = axis };
    const size_t pieces = over_pieces(b, planes_of_piece, &p);
    double hi = -INFINITY, lo = -INFINITY;
    for (size_t k = 0; k < pieces; k++) {
        hi = most(hi, p.hi[k]);
        lo = most(lo, p.lo[k]);
    }
    *eye_axis = 0.5 * (hi - lo) / p.ca;
    *eye_z = 0.5 * (hi + lo) / p.sa;
}

/* The automatic camera: looking down -Z, +Y up, placed so that the spheres'
 * projection fills FRAME_FILL of the image along the axis that binds and is
 * centred along both. Perspective has a 40 degree vertical field of view;
 * orthographic views parallel rays from in front of every sphere. The
 * image's aspect is the command line's, else the scene's resolution's,
 * else 16:9, and the camera keeps it, so the image size follows. */
static void frame_spheres(PtrSceneBuilder *b, double smallest)
{
    const PtrScene *scene = b->scene;
    double aspect = b->auto_aspect > 0   ? b->auto_aspect
                    : scene->width > 0 ? (double)scene->width / scene->height
                                       : 16.0 / 9.0;
    double lo[3] = { -1, -1, -1 }, hi[3] = { 1, 1, 1 };
    framed_box(b, smallest, world_origin, lo, hi);
    double centre[3];
    for (int k = 0; k < 3; k++)
        centre[k] = 0.5 * (lo[k] + hi[k]);
    const double up[3] = { 0, 1, 0 };
    PtrCamera lens = { .projection = b->auto_projection, .aspect = (float)aspect };
    double eye[3];
    if (b->auto_projection == PTR_PROJECTION_ORTHOGRAPHIC) {
        double half_height = fmax(hi[1] - lo[1], (hi[0] - lo[0]) / aspect) / (2 * FRAME_FILL);
        lens.ymag = (float)half_height;
        eye[0] = centre[0];
        eye[1] = centre[1];
        eye[2] = hi[2] + half_height;
    } else {
        const double vfov_deg = 40.0, tan_v = tan(0.5 * vfov_deg * DEG_TO_RAD);
        if (b->count) {
            double z_v, z_h;
            fit_axis(b, smallest, 1, atan(FRAME_FILL * tan_v), &eye[1], &z_v);
            fit_axis(b, smallest, 0, atan(FRAME_FILL * tan_v * aspect), &eye[0], &z_h);
            eye[2] = fmax(z_v, z_h);
        } else { /* nothing to frame: the unit sphere at the origin */
            eye[0] = eye[1] = 0;
            eye[2] = 1.0 / sin(0.5 * vfov_deg * DEG_TO_RAD);
        }
        lens.vfov_deg = (float)vfov_deg;
        lens.focus_distance = (float)(eye[2] - centre[2]);
    }
    const double target[3] = { eye[0], eye[1], centre[2] };
    place_camera(b, eye, target, up, &lens);
}

/* Turns p by the orbit about the vertical line through axis (x, z). */
static void orbit_point(double p[3], double cos_t, double sin_t, const double axis[2])
{
    double x = p[0] - axis[0], z = p[2] - axis[1];
    p[0] = axis[0] + cos_t * x + sin_t * z;
    p[2] = axis[1] - sin_t * x + cos_t * z;
}

/* Turns the camera about the vertical axis (+Y) through the centre of the
 * framed spheres' box, counter-clockwise seen from above. */
static void orbit_camera(PtrSceneBuilder *b, double smallest)
{
    if (b->orbit_degrees == 0)
        return;
    double lo[3] = { 0, 0, 0 }, hi[3] = { 0, 0, 0 };
    framed_box(b, smallest, world_origin, lo, hi);
    const double axis[2] = { 0.5 * (lo[0] + hi[0]), 0.5 * (lo[2] + hi[2]) };
    double t = b->orbit_degrees * DEG_TO_RAD, c = cos(t), s = sin(t);
    const double through_origin[2] = { 0, 0 };
    orbit_point(b->eye, c, s, axis);
    orbit_point(b->target, c, s, axis);
    orbit_point(b->up, c, s, through_origin); /* a direction */
}

static PtrVec3 relative(const double p[3], const double origin[3])
{
    return v3((float)(p[0] - origin[0]), (float)(p[1] - origin[1]), (float)(p[2] - origin[2]));
}

typedef struct HugePass {
    PtrBuilderSpheres spheres;
    PtrHugeChoice choice[PIECES_MAX];
} HugePass;

static void huge_of_piece(void *arg, size_t piece, size_t from, size_t to)
{
    HugePass *p = arg;
    const PtrBuilderSpheres spheres = p->spheres;
    for (size_t i = from; i < to; i++) {
        double s[4];
        ptr_builder_sphere(spheres, i, s);
        ptr_huge_offer(&p->choice[piece], i, i, s[3]);
    }
}

/* The huge spheres (scene.h's rule) kept in double (accel/huge.h says why):
 * the limit is HUGE_RATIO times the extent E of the region the rays live
 * in, taken as the box around the camera and every sphere of a radius within
 * SMALL_RATIO of the smallest. In float, rays leave a sphere of radius r lifted by about
 * 2^-20 r; below 256 E that is under 2^-12 E, less than a pixel of a 4K
 * image of the whole region, and the double test would only cost time (a
 * quarter of the rays per second on a four-sphere scene). A radius-1e5
 * ground under a scene a few units (or a room 100) across is huge; the
 * radius-100 and radius-1000 grounds of seed.gltf and final.gltf are not;
 * a cloud of like spheres has none (the tree's limit takes those grounds
 * out of its boxes). The box is taken relative to origin, as the scene
 * holds the spheres, and eye is too. Puts their indices in huge[],
 * ascending, and returns how many: none, without a pass of its own over
 * the spheres (1.6 GB at 10^8, 3.2 in doubles), if the largest radius is
 * within the limit, as in most scenes. */
#define HUGE_RATIO 256.0

static size_t choose_huge(const PtrSceneBuilder *b, Radii radii, const double origin[3],
                          const double eye[3], size_t huge[PTR_HUGE_MAX])
{
    double lo[3], hi[3];
    memcpy(lo, eye, sizeof lo);
    memcpy(hi, eye, sizeof hi);
    double around[2][3];
    if (framed_box(b, radii.smallest, origin, around[0], around[1]))
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], around[0][k]);
            hi[k] = fmax(hi[k], around[1][k]);
        }
    double extent = 0;
    for (int k = 0; k < 3; k++)
        extent = fmax(extent, hi[k] - lo[k]);
    const PtrHugeChoice choice_of_none = { .limit = HUGE_RATIO * extent };
    if (!(radii.largest > choice_of_none.limit)) /* ptr_huge_offer's test */
        return 0;
    HugePass p = { .spheres = b->spheres };
    for (size_t k = 0; k < PIECES_MAX; k++)
        p.choice[k] = choice_of_none;
    const size_t pieces = over_pieces(b, huge_of_piece, &p);
    PtrHugeChoice choice = choice_of_none;
    ptr_huge_merge(&choice, p.choice, pieces);
    ptr_huge_file_order(&choice);
    for (size_t k = 0; k < choice.count; k++)
        huge[k] = choice.sphere[k].index;
    return choice.count;
}

/* Puts sphere i of the builder, d its centre and radius, its centre less
 * origin (the scene's), at entry at of the scene's arrays (its value at
 * entry i: see PtrSpheres), whose attributes and values exist if the
 * builder's do. */
static PtrResult add_sphere(PtrSceneBuilder *b, size_t i, const double d[4], size_t at,
                            const double origin[3], PtrError *err)
{
    PtrVec3 c = relative(d, origin);
    float r = (float)d[3];
    if (!isfinite(c.x) || !isfinite(c.y) || !isfinite(c.z) || !(r > 0.0f) || !isfinite(r))
        return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                             "a sphere lies too far from the camera for single precision");
    PtrSpheres *s = &b->scene->spheres;
    s->cx[at] = c.x;
    s->cy[at] = c.y;
    s->cz[at] = c.z;
    s->radius[at] = r;
    const PtrSpheres column = material_column(b);
    ptr_sphere_set_material(s, at, ptr_sphere_material(&column, i));
    if (s->id)
        s->id[at] = (uint32_t)i;
#define COPY_ATTRIBUTE(name, type, per_sphere, none, hashed)                               \
    if (b->name)                                                                           \
        memcpy(&s->name[(per_sphere) * at], &b->name[(per_sphere) * i],                    \
               (per_sphere) * sizeof(type));
    PTR_SPHERE_ATTRIBUTES(COPY_ATTRIBUTE)
#undef COPY_ATTRIBUTE
    if (b->values)
        s->value[i] = b->values[i];
    return PTR_OK;
}

typedef struct SphereMove {
    PtrSceneBuilder *builder;
    const double *origin;
    const size_t *huge; /* ascending */
    size_t huge_count;
    atomic_int invalid; /* a sphere the scene cannot hold */
} SphereMove;

/* Puts spheres begin .. end - 1 but the huge ones at their entries, each
 * moved forward by the huge spheres before it. */
static void move_spheres(void *arg, size_t begin, size_t end)
{
    SphereMove *m = arg;
    size_t before = ptr_huge_before(m->huge, m->huge_count, begin);
    int invalid = 0;
    const PtrBuilderSpheres spheres = m->builder->spheres;
    for (size_t i = begin; i < end; i++) {
        if (before < m->huge_count && m->huge[before] == i) {
            before++;
            continue;
        }
        double d[4];
        ptr_builder_sphere(spheres, i, d);
        invalid |= add_sphere(m->builder, i, d, i - before, m->origin, NULL) != PTR_OK;
    }
    if (invalid)
        atomic_store(&m->invalid, 1);
}

/* Gives the pages of spheres begin .. end - 1 in the builder's arrays to
 * bank (see ptr_pages_put), for add_spheres, which has moved them. */
static void put_pages(PtrSceneBuilder *b, PtrPageBank *bank, size_t begin, size_t end)
{
    ptr_pages_put(bank, b->spheres.data, begin * sphere_bytes(b), end * sphere_bytes(b));
    ptr_pages_put(bank, b->materials, begin * b->material_size, end * b->material_size);
    for (size_t k = 0; k < OPTIONAL_ARRAYS; k++)
        if (*optional_array(b, k)) {
            const size_t entry = optional_arrays[k].bytes;
            ptr_pages_put(bank, *optional_array(b, k), begin * entry, end * entry);
        }
}

/* The spheres in file order, the huge ones last (then ids keep the file's
 * order; see PtrSpheres.id), with the huge ones in double as well, all
 * relative to origin: each centre less origin as it is moved (a pass of its
 * own over the builder's 16 or 32 bytes a sphere cost more than the
 * subtraction). Moved on all cores a step at a time, the builder's pages
 * going to the scene's arrays as they empty, so that 10^8 spheres are
 * never in memory twice. */
static PtrResult add_spheres(PtrSceneBuilder *b, Radii radii, const double origin[3],
                             int huge_in_double, PtrError *err)
{
    PtrScene *scene = b->scene;
    const size_t count = b->count;
    const double eye[3] = { b->eye[0] - origin[0], b->eye[1] - origin[1], b->eye[2] - origin[2] };
    size_t huge[PTR_HUGE_MAX];
    const size_t huge_count = huge_in_double ? choose_huge(b, radii, origin, eye, huge) : 0;
    PtrResult res = ptr_spheres_resize(&scene->spheres, count, err);
    /* Made here, not by the first sphere's, so the threads only write them. */
#define MAKE_ATTRIBUTE(name, type, per_sphere, none, hashed)                               \
    if (res == PTR_OK && b->name)                                                          \
        res = ptr_spheres_make(&scene->spheres, (void **)&scene->spheres.name, err);
    PTR_SPHERE_ATTRIBUTES(MAKE_ATTRIBUTE)
#undef MAKE_ATTRIBUTE
    if (res == PTR_OK && b->values)
        res = ptr_spheres_make(&scene->spheres, (void **)&scene->spheres.value, err);
    if (res == PTR_OK && huge_count)
        res = ptr_spheres_make_ids(&scene->spheres, err);
    if (res == PTR_OK && huge_count) {
        scene->huge.centre_radius = malloc(huge_count * 4 * sizeof(double));
        if (!scene->huge.centre_radius)
            res = ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the huge spheres");
    }
    for (size_t k = 0; k < huge_count && res == PTR_OK; k++) {
        double d[4], *centre_radius = &scene->huge.centre_radius[4 * k];
        ptr_builder_sphere(b->spheres, huge[k], d);
        for (int a = 0; a < 3; a++)
            centre_radius[a] = d[a] - origin[a];
        centre_radius[3] = d[3];
        res = add_sphere(b, huge[k], d, count - huge_count + k, origin, err);
    }
    SphereMove move = { .builder = b, .origin = origin, .huge = huge, .huge_count = huge_count };
    atomic_init(&move.invalid, 0);
    const int threads = ptr_usable_cpus();
    PtrPageBank bank = { 0 };
    for (size_t begin = 0; begin < count && res == PTR_OK; begin += PTR_PAGE_STEP) {
        const size_t end = count - begin > PTR_PAGE_STEP ? begin + PTR_PAGE_STEP : count;
        /* Each step's spheres on the pages of those the step before moved. */
        if (!ptr_spheres_take_pages(&scene->spheres, &bank,
                                    begin - ptr_huge_before(huge, huge_count, begin),
                                    end - ptr_huge_before(huge, huge_count, end))) {
            res = ptr_error_set(err, PTR_ERR_NOMEM, "out of memory moving the spheres");
            break;
        }
        ptr_parallel_ranges(threads, begin, end, move_spheres, &move);
        if (atomic_load(&move.invalid))
            res = ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                                "a sphere lies too far from the camera for single precision");
        put_pages(b, end < count ? &bank : NULL, begin, end);
    }
    ptr_pages_free(&bank);
    if (res == PTR_OK)
        scene->huge.count = huge_count;
    return res;
}

PtrResult ptr_builder_finish(PtrSceneBuilder *b, unsigned flags, PtrError *err)
{
    assert(!atomic_load(&b->lost)); /* every fill was followed by ptr_builder_refill */
    PtrScene *scene = b->scene;
    PtrResult res = PTR_OK;
    /* The framing, the orbit and the huge choice look at the spheres whose
     * radius is within SMALL_RATIO of the smallest. */
    const Radii radii = radii_of(b);
    if (b->override)
        use_override(b);
    else if (!b->has_camera)
        frame_spheres(b, radii.smallest);
    orbit_camera(b, radii.smallest);
    const double *origin = flags & PTR_BUILD_RECENTRE ? b->eye : world_origin;
    memcpy(scene->origin, origin, sizeof scene->origin);

    res = add_spheres(b, radii, origin, flags & PTR_BUILD_HUGE_IN_DOUBLE, err);
    scene->camera = b->lens;
    scene->camera.lookfrom = relative(b->eye, origin);
    scene->camera.lookat = relative(b->target, origin);
    scene->camera.up = relative(b->up, world_origin);
    ptr_builder_free(b);
    return res;
}

PtrResult ptr_builder_keep_attributes(PtrSceneBuilder *b, int colors, int values,
                                      PtrError *err)
{
    const int keep[OPTIONAL_ARRAYS] = { [OPTIONAL_color] = colors, [OPTIONAL_VALUES] = values };
    for (size_t k = 0; k < OPTIONAL_ARRAYS; k++)
        if (keep[k] && !*optional_array(b, k)) {
            PtrResult r = start_optional(b, k, b->capacity, err);
            if (r != PTR_OK)
                return r;
        }
    return PTR_OK;
}

void ptr_builder_fill_value(PtrSceneBuilder *b, size_t n, double value)
{
    b->values[n] = (float)value;
}
