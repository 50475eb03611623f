/* OBJ (with its MTL) to spheres, following docs/scenes.md.
 *
 * A reader written here, not tinyobjloader: the conventions take objects (`o`)
 * and, only in files without any, groups (`g`), and tinyobjloader folds both
 * into one notion of shape that keeps only the latest name. ptr needs a small
 * part of OBJ (v, f, o, g, usemtl, mtllib and a dozen MTL keys), reads it line
 * by line with errors that name the line, and is fuzzed (tests/fuzz/). */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "builder.h"
#include "base/grow.h"
#include "importer_internal.h"
#include "mesh_spheres.h"

enum { MAX_LINE = 64 << 20 }; /* longer lines are not OBJ */

/* A part's faces from first_triangle on (up to the next run's) were read
 * under one usemtl: a joined object (Blender's Join, exported) holds spheres
 * of several materials, each run of faces its own. */
typedef struct MaterialRun {
    size_t first_triangle;
    uint32_t material;    /* its usemtl's name among the reader's names,
                           * NO_MATERIAL before any usemtl */
} MaterialRun;

enum { NO_MATERIAL = UINT32_MAX };

/* A name usemtl gave, held once however many runs use it (files switch
 * material at every face). */
typedef struct MaterialName {
    char *text;
    uint32_t scene_index; /* its material's once a sphere uses it, else UINT32_MAX */
} MaterialName;

typedef struct Part { /* an object (o) or a group (g) */
    char *name;       /* NULL: faces before any o or g */
    long line;
    double lo[3], hi[3];
    size_t faces;
    MaterialRun *runs; /* in the order of their faces; the first at face 0 */
    size_t nruns, runs_capacity;
    uint32_t *tris;   /* its faces as triangles (fans), 3 vertex indices each */
    size_t ntris, tris_capacity;
} Part;

typedef struct Parts {
    Part *items;
    size_t count, capacity;
    long current;     /* index of the part faces go to, -1: none yet */
    int named;        /* the file has at least one o (or g) line */
} Parts;

typedef struct Mtl {
    char *name;
    double kd[3], ke[3], tf[3];
    double ni, d, tr, ns, pr, pm;
    int illum;
    int has_tf, has_pr, has_pm, has_d, has_tr;
    uint32_t scene_index; /* in the scene once used, else UINT32_MAX */
} Mtl;

typedef struct Reader {
    const char *path;
    PtrStrings *warnings;
    PtrError *err;
    double *v;        /* x, y, z per vertex */
    size_t nv, capacity;
    Parts objects, groups;
    MaterialName *names;
    size_t nnames, names_capacity;
    uint32_t *slots;  /* names by hash, open-addressed: indices, UINT32_MAX for none */
    size_t nslots;    /* a power of two, at least twice nnames */
    uint32_t material; /* usemtl in force: its name, NO_MATERIAL before any */
    char **libs;      /* mtllib files, as paths */
    size_t nlibs;
    Mtl *mtls;
    size_t nmtls;
    int missing_lib;  /* an mtllib could not be read (and was reported) */
    uint32_t *corners; /* the face being read */
    size_t corners_capacity;
} Reader;

static char *copy(const char *s)
{
    char *c = strdup(s);
    return c;
}

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    char *end = s + strlen(s);
    while (end > s && isspace((unsigned char)end[-1]))
        *--end = '\0';
    return s;
}

/* Reads one line into *buf; returns its length, -1 at the end, -2 on an
 * error already set (NUL bytes, too long). */
static long read_line(Reader *r, FILE *f, const char *path, long number, char **buf, size_t *size)
{
    errno = 0;
    ssize_t n = getline(buf, size, f);
    /* An error in a material library names the scene file too. */
    const char *scene = path == r->path ? "" : r->path, *colon = path == r->path ? "" : ": ";
    if (n < 0)
        return errno ? (ptr_error_set(r->err, PTR_ERR_SCENE_UNREADABLE, "%s%s%s: %s", scene, colon,
                                      path, strerror(errno)), -2)
                     : -1;
    if (n > MAX_LINE)
        return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID, "%s%s%s:%ld: a line of %zd bytes", scene,
                             colon, path, number, n), -2;
    if (memchr(*buf, '\0', (size_t)n))
        return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID, "%s%s%s:%ld: binary data, not text",
                             scene, colon, path, number), -2;
    return (long)n;
}

/* Parses up to max finite numbers from s; returns how many. */
static int numbers(const char *s, double *out, int max, int *bad)
{
    int n = 0;
    *bad = 0;
    while (n < max) {
        while (isspace((unsigned char)*s))
            s++;
        if (!*s)
            break;
        char *end;
        double x = strtod(s, &end);
        if (end == s) {
            *bad = 1;
            break;
        }
        if (!isfinite(x))
            *bad = 1;
        out[n++] = x;
        s = end;
    }
    return n;
}

static PtrResult start_part(Reader *r, Parts *parts, const char *name, long line)
{
    if (ptr_grow((void **)&parts->items, &parts->capacity, parts->count + 1, sizeof(Part)))
        return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
    Part *p = &parts->items[parts->count];
    *p = (Part){ .name = name ? copy(name) : NULL, .line = line };
    for (int k = 0; k < 3; k++) {
        p->lo[k] = INFINITY;
        p->hi[k] = -INFINITY;
    }
    parts->current = (long)parts->count++;
    parts->named |= name != NULL;
    return PTR_OK;
}

static PtrResult add_to(Reader *r, Parts *parts, const double *p, long line, int first_corner)
{
    if (parts->current < 0 && start_part(r, parts, NULL, line) != PTR_OK)
        return r->err->code;
    Part *part = &parts->items[parts->current];
    for (int k = 0; k < 3; k++) {
        part->lo[k] = fmin(part->lo[k], p[k]);
        part->hi[k] = fmax(part->hi[k], p[k]);
    }
    if (first_corner) {
        const MaterialRun *last = part->nruns ? &part->runs[part->nruns - 1] : NULL;
        if (!last || last->material != r->material) {
            if (ptr_grow((void **)&part->runs, &part->runs_capacity, part->nruns + 1,
                     sizeof *part->runs))
                return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
            part->runs[part->nruns++] =
                (MaterialRun){ .first_triangle = part->ntris, .material = r->material };
        }
        part->faces++;
    }
    return PTR_OK;
}

/* The face just read (n corners) into the current part as a fan of
 * triangles. */
static PtrResult add_triangles(Reader *r, Parts *parts, size_t n)
{
    Part *part = &parts->items[parts->current];
    if (ptr_grow((void **)&part->tris, &part->tris_capacity, 3 * (part->ntris + n - 2),
             sizeof *part->tris))
        return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
    for (size_t c = 1; c + 1 < n; c++) {
        uint32_t *t = &part->tris[3 * part->ntris++];
        t[0] = r->corners[0], t[1] = r->corners[c], t[2] = r->corners[c + 1];
    }
    return PTR_OK;
}

static PtrResult face(Reader *r, char *s, long line)
{
    size_t corners = 0;
    char *save;
    for (char *tok = strtok_r(s, " \t\r\n", &save); tok; tok = strtok_r(NULL, " \t\r\n", &save)) {
        char *end;
        errno = 0;
        long i = strtol(tok, &end, 10);
        if (end == tok || (*end && *end != '/') || errno)
            return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID, "%s:%ld: '%.40s' is not a vertex index",
                                 r->path, line, tok);
        /* 1-based, or negative: counted back from the last vertex. */
        long index = i > 0 ? i - 1 : (long)r->nv + i;
        if (i == 0 || index < 0 || (size_t)index >= r->nv)
            return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID,
                                 "%s:%ld: vertex %ld does not exist (%zu defined so far)", r->path,
                                 line, i, r->nv);
        if ((size_t)index >= UINT32_MAX)
            return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID,
                                 "%s:%ld: vertex %ld is past the vertices ptr reads", r->path,
                                 line, i);
        const double *p = &r->v[3 * index];
        if (add_to(r, &r->objects, p, line, corners == 0) != PTR_OK ||
            add_to(r, &r->groups, p, line, corners == 0) != PTR_OK)
            return r->err->code;
        if (ptr_grow((void **)&r->corners, &r->corners_capacity, corners + 1, sizeof *r->corners))
            return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
        r->corners[corners++] = (uint32_t)index;
    }
    if (corners == 0)
        return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID, "%s:%ld: a face with no vertices",
                             r->path, line);
    if (corners < 3) /* a point or a line: no surface */
        return PTR_OK;
    if (add_triangles(r, &r->objects, corners) != PTR_OK ||
        add_triangles(r, &r->groups, corners) != PTR_OK)
        return r->err->code;
    return PTR_OK;
}

/* Splits a line into its keyword and the rest, both trimmed; returns 0 for a
 * blank line or a comment. */
/* FNV-1a. */
static uint64_t name_hash(const char *name)
{
    uint64_t h = 0xcbf29ce484222325u;
    for (const unsigned char *c = (const unsigned char *)name; *c; c++)
        h = (h ^ *c) * 0x100000001b3u;
    return h;
}

/* The slot of slots (nslots of them) that holds name, or the empty one
 * where it goes. */
static size_t slot_of(const Reader *r, const uint32_t *slots, size_t nslots, const char *name)
{
    size_t slot = name_hash(name) & (nslots - 1);
    while (slots[slot] != UINT32_MAX && strcmp(r->names[slots[slot]].text, name))
        slot = (slot + 1) & (nslots - 1);
    return slot;
}

/* Name's index among the reader's names, added if it is new. */
static PtrResult intern(Reader *r, const char *name, uint32_t *index)
{
    if (2 * (r->nnames + 1) > r->nslots) {
        const size_t nslots = r->nslots ? 2 * r->nslots : 64;
        uint32_t *slots = malloc(nslots * sizeof *slots);
        if (!slots)
            return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
        memset(slots, 0xff, nslots * sizeof *slots);
        for (size_t i = 0; i < r->nnames; i++)
            slots[slot_of(r, slots, nslots, r->names[i].text)] = (uint32_t)i;
        free(r->slots);
        r->slots = slots;
        r->nslots = nslots;
    }
    const size_t slot = slot_of(r, r->slots, r->nslots, name);
    if (r->slots[slot] == UINT32_MAX) {
        char *text = copy(name);
        if (!text ||
            ptr_grow((void **)&r->names, &r->names_capacity, r->nnames + 1, sizeof *r->names)) {
            free(text);
            return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
        }
        r->names[r->nnames] = (MaterialName){ .text = text, .scene_index = UINT32_MAX };
        r->slots[slot] = (uint32_t)r->nnames++;
    }
    *index = r->slots[slot];
    return PTR_OK;
}

static int split_keyword(char *line, char **keyword, char **rest)
{
    char *s = trim(line);
    if (!*s || *s == '#')
        return 0;
    char *r = s;
    while (*r && !isspace((unsigned char)*r))
        r++;
    if (*r)
        *r++ = '\0';
    *keyword = s;
    *rest = trim(r);
    return 1;
}

static PtrResult obj_line(Reader *r, const char *path, char *line, long number)
{
    (void)path; /* the scene file: r->path */
    char *s, *rest;
    if (!split_keyword(line, &s, &rest))
        return PTR_OK;

    if (!strcmp(s, "v")) {
        double p[3];
        int bad;
        if (numbers(rest, p, 3, &bad) < 3 || bad)
            return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID,
                                 "%s:%ld: a vertex needs three finite numbers", r->path, number);
        if (ptr_grow((void **)&r->v, &r->capacity, 3 * (r->nv + 1), sizeof(double)))
            return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
        memcpy(&r->v[3 * r->nv++], p, sizeof p);
    } else if (!strcmp(s, "f")) {
        return face(r, rest, number);
    } else if (!strcmp(s, "o")) {
        return start_part(r, &r->objects, rest, number);
    } else if (!strcmp(s, "g")) {
        return start_part(r, &r->groups, rest, number);
    } else if (!strcmp(s, "usemtl")) {
        r->material = NO_MATERIAL;
        return *rest ? intern(r, rest, &r->material) : PTR_OK;
    } else if (!strcmp(s, "mtllib")) {
        const char *slash = strrchr(r->path, '/');
        int dir = slash ? (int)(slash - r->path + 1) : 0;
        char *save;
        for (char *name = strtok_r(rest, " \t", &save); name; name = strtok_r(NULL, " \t", &save)) {
            char **libs = realloc(r->libs, (r->nlibs + 1) * sizeof *libs);
            if (!libs)
                return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
            r->libs = libs;
            size_t n = (size_t)dir + strlen(name) + 1;
            if (!(libs[r->nlibs] = malloc(n)))
                return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
            snprintf(libs[r->nlibs++], n, "%.*s%s", name[0] == '/' ? 0 : dir, r->path, name);
        }
    }
    /* Everything else (vt, vn, s, l, p, curves, ...) shapes no sphere. */
    return PTR_OK;
}

static PtrResult mtl_line(Reader *r, const char *path, char *line, long number)
{
    char *s, *rest;
    if (!split_keyword(line, &s, &rest))
        return PTR_OK;

    if (!strcmp(s, "newmtl")) {
        Mtl *m = realloc(r->mtls, (r->nmtls + 1) * sizeof *m);
        if (!m)
            return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
        r->mtls = m;
        r->mtls[r->nmtls++] = (Mtl){ .name = copy(rest), .kd = { 0.8, 0.8, 0.8 }, .ni = 1.5,
                                     .d = 1, .scene_index = UINT32_MAX };
        return PTR_OK;
    }
    static const char *const keys[] = { "Kd", "Ke", "Tf", "Ni", "d", "Tr", "Ns", "Pr", "Pm", "illum" };
    int key = -1;
    for (int k = 0; k < (int)(sizeof keys / sizeof keys[0]); k++)
        if (!strcmp(s, keys[k]))
            key = k;
    if (key < 0)
        return PTR_OK; /* maps, Ka, Ks, ...: nothing a sphere here uses */
    if (r->nmtls == 0)
        return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID, "%s: %s:%ld: %s before any newmtl",
                             r->path, path, number, s);
    Mtl *m = &r->mtls[r->nmtls - 1];
    double x[3];
    int bad, n = numbers(rest, x, 3, &bad);
    if (key == 2 && n == 0) /* Tf spectral or xyz: not modelled */
        return PTR_OK;
    if (n == 0 || bad)
        return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID, "%s: %s:%ld: %s needs finite numbers",
                             r->path, path, number, s);
    if (key <= 2 && n < 3) /* "Kd r" means r r r */
        x[1] = x[2] = x[0];
    switch (key) {
    case 0: memcpy(m->kd, x, sizeof x); break;
    case 1: memcpy(m->ke, x, sizeof x); break;
    case 2: memcpy(m->tf, x, sizeof x); m->has_tf = 1; break;
    case 3: m->ni = x[0]; break;
    case 4: m->d = x[0]; m->has_d = 1; break;
    case 5: m->tr = x[0]; m->has_tr = 1; break;
    case 6: m->ns = x[0]; break;
    case 7: m->pr = x[0]; m->has_pr = 1; break;
    case 8: m->pm = x[0]; m->has_pm = 1; break;
    case 9: m->illum = (int)x[0]; break;
    }
    return PTR_OK;
}

/* Reads a whole file with line(reader, path, line, number). */
static PtrResult read_file(Reader *r, const char *path, int required,
                           PtrResult (*line)(Reader *, const char *, char *, long))
{
    /* A material library that is not a readable file (missing, a folder, ...)
     * costs its materials, not the scene. */
    struct stat st;
    int found = stat(path, &st) == 0, regular = found && S_ISREG(st.st_mode);
    FILE *f = regular || required ? fopen(path, "rb") : NULL;
    if (!f) {
        const char *why = found && !regular ? "not a file" : strerror(errno);
        if (required)
            return ptr_error_set(r->err, PTR_ERR_SCENE_UNREADABLE, "%s: %s", path, strerror(errno));
        ptr_warn(r->warnings, "%s: material library %s cannot be read (%s); its materials are "
                              "grey diffuse", r->path, path, why);
        r->missing_lib = 1;
        return PTR_OK;
    }
    char *buf = NULL;
    size_t size = 0;
    PtrResult res = PTR_OK;
    long n, number = 0;
    while (res == PTR_OK && (n = read_line(r, f, path, ++number, &buf, &size)) >= 0)
        res = line(r, path, buf, number);
    if (res == PTR_OK && n == -2)
        res = r->err->code;
    free(buf);
    fclose(f);
    return res;
}

static int contains_sphere(const char *name)
{
    for (const char *s = name; *s; s++)
        if (!strncasecmp(s, "sphere", 6))
            return 1;
    return 0;
}

static PtrResult material_for(Reader *r, const char *name, PtrScene *scene, uint32_t *index,
                              uint32_t *grey)
{
    Mtl *m = NULL;
    for (size_t i = 0; name && i < r->nmtls; i++)
        if (r->mtls[i].name && !strcmp(r->mtls[i].name, name))
            m = &r->mtls[i];
    if (m && m->scene_index != UINT32_MAX) {
        *index = m->scene_index;
        return PTR_OK;
    }
    if (!m) {
        if (name && r->nlibs && !r->missing_lib)
            ptr_warn(r->warnings, "%s: material '%s' is not in its material library; grey diffuse",
                     r->path, name);
        if (*grey == UINT32_MAX) {
            const PtrMaterial g = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.8f), .ior = 1.5f };
            if (ptr_scene_add_material(scene, &g, grey, NULL) != PTR_OK)
                return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
        }
        *index = *grey;
        return PTR_OK;
    }
    PtrMaterial out = { .kind = PTR_MATERIAL_DIFFUSE,
                        .albedo = v3((float)m->kd[0], (float)m->kd[1], (float)m->kd[2]),
                        .emission = v3((float)m->ke[0], (float)m->ke[1], (float)m->ke[2]),
                        .ior = (float)m->ni };
    int tf = m->has_tf && (m->tf[0] != 0 || m->tf[1] != 0 || m->tf[2] != 0);
    if (tf || m->illum == 4 || m->illum == 6 || m->illum == 7 || (m->has_d && m->d < 1) ||
        (m->has_tr && m->tr > 0)) {
        out.kind = PTR_MATERIAL_DIELECTRIC;
        out.albedo = m->has_tf ? v3((float)m->tf[0], (float)m->tf[1], (float)m->tf[2]) : v3_splat(1);
    } else if ((m->has_pm && m->pm >= 0.5) || m->illum == 3) {
        out.kind = PTR_MATERIAL_METAL;
        out.fuzz = (float)(m->has_pr ? m->pr : 1.0 - sqrt(fmin(fmax(m->ns, 0), 1000) / 1000));
    }
    const char *problem = ptr_material_problem(&out);
    if (problem)
        return ptr_error_set(r->err, PTR_ERR_SCENE_INVALID, "%s: material '%s': %s", r->path,
                             m->name, problem);
    if (ptr_scene_add_material(scene, &out, index, NULL) != PTR_OK)
        return ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
    m->scene_index = *index;
    return PTR_OK;
}

/* The scene's material for a run's name (NO_MATERIAL: grey), looked up once
 * a name, so that a name missing from the material library is reported
 * once. */
static PtrResult material_of(Reader *r, uint32_t name, PtrScene *scene, uint32_t *index,
                             uint32_t *grey)
{
    if (name == NO_MATERIAL)
        return material_for(r, NULL, scene, index, grey);
    MaterialName *n = &r->names[name];
    PtrResult res = PTR_OK;
    if (n->scene_index == UINT32_MAX)
        res = material_for(r, n->text, scene, &n->scene_index, grey);
    *index = n->scene_index;
    return res;
}

/* A part's triangles over its own vertices: local vertex k is the file's
 * vertex global[k]. */
typedef struct PartMesh {
    const double *v;
    const uint32_t *global;
    const uint32_t *tris;
} PartMesh;

static void part_positions(const void *user, size_t first, size_t count, double (*out)[3])
{
    const PartMesh *m = user;
    for (size_t i = 0; i < count; i++)
        memcpy(out[i], &m->v[3 * (size_t)m->global[first + i]], sizeof out[i]);
}

static void part_gather(const void *user, const uint32_t *vertices, size_t count,
                        double (*out)[3])
{
    const PartMesh *m = user;
    for (size_t i = 0; i < count; i++)
        memcpy(out[i], &m->v[3 * (size_t)m->global[vertices[i]]], sizeof out[i]);
}

static void part_triangles(const void *user, size_t first, size_t count, uint32_t (*out)[3])
{
    const PartMesh *m = user;
    memcpy(out, &m->tris[3 * first], count * sizeof *out);
}

/* The run of faces triangle t of part p was read in: the last that starts at
 * or before it (runs of faces with no surface start where the next does). */
static const MaterialRun *run_at(const Part *p, size_t t)
{
    size_t lo = 0, hi = p->nruns;
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2;
        if (p->runs[mid].first_triangle <= t)
            lo = mid;
        else
            hi = mid;
    }
    return &p->runs[lo];
}

/* The spheres of part p (docs/scenes.md): its components, checked, each with
 * the material of its first face; local_of (one a vertex of the file, UNSET)
 * is left as it was found. Adds the components that are not spheres to
 * *skipped. */
static PtrResult part_spheres(Reader *r, Part *p, uint32_t *local_of, PtrSceneBuilder *builder,
                              PtrScene *scene, uint32_t *grey, size_t *skipped)
{
    const size_t corners = 3 * p->ntris;
    uint32_t *global = malloc((corners ? corners : 1) * sizeof *global);
    uint32_t *tris = malloc((corners ? corners : 1) * sizeof *tris);
    size_t n = 0, count = 0;
    PtrMeshSphere *spheres = NULL;
    PtrResult res = global && tris ? PTR_OK
                                   : ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory",
                                                   r->path);
    for (size_t i = 0; res == PTR_OK && i < corners; i++) {
        if (local_of[p->tris[i]] == UINT32_MAX) {
            local_of[p->tris[i]] = (uint32_t)n;
            global[n++] = p->tris[i];
        }
        tris[i] = local_of[p->tris[i]];
    }
    for (size_t k = 0; global && k < n; k++)
        local_of[global[k]] = UINT32_MAX;
    const PartMesh mesh = { r->v, global, tris };
    const PtrMeshSource source = { .vertex_count = n, .triangle_count = p->ntris,
                                   .positions = part_positions, .gather = part_gather,
                                   .triangles = part_triangles,
                                   .user = &mesh };
    if (res == PTR_OK)
        res = ptr_mesh_spheres(&source, r->path, &spheres, &count, NULL, r->err);
    for (size_t c = 0; res == PTR_OK && c < count; c++) {
        if (!spheres[c].is_sphere) {
            ++*skipped;
            continue;
        }
        uint32_t material;
        res = material_of(r, run_at(p, spheres[c].first_triangle)->material, scene, &material,
                          grey);
        if (res == PTR_OK && ptr_builder_add_sphere(builder, spheres[c].centre, spheres[c].radius,
                                                    material, NULL))
            res = ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
    }
    free(spheres);
    free(global);
    free(tris);
    return res;
}

static PtrResult build(Reader *r, const PtrImportOptions *options, PtrScene *scene)
{
    /* Objects; in a file without any o, groups. */
    const Parts *parts = r->objects.named || !r->groups.named ? &r->objects : &r->groups;
    const char *base = strrchr(r->path, '/') ? strrchr(r->path, '/') + 1 : r->path;
    PtrSceneBuilder builder;
    ptr_builder_init(&builder, scene, options);
    uint32_t grey = UINT32_MAX;
    size_t fitted = 0, skipped = 0, named = 0;
    char names[256] = "";
    int more = 0; /* names that did not fit */
    const int fit_all = options && options->fit_all_objects;
    uint32_t *local_of = fit_all ? NULL : malloc((r->nv ? r->nv : 1) * sizeof *local_of);
    PtrResult res = fit_all || local_of ? PTR_OK
                                        : ptr_error_set(r->err, PTR_ERR_NOMEM,
                                                        "%s: out of memory", r->path);
    if (local_of)
        memset(local_of, 0xff, (r->nv ? r->nv : 1) * sizeof *local_of);
    for (size_t i = 0; res == PTR_OK && i < parts->count; i++) {
        Part *p = &parts->items[i];
        const char *name = p->name ? p->name : base;
        if (!p->faces)
            continue;
        if (!contains_sphere(name) && !fit_all) {
            ptr_warn(r->warnings, "%s:%ld: object '%s' is skipped: its name lacks 'sphere' "
                                  "(--fit-all-objects fits every object)", r->path, p->line, name);
            continue;
        }
        double centre[3], extent = 0;
        for (int k = 0; k < 3; k++) {
            centre[k] = 0.5 * (p->lo[k] + p->hi[k]);
            extent = fmax(extent, p->hi[k] - p->lo[k]);
        }
        if (!(extent > 0) || !isfinite(extent) || !((float)(0.5 * extent) > 0)) {
            res = ptr_error_set(r->err, PTR_ERR_SCENE_INVALID,
                                "%s:%ld: object '%s': its vertices span no space", r->path,
                                p->line, name);
            break;
        }
        const size_t before = skipped;
        uint32_t material; /* --fit-all-objects: the object's first face's */
        if (!fit_all)
            res = part_spheres(r, p, local_of, &builder, scene, &grey, &skipped);
        else if ((res = material_of(r, p->runs[0].material, scene, &material, &grey)) == PTR_OK &&
                 ptr_builder_add_sphere(&builder, centre, 0.5 * extent, material, NULL))
            res = ptr_error_set(r->err, PTR_ERR_NOMEM, "%s: out of memory", r->path);
        if (skipped > before) {
            const size_t used = strlen(names);
            char one[sizeof names];
            const int n = snprintf(one, sizeof one, "%sobject '%s' (line %ld)", used ? ", " : "",
                                   name, p->line);
            if (n < 0 || used + (size_t)n >= sizeof names)
                more = 1;
            else
                memcpy(names + used, one, (size_t)n + 1);
            named++;
        }
        fitted++;
    }
    free(local_of);
    if (res == PTR_OK && skipped)
        ptr_warn(r->warnings, "%s: %zu mesh part%s not drawn: %s not a sphere (docs/scenes.md, "
                 "\"What becomes a sphere\"): %s%s", r->path, skipped, skipped == 1 ? "" : "s",
                 skipped == 1 ? "it is" : "they are", names, more ? ", ..." : "");
    if (res == PTR_OK && fitted == 0 && r->nv == 0)
        res = ptr_error_set(r->err, PTR_ERR_SCENE_INVALID, "%s: no vertices: not an OBJ file?",
                            r->path);
    if (res == PTR_OK)
        res = ptr_import_finish(&builder, r->path, r->err);
    ptr_builder_free(&builder);
    return res;
}

static void free_parts(Parts *parts)
{
    for (size_t i = 0; i < parts->count; i++) {
        free(parts->items[i].name);
        free(parts->items[i].runs);
        free(parts->items[i].tris);
    }
    free(parts->items);
}

PtrResult ptr_import_obj(const char *path, const PtrImportOptions *options, PtrScene *scene,
                         PtrStrings *warnings, PtrError *err)
{
    Reader r = { .path = path, .warnings = warnings, .err = err,
                 .objects = { .current = -1 }, .groups = { .current = -1 },
                 .material = NO_MATERIAL };
    PtrResult res = read_file(&r, path, 1, obj_line);
    for (size_t i = 0; res == PTR_OK && i < r.nlibs; i++) {
        if (options && options->dependencies)
            ptr_warn(options->dependencies, "%s", r.libs[i]);
        res = read_file(&r, r.libs[i], 0, mtl_line);
    }
    if (res == PTR_OK)
        res = build(&r, options, scene);
    free(r.v);
    free_parts(&r.objects);
    free_parts(&r.groups);
    for (size_t i = 0; i < r.nnames; i++)
        free(r.names[i].text);
    free(r.names);
    free(r.slots);
    free(r.corners);
    for (size_t i = 0; i < r.nlibs; i++)
        free(r.libs[i]);
    free(r.libs);
    for (size_t i = 0; i < r.nmtls; i++)
        free(r.mtls[i].name);
    free(r.mtls);
    return res;
}
