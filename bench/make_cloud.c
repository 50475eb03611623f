/* A particle cloud of N spheres above a ground, as an instanced glTF binary:
 * the file scripts/make_cloud.py writes (the same nodes, meshes, materials,
 * EXT_mesh_gpu_instancing accessors, ground, camera and extensions) and the
 * same distribution (that of ../shared/bench-scenes/gen_cloud.py: a 20x6x20
 * box at 8% volume fraction, 80% diffuse in colours that are the product of
 * two uniforms a channel, 15% metal with a fuzz from {0, 0.1, ..., 0.5}, 5%
 * glass), fast enough for 10^8 spheres and in a few megabytes of memory.
 *
 *   make_cloud [--joined] N OUT.glb [SEED]
 *
 * --joined writes the same spheres as one mesh instead, as `gltf-transform
 * join` and Blender's Join leave them: a primitive a material holding a UV
 * sphere of 8 segments and 6 rings for each sphere (its transform baked into
 * float positions, 32-bit indices), 1464 bytes a sphere; the spheres' own
 * colours are not written (a mesh has no per-sphere colour). It measures
 * the import of joined meshes against instances (README, "Scaling").
 *
 * Its random numbers are its own (splitmix64), not Python's: the same N and
 * SEED give the same file, not the file make_cloud.py gives.
 *
 * The binary chunk holds each material's spheres as three blocks
 * (TRANSLATION, SCALE, _COLOR_0: float VEC3, 36 bytes a sphere), and the
 * JSON chunk, which comes first, gives their lengths. So a first pass counts
 * the spheres of each material, and a second writes every sphere into its
 * material's three blocks, each a buffered stream at its own place in the
 * file (pwrite). Sphere i draws from its own fixed slots of one splitmix64
 * sequence, so the first pass draws only the material, and both passes see
 * the same spheres. */
#define _XOPEN_SOURCE 700
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum {
    SEGMENTS = 32, RINGS = 16, /* make_scenes.py's unit UV sphere */
    VERTICES = 1 + (RINGS - 1) * SEGMENTS + 1,
    TRIANGLES = 2 * SEGMENTS * (RINGS - 1),
    JOINED_SEGMENTS = 8, JOINED_RINGS = 6, /* --joined: each sphere's mesh */
    JOINED_VERTICES = 1 + (JOINED_RINGS - 1) * JOINED_SEGMENTS + 1,
    JOINED_TRIANGLES = 2 * JOINED_SEGMENTS * (JOINED_RINGS - 1),
    SLOTS_PER_SPHERE = 16, /* splitmix64 outputs reserved for each sphere */
    FUZZES = 6,
    GROUPS = 1 + FUZZES + 1, /* diffuse, metal with each fuzz, glass */
    GLASS = GROUPS - 1,
    ATTRIBUTES = 3, /* TRANSLATION, SCALE, _COLOR_0 */
    STREAM_BYTES = 1 << 18,
};

static const double BOX[3] = { 20.0, 6.0, 20.0 };
static const double FUZZ[FUZZES] = { 0.0, 0.1, 0.2, 0.3, 0.4, 0.5 };

static const char *out_path;
static char *tmp_path;

static void fail(const char *what)
{
    fprintf(stderr, "make_cloud: %s: %s\n", out_path ? out_path : "", what);
    if (tmp_path)
        unlink(tmp_path);
    exit(1);
}

static uint64_t splitmix64_mix(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* Sphere i's random numbers: slots i*16 .. i*16+15 of the splitmix64
 * sequence that starts at a state hashed from the seed (so that neighbouring
 * seeds do not give shifted copies of one sequence). */
typedef struct {
    uint64_t start;
} CloudRng;

static uint64_t draw_bits(const CloudRng *rng, uint64_t sphere, unsigned slot)
{
    return splitmix64_mix(rng->start + (sphere * SLOTS_PER_SPHERE + slot + 1) * 0x9e3779b97f4a7c15u);
}

static double draw(const CloudRng *rng, uint64_t sphere, unsigned slot)
{
    return (double)(draw_bits(rng, sphere, slot) >> 11) * 0x1.0p-53;
}

enum { SLOT_KIND, SLOT_FUZZ, SLOT_CENTRE, SLOT_COLOUR = SLOT_CENTRE + 3 };

/* The material group of sphere i: 0 diffuse, 1 + fuzz index metal, GLASS. */
static unsigned sphere_group(const CloudRng *rng, uint64_t sphere)
{
    double kind = draw(rng, sphere, SLOT_KIND);
    if (kind < 0.8)
        return 0;
    if (kind < 0.95)
        return 1 + (unsigned)((draw_bits(rng, sphere, SLOT_FUZZ) >> 32) * FUZZES >> 32);
    return GLASS;
}

/* A block of the binary chunk written at its own offset, through a buffer. */
typedef struct {
    int fd;
    uint64_t offset;
    size_t used;
    unsigned char *buffer;
} Stream;

static void write_at(int fd, const void *data, size_t size, uint64_t offset)
{
    const unsigned char *p = data;
    while (size > 0) {
        ssize_t n = pwrite(fd, p, size, (off_t)offset);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            fail(strerror(n < 0 ? errno : EIO));
        p += n, size -= (size_t)n, offset += (uint64_t)n;
    }
}

static void stream_flush(Stream *s)
{
    write_at(s->fd, s->buffer, s->used, s->offset);
    s->offset += s->used;
    s->used = 0;
}

/* Three floats at p, little-endian whatever the host; returns the end. */
static unsigned char *put_vec3(unsigned char *p, double x, double y, double z)
{
    float v[3] = { (float)x, (float)y, (float)z };
    for (int i = 0; i < 3; i++) {
        uint32_t bits;
        memcpy(&bits, &v[i], 4);
        for (int b = 0; b < 4; b++)
            *p++ = (unsigned char)(bits >> 8 * b);
    }
    return p;
}

static void stream_vec3(Stream *s, double x, double y, double z)
{
    if (s->used + 12 > STREAM_BYTES)
        stream_flush(s);
    put_vec3(s->buffer + s->used, x, y, z);
    s->used += 12;
}

/* Three 32-bit little-endian integers (indices below 2^32: the file's
 * length is a 32-bit number). */
static void stream_u32x3(Stream *s, uint64_t a, uint64_t b, uint64_t c)
{
    if (s->used + 12 > STREAM_BYTES)
        stream_flush(s);
    const uint64_t v[3] = { a, b, c };
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 4; k++)
            s->buffer[s->used++] = (unsigned char)(v[i] >> 8 * k);
}

/* make_scenes.py's unit UV sphere of `segments` and `rings` (bounds exactly
 * +-1): its vertices and triangles. */
static void sphere_geometry(unsigned segments, unsigned rings, double (*verts)[3],
                            unsigned (*triangles)[3])
{
    unsigned v = 0, t = 0;
    verts[v][0] = 0.0, verts[v][1] = 1.0, verts[v++][2] = 0.0;
    for (unsigned ring = 1; ring < rings; ring++) {
        double theta = M_PI * ring / rings, y = 2 * ring == rings ? 0.0 : cos(theta);
        double sin_theta = sin(theta);
        for (unsigned seg = 0; seg < segments; seg++) {
            double phi = 2.0 * M_PI * seg / segments;
            int quarter = 4 * seg % segments == 0; /* exactly +-1 where the bounds are */
            double x = quarter ? (double)lround(cos(phi)) : cos(phi);
            double z = quarter ? (double)lround(sin(phi)) : sin(phi);
            verts[v][0] = sin_theta * x, verts[v][1] = y, verts[v++][2] = sin_theta * z;
        }
    }
    verts[v][0] = 0.0, verts[v][1] = -1.0, verts[v][2] = 0.0;
    const unsigned bottom = v;
#define RING_VERTEX(ring, seg) (1u + ((ring) - 1u) * segments + (seg) % segments)
    for (unsigned seg = 0; seg < segments; seg++) {
        unsigned top[3] = { 0, RING_VERTEX(1, seg + 1), RING_VERTEX(1, seg) };
        unsigned low[3] = { bottom, RING_VERTEX(rings - 1, seg), RING_VERTEX(rings - 1, seg + 1) };
        memcpy(triangles[t++], top, sizeof top);
        memcpy(triangles[t++], low, sizeof low);
    }
    for (unsigned ring = 1; ring < rings - 1; ring++)
        for (unsigned seg = 0; seg < segments; seg++) {
            unsigned a = RING_VERTEX(ring, seg), b = RING_VERTEX(ring, seg + 1);
            unsigned c = RING_VERTEX(ring + 1, seg), d = RING_VERTEX(ring + 1, seg + 1);
            unsigned first[3] = { a, b, d }, second[3] = { a, d, c };
            memcpy(triangles[t++], first, sizeof first);
            memcpy(triangles[t++], second, sizeof second);
        }
#undef RING_VERTEX
}

/* The binary chunk's first bytes: make_scenes.py's unit UV sphere,
 * positions then triangle indices. */
static size_t unit_sphere(unsigned char *out)
{
    double verts[VERTICES][3];
    unsigned triangles[TRIANGLES][3];
    sphere_geometry(SEGMENTS, RINGS, verts, triangles);
    unsigned char *p = out;
    for (unsigned v = 0; v < VERTICES; v++)
        p = put_vec3(p, verts[v][0], verts[v][1], verts[v][2]);
    for (unsigned i = 0; i < TRIANGLES * 3; i++) {
        *p++ = (unsigned char)(triangles[i / 3][i % 3] & 0xff);
        *p++ = (unsigned char)(triangles[i / 3][i % 3] >> 8);
    }
    return (size_t)(p - out);
}

/* A JSON number as Python writes a float: the shortest text that reads back
 * the same, with ".0" on whole numbers. */
static void json_real(FILE *f, double v)
{
    char text[32];
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, v);
        if (strtod(text, NULL) == v)
            break;
    }
    fprintf(f, "%s%s", text, strpbrk(text, ".e") ? "" : ".0");
}

static void json_reals(FILE *f, const double *v, int n)
{
    fputc('[', f);
    for (int i = 0; i < n; i++) {
        if (i)
            fputc(',', f);
        json_real(f, v[i]);
    }
    fputc(']', f);
}

static void normalize(double *v, int n)
{
    double sum = 0.0;
    for (int i = 0; i < n; i++)
        sum += v[i] * v[i];
    double length = sqrt(sum);
    for (int i = 0; i < n; i++)
        v[i] /= length;
}

/* make_scenes.py's look_rotation: the quaternion (x, y, z, w) that turns a
 * camera looking down -Z with +Y up to look from `from` at `at`; here vup is
 * +Y and the trace is positive. */
static void look_rotation(const double from[3], const double at[3], double q[4])
{
    double w[3] = { from[0] - at[0], from[1] - at[1], from[2] - at[2] };
    normalize(w, 3);
    double u[3] = { w[2], 0.0, -w[0] }; /* (0, 1, 0) x w */
    normalize(u, 3);
    double v[3] = { w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2], w[0] * u[1] - w[1] * u[0] };
    double s = 0.5 / sqrt(u[0] + v[1] + w[2] + 1.0);
    q[0] = (v[2] - w[1]) * s;
    q[1] = (w[0] - u[2]) * s;
    q[2] = (u[1] - v[0]) * s;
    q[3] = 0.25 / s;
    normalize(q, 4);
}

static void json_material(FILE *f, unsigned group, unsigned index)
{
    const double white[4] = { 1.0, 1.0, 1.0, 1.0 };
    fputs("{\"pbrMetallicRoughness\":{\"baseColorFactor\":", f);
    json_reals(f, white, 4);
    fputs(",\"metallicFactor\":", f);
    json_real(f, group > 0 && group < GLASS ? 1.0 : 0.0);
    fputs(",\"roughnessFactor\":", f);
    json_real(f, group == 0 ? 1.0 : group == GLASS ? 0.0 : FUZZ[group - 1]);
    fputc('}', f);
    if (group == GLASS) {
        fputs(",\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":", f);
        json_real(f, 1.0);
        fputs("},\"KHR_materials_ior\":{\"ior\":", f);
        json_real(f, 1.5);
        fputs("}}", f);
    }
    fprintf(f, ",\"name\":\"%s.%03u\"}", group == 0 ? "lambertian" : group == GLASS ? "dielectric" : "metal",
            index);
}

/* --joined: bytes a sphere in its primitive's positions and indices. */
enum { JOINED_POSITION_BYTES = 12 * JOINED_VERTICES, JOINED_INDEX_BYTES = 12 * JOINED_TRIANGLES };

/* What --joined writes of group g: its primitive's positions' bounds. */
typedef struct {
    int joined;
    double lower[GROUPS][3], upper[GROUPS][3];
} Joined;

/* --joined: the accessors and buffer views of each group's primitive, its
 * positions then its indices, group after group in `order`. */
static void joined_accessors(FILE *f, const unsigned *order, unsigned used, const uint64_t *count,
                             const Joined *joined)
{
    fputs("],\"accessors\":[", f);
    for (unsigned m = 0; m < used; m++) {
        const unsigned g = order[m];
        fprintf(f, "%s{\"bufferView\":%u,\"componentType\":5126,\"count\":%" PRIu64
                   ",\"type\":\"VEC3\",\"min\":", m ? "," : "", 2 * m, count[g] * JOINED_VERTICES);
        json_reals(f, joined->lower[g], 3);
        fputs(",\"max\":", f);
        json_reals(f, joined->upper[g], 3);
        fprintf(f, "},{\"bufferView\":%u,\"componentType\":5125,\"count\":%" PRIu64
                   ",\"type\":\"SCALAR\"}", 2 * m + 1, count[g] * 3 * JOINED_TRIANGLES);
    }
    fputs("],\"bufferViews\":[", f);
    uint64_t offset = 0;
    for (unsigned m = 0; m < used; m++) {
        const uint64_t positions = count[order[m]] * JOINED_POSITION_BYTES;
        const uint64_t indices = count[order[m]] * JOINED_INDEX_BYTES;
        fprintf(f, "%s{\"buffer\":0,\"byteOffset\":%" PRIu64 ",\"byteLength\":%" PRIu64
                   ",\"target\":34962},{\"buffer\":0,\"byteOffset\":%" PRIu64
                   ",\"byteLength\":%" PRIu64 ",\"target\":34963}",
                m ? "," : "", offset, positions, offset + positions, indices);
        offset += positions + indices;
    }
}

/* The JSON chunk, in make_scenes.py's order of keys; `order` lists the groups
 * present in the order of their first sphere (the ground's, diffuse, first),
 * as make_scenes.py numbers materials. */
static char *json_chunk(uint64_t spheres, const unsigned *order, unsigned used, const uint64_t *count,
                        uint64_t mesh_bytes, uint64_t binary_bytes, const Joined *joined,
                        size_t *size)
{
    char *text = NULL;
    FILE *f = open_memstream(&text, size);
    if (!f)
        fail("out of memory");
    fprintf(f, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"ptr bench/make_cloud\"},\"scene\":0,"
               "\"scenes\":[{\"name\":\"cloud%" PRIu64 "\",\"nodes\":[",
            spheres);
    const unsigned nodes = joined->joined ? 1 : used;
    for (unsigned i = 0; i <= nodes; i++)
        fprintf(f, "%s%u", i ? "," : "", i);
    fputs("],\"extras\":{\"sky\":\"gradient\",\"resolution\":[400,225]}}],\"nodes\":[", f);
    if (joined->joined)
        fputs("{\"name\":\"Spheres\",\"mesh\":0},", f);
    for (unsigned m = 0; m < used && !joined->joined; m++)
        fprintf(f,
                "{\"name\":\"Spheres.%03u\",\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":"
                "{\"TRANSLATION\":%u,\"SCALE\":%u,\"_COLOR_0\":%u}}},\"mesh\":%u},",
                m, 2 + ATTRIBUTES * m, 3 + ATTRIBUTES * m, 4 + ATTRIBUTES * m, m);
    const double from[3] = { 0.0, 9.0, 26.0 }, at[3] = { 0.0, 2.0, 0.0 };
    double rotation[4];
    look_rotation(from, at, rotation);
    fputs("{\"name\":\"Camera\",\"camera\":0,\"translation\":", f);
    json_reals(f, from, 3);
    fputs(",\"rotation\":", f);
    json_reals(f, rotation, 4);
    fputs("}],\"cameras\":[{\"name\":\"Camera\",\"type\":\"perspective\",\"perspective\":{\"yfov\":", f);
    json_real(f, 40.0 * M_PI / 180.0);
    fputs(",\"aspectRatio\":", f);
    json_real(f, 400.0 / 225.0);
    fputs(",\"znear\":", f);
    json_real(f, 0.001);
    fputs("},\"extras\":{\"aperture\":", f);
    json_real(f, 0.0);
    fputs(",\"focus_distance\":", f);
    json_real(f, 26.0);
    fputs("}}],\"meshes\":[", f);
    if (joined->joined) {
        fputs("{\"name\":\"Spheres\",\"primitives\":[", f);
        for (unsigned m = 0; m < used; m++)
            fprintf(f, "%s{\"attributes\":{\"POSITION\":%u},\"indices\":%u,\"material\":%u}",
                    m ? "," : "", 2 * m, 2 * m + 1, m);
        fputs("]}", f);
    }
    for (unsigned m = 0; m < used && !joined->joined; m++)
        fprintf(f,
                "%s{\"name\":\"Sphere.%03u\",\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":0},"
                "\"indices\":1,\"material\":%u}]}",
                m ? "," : "", m, m);
    fputs("],\"materials\":[", f);
    for (unsigned m = 0; m < used; m++) {
        if (m)
            fputc(',', f);
        json_material(f, order[m], m);
    }
    if (joined->joined) {
        joined_accessors(f, order, used, count, joined);
        fprintf(f, "],\"buffers\":[{\"byteLength\":%" PRIu64 "}]%s}", binary_bytes,
                count[GLASS] ? ",\"extensionsUsed\":[\"KHR_materials_transmission\","
                               "\"KHR_materials_ior\"]" : "");
        goto done;
    }
    const double lower[3] = { -1.0, -1.0, -1.0 }, upper[3] = { 1.0, 1.0, 1.0 };
    fprintf(f, "],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\",\"min\":",
            VERTICES);
    json_reals(f, lower, 3);
    fputs(",\"max\":", f);
    json_reals(f, upper, 3);
    fprintf(f, "},{\"bufferView\":1,\"componentType\":5123,\"count\":%d,\"type\":\"SCALAR\"}", 3 * TRIANGLES);
    for (unsigned m = 0; m < used; m++)
        for (unsigned a = 0; a < ATTRIBUTES; a++)
            fprintf(f, ",{\"bufferView\":%u,\"componentType\":5126,\"count\":%" PRIu64 ",\"type\":\"VEC3\"}",
                    2 + ATTRIBUTES * m + a, count[order[m]]);
    fprintf(f,
            "],\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%d,\"target\":34962},"
            "{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d,\"target\":34963}",
            VERTICES * 12, VERTICES * 12, TRIANGLES * 6);
    uint64_t offset = mesh_bytes;
    for (unsigned m = 0; m < used; m++)
        for (unsigned a = 0; a < ATTRIBUTES; a++) {
            fprintf(f, ",{\"buffer\":0,\"byteOffset\":%" PRIu64 ",\"byteLength\":%" PRIu64 "}", offset,
                    12 * count[order[m]]);
            offset += 12 * count[order[m]];
        }
    fprintf(f, "],\"buffers\":[{\"byteLength\":%" PRIu64 "}],"
               "\"extensionsRequired\":[\"EXT_mesh_gpu_instancing\"],\"extensionsUsed\":[%s\"EXT_mesh_gpu_instancing\"]}",
            binary_bytes, count[GLASS] ? "\"KHR_materials_transmission\",\"KHR_materials_ior\"," : "");
done:
    if (ferror(f) || fclose(f))
        fail("out of memory");
    return text;
}

/* Sphere i's centre, spheres of `radius` in the box above the ground. */
static void sphere_centre(const CloudRng *rng, uint64_t i, double radius, double centre[3])
{
    centre[0] = -BOX[0] / 2 + BOX[0] * draw(rng, i, SLOT_CENTRE);
    centre[1] = radius + (BOX[1] - radius) * draw(rng, i, SLOT_CENTRE + 1);
    centre[2] = -BOX[2] / 2 + BOX[2] * draw(rng, i, SLOT_CENTRE + 2);
}

/* The instanced form's second pass: each sphere into its material's three
 * blocks, which start at `offset`. */
static void write_instances(int fd, uint64_t offset, const CloudRng *rng, uint64_t spheres,
                            double radius, const unsigned *order, unsigned used,
                            const uint64_t *count)
{
    /* Second pass: each sphere into its material's three blocks. */
    Stream streams[GROUPS][ATTRIBUTES];
    for (unsigned m = 0; m < used; m++)
        for (unsigned a = 0; a < ATTRIBUTES; a++) {
            Stream *s = &streams[order[m]][a];
            *s = (Stream){ .fd = fd, .offset = offset, .buffer = malloc(STREAM_BYTES) };
            if (!s->buffer)
                fail("out of memory");
            offset += 12 * count[order[m]];
        }
    Stream *ground = streams[0];
    stream_vec3(&ground[0], 0.0, -1000.0, 0.0);
    stream_vec3(&ground[1], 1000.0, 1000.0, 1000.0);
    stream_vec3(&ground[2], 0.5, 0.5, 0.5);
    for (uint64_t i = 0; i < spheres; i++) {
        unsigned g = sphere_group(rng, i);
        Stream *s = streams[g];
        double centre[3];
        sphere_centre(rng, i, radius, centre);
        stream_vec3(&s[0], centre[0], centre[1], centre[2]);
        stream_vec3(&s[1], radius, radius, radius);
        double colour[3] = { 1.0, 1.0, 1.0 };
        for (unsigned c = 0; c < 3 && g != GLASS; c++)
            colour[c] = g == 0 ? draw(rng, i, SLOT_COLOUR + 2 * c) * draw(rng, i, SLOT_COLOUR + 2 * c + 1)
                               : 0.5 + 0.5 * draw(rng, i, SLOT_COLOUR + c);
        stream_vec3(&s[2], colour[0], colour[1], colour[2]);
    }
    for (unsigned g = 0; g < GROUPS; g++)
        for (unsigned a = 0; a < ATTRIBUTES && count[g]; a++) {
            stream_flush(&streams[g][a]);
            free(streams[g][a].buffer);
        }
}

/* --joined: the ground, then each sphere, as its group and the vertices of
 * its mesh as the file stores them, handed to each(user, ...). */
static void joined_spheres(const CloudRng *rng, uint64_t spheres, double radius,
                           void (*each)(void *user, unsigned group,
                                        const float (*verts)[3]),
                           void *user)
{
    double unit[JOINED_VERTICES][3];
    unsigned triangles[JOINED_TRIANGLES][3];
    sphere_geometry(JOINED_SEGMENTS, JOINED_RINGS, unit, triangles);
    float verts[JOINED_VERTICES][3];
    for (uint64_t i = 0; i <= spheres; i++) {
        double centre[3] = { 0.0, -1000.0, 0.0 }, r = 1000.0; /* the ground */
        unsigned group = 0;
        if (i > 0) {
            sphere_centre(rng, i - 1, radius, centre);
            r = radius;
            group = sphere_group(rng, i - 1);
        }
        for (unsigned v = 0; v < JOINED_VERTICES; v++)
            for (int c = 0; c < 3; c++)
                verts[v][c] = (float)(centre[c] + r * unit[v][c]);
        each(user, group, (const float (*)[3])verts);
    }
}

static void add_bounds(void *user, unsigned group, const float (*verts)[3])
{
    Joined *joined = user;
    for (unsigned v = 0; v < JOINED_VERTICES; v++)
        for (int c = 0; c < 3; c++) {
            joined->lower[group][c] = fmin(joined->lower[group][c], verts[v][c]);
            joined->upper[group][c] = fmax(joined->upper[group][c], verts[v][c]);
        }
}

/* --joined: each group's bounds, over the ground and every sphere. */
static void joined_bounds(const CloudRng *rng, uint64_t spheres, double radius, Joined *joined)
{
    for (unsigned g = 0; g < GROUPS; g++)
        for (int c = 0; c < 3; c++)
            joined->lower[g][c] = HUGE_VAL, joined->upper[g][c] = -HUGE_VAL;
    joined_spheres(rng, spheres, radius, add_bounds, joined);
}

/* --joined's second pass: a stream of positions and one of indices a
 * group, and the spheres each has so far. */
typedef struct {
    Stream streams[GROUPS][2];
    uint64_t written[GROUPS];
    unsigned triangles[JOINED_TRIANGLES][3];
} JoinedWriter;

static void write_sphere(void *user, unsigned group, const float (*verts)[3])
{
    JoinedWriter *w = user;
    for (unsigned v = 0; v < JOINED_VERTICES; v++)
        stream_vec3(&w->streams[group][0], verts[v][0], verts[v][1], verts[v][2]);
    const uint64_t base = w->written[group]++ * JOINED_VERTICES;
    for (unsigned t = 0; t < JOINED_TRIANGLES; t++)
        stream_u32x3(&w->streams[group][1], base + w->triangles[t][0],
                     base + w->triangles[t][1], base + w->triangles[t][2]);
}

/* --joined's second pass: each sphere's vertices and triangles into its
 * group's primitive, the groups' blocks in `order` from `offset`. */
static void write_joined(int fd, uint64_t offset, const CloudRng *rng, uint64_t spheres,
                         double radius, const unsigned *order, unsigned used,
                         const uint64_t *count)
{
    JoinedWriter w = { .written = { 0 } };
    double unit[JOINED_VERTICES][3];
    sphere_geometry(JOINED_SEGMENTS, JOINED_RINGS, unit, w.triangles);
    for (unsigned m = 0; m < used; m++) {
        const uint64_t n = count[order[m]];
        for (unsigned a = 0; a < 2; a++) {
            w.streams[order[m]][a] = (Stream){ .fd = fd, .offset = offset,
                                               .buffer = malloc(STREAM_BYTES) };
            if (!w.streams[order[m]][a].buffer)
                fail("out of memory");
            offset += n * (a ? JOINED_INDEX_BYTES : JOINED_POSITION_BYTES);
        }
    }
    joined_spheres(rng, spheres, radius, write_sphere, &w);
    for (unsigned m = 0; m < used; m++)
        for (unsigned a = 0; a < 2; a++) {
            stream_flush(&w.streams[order[m]][a]);
            free(w.streams[order[m]][a].buffer);
        }
}

static void put_u32(unsigned char *p, uint64_t v)
{
    for (int b = 0; b < 4; b++)
        p[b] = (unsigned char)(v >> 8 * b);
}

int main(int argc, char **argv)
{
    Joined joined = { .joined = argc > 1 && strcmp(argv[1], "--joined") == 0 };
    argc -= joined.joined, argv += joined.joined;
    if (argc < 3 || argc > 4) {
        fputs("usage: make_cloud [--joined] N OUT.glb [SEED]\n", stderr);
        return 2;
    }
    out_path = argv[2];
    char *end;
    errno = 0;
    uint64_t spheres = strtoull(argv[1], &end, 10);
    uint64_t seed = argc > 3 ? strtoull(argv[3], &end, 10) : 7;
    if (errno || *end || argv[1][0] == '-' || spheres == 0 || (argc > 3 && argv[3][0] == '-')) {
        fputs("make_cloud: N and SEED are whole numbers, N at least 1\n", stderr);
        return 2;
    }

    /* First pass: how many spheres each material has, and which comes first. */
    CloudRng rng = { splitmix64_mix(seed ^ 0x6a09e667f3bcc909u) };
    uint64_t count[GROUPS] = { 1 }, first[GROUPS]; /* the ground is diffuse */
    for (unsigned g = 0; g < GROUPS; g++)
        first[g] = UINT64_MAX;
    first[0] = 0;
    for (uint64_t i = 0; i < spheres; i++) {
        unsigned g = sphere_group(&rng, i);
        if (!count[g]++)
            first[g] = i + 1;
    }
    unsigned order[GROUPS], used = 0;
    for (unsigned g = 0; g < GROUPS; g++)
        if (count[g]) {
            unsigned at = used++;
            for (; at > 0 && first[order[at - 1]] > first[g]; at--)
                order[at] = order[at - 1];
            order[at] = g;
        }

    const double radius = pow(0.08 * BOX[0] * BOX[1] * BOX[2] / (double)spheres * 3 / (4 * M_PI), 1.0 / 3);
    unsigned char mesh[VERTICES * 12 + TRIANGLES * 6];
    size_t mesh_bytes = joined.joined ? 0 : unit_sphere(mesh);
    uint64_t binary_bytes = mesh_bytes + 36 * (spheres + 1);
    if (joined.joined) {
        joined_bounds(&rng, spheres, radius, &joined);
        binary_bytes = (spheres + 1) * (uint64_t)(JOINED_POSITION_BYTES + JOINED_INDEX_BYTES);
    }
    size_t json_bytes;
    char *json = json_chunk(spheres, order, used, count, mesh_bytes, binary_bytes, &joined,
                            &json_bytes);
    size_t json_padded = (json_bytes + 3) & ~(size_t)3;
    uint64_t binary_start = 12 + 8 + json_padded + 8, total = binary_start + binary_bytes;
    if (total > UINT32_MAX)
        fail("too many spheres for a .glb (its length is a 32-bit number)");

    tmp_path = malloc(strlen(out_path) + 5);
    if (!tmp_path)
        fail("out of memory");
    strcat(strcpy(tmp_path, out_path), ".tmp");
    int fd = open(tmp_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) {
        char *path = tmp_path;
        tmp_path = NULL; /* nothing to remove */
        fprintf(stderr, "make_cloud: %s: %s\n", path, strerror(errno));
        return 1;
    }
    unsigned char header[12 + 8];
    memcpy(header, "glTF", 4);
    put_u32(header + 4, 2);
    put_u32(header + 8, total);
    put_u32(header + 12, json_padded);
    memcpy(header + 16, "JSON", 4);
    write_at(fd, header, sizeof header, 0);
    write_at(fd, json, json_bytes, sizeof header);
    write_at(fd, "   ", json_padded - json_bytes, sizeof header + json_bytes);
    put_u32(header, binary_bytes);
    memcpy(header + 4, "BIN", 4);
    write_at(fd, header, 8, binary_start - 8);
    write_at(fd, mesh, mesh_bytes, binary_start);
    free(json);

    if (joined.joined)
        write_joined(fd, binary_start, &rng, spheres, radius, order, used, count);
    else
        write_instances(fd, binary_start + mesh_bytes, &rng, spheres, radius, order, used, count);
    if (close(fd) != 0)
        fail(strerror(errno));
    if (rename(tmp_path, out_path) != 0)
        fail(strerror(errno));
    free(tmp_path);
    return 0;
}
