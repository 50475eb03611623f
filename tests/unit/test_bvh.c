/* The tree: its structure, its determinism, and its traversal against brute
 * force on hard sphere sets, bit for bit. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "accel/bvh.h"
#include "accel/bvh_split.h"
#include "accel/isect.h"
#include "base/memory.h"
#include "bvh_scenes.h"
#include "importer.h"
#include "render/render.h"
#include "test.h"

/* A tree over all of s's spheres on this many threads (0: one per CPU),
 * at the CPU level in force (PTR_CPUMASK caps it; test_tree_bytes and
 * test_split_boxes build with each binning). */
static void build_tree(PtrBvh *bvh, PtrSpheres *s, int threads)
{
    CHECK_INT(ptr_bvh_build(bvh, s, s->count, threads, ptr_cpu_level(), NULL), PTR_OK);
}

/* Whether the build's binning at this CPU level is another kernel than the
 * level below's: the tests that build with each binning build once a
 * kernel. */
static int binning_is_new(int level)
{
    return level == PTR_CPU_NONE || bvh_bin_for_level((PtrCpuLevel)level).bin !=
                                        bvh_bin_for_level((PtrCpuLevel)(level - 1)).bin;
}

/* Gives every sphere of s a colour that is its position in the file (the
 * colours move with the spheres), for the checks below to read back. */
static void tag_file_order(PtrScene *s)
{
    for (size_t i = 0; i < s->spheres.count; i++) {
        const uint16_t tag[3] = { (uint16_t)i, (uint16_t)(i >> 16), 0 };
        CHECK_INT(ptr_scene_set_sphere_color16(s, i, tag, NULL), PTR_OK);
    }
}

/* The place in the file of sphere i, as tag_file_order tagged it. */
static uint32_t file_position(const PtrSpheres *s, size_t i)
{
    return s->color[3 * i] | (uint32_t)s->color[3 * i + 1] << 16;
}

/* The material give_materials gives the sphere at this place in the file. */
static uint32_t material_at(uint32_t file, uint32_t materials)
{
    return (uint32_t)((uint64_t)file * 7919 % materials);
}

/* Gives s this many materials in all, each sphere one by its place. */
static void give_materials(PtrScene *s, uint32_t materials)
{
    const PtrMaterial grey = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = { 0.5f, 0.5f, 0.5f } };
    uint32_t index = 0;
    while (s->material_count < materials)
        CHECK_INT(ptr_scene_add_material(s, &grey, &index, NULL), PTR_OK);
    for (size_t i = 0; i < s->spheres.count; i++)
        ptr_sphere_set_material(&s->spheres, i, material_at((uint32_t)i, materials));
}

/* Walks the tree: every sphere in the tree is in exactly one leaf, every
 * box contains its spheres and its subtree's boxes, leaves hold 1 to
 * PTR_BVH_LEAF_MAX spheres in file order, and the depth is as stated. */
static void check_node(const PtrBvh *bvh, const PtrSpheres *s, uint32_t index,
                       int level, const float parent_lo[3], const float parent_hi[3],
                       unsigned char *seen, int *ok)
{
    const PtrBvhNode *n = &bvh->nodes[index];
    const float *lo[3] = { n->lower_x, n->lower_y, n->lower_z };
    const float *hi[3] = { n->upper_x, n->upper_y, n->upper_z };
    if (level > bvh->depth)
        *ok = 0;
    for (int k = 0; k < PTR_BVH_WIDTH; k++) {
        if (lo[0][k] == INFINITY) { /* empty lane */
            for (int a = 0; a < 3; a++)
                if (lo[a][k] != INFINITY || hi[a][k] != -INFINITY)
                    *ok = 0;
            if (n->leaf_count[k] != 0)
                *ok = 0;
            continue;
        }
        float box_lo[3], box_hi[3];
        for (int a = 0; a < 3; a++) {
            box_lo[a] = lo[a][k];
            box_hi[a] = hi[a][k];
            if (parent_lo && (box_lo[a] < parent_lo[a] || box_hi[a] > parent_hi[a]))
                *ok = 0;
        }
        uint32_t count = n->leaf_count[k];
        if (count == 0) {
            if (n->child[k] <= index || n->child[k] >= bvh->node_count)
                *ok = 0;
            else
                check_node(bvh, s, n->child[k], level + 1, box_lo, box_hi, seen, ok);
            continue;
        }
        uint32_t first = n->child[k];
        if (count > PTR_BVH_LEAF_MAX || first < bvh->huge_count || first + count > s->count) {
            *ok = 0;
            continue;
        }
        for (uint32_t i = first; i < first + count; i++) {
            seen[i]++;
            if (i > first && file_position(s, i) <= file_position(s, i - 1))
                *ok = 0;
            float c[3] = { s->cx[i], s->cy[i], s->cz[i] };
            for (int a = 0; a < 3; a++)
                if (!(c[a] - s->radius[i] >= box_lo[a] && c[a] + s->radius[i] <= box_hi[a]))
                    *ok = 0;
        }
    }
}

/* The tree over s, whose spheres were given materials by give_materials
 * (all 0: 1). */
static void check_structure(const PtrBvh *bvh, const PtrSpheres *s, uint32_t materials,
                            const char *name)
{
    unsigned char *seen = calloc(s->count + 1, 1);
    int ok = seen != NULL && s->id == NULL; /* the build frees the ids */
    for (size_t i = 0; ok && i < bvh->huge_count; i++) {
        seen[i]++;
        if (i > 0 && file_position(s, i) <= file_position(s, i - 1))
            ok = 0;
    }
    if (ok && bvh->nodes)
        check_node(bvh, s, 0, 0, NULL, NULL, seen, &ok);
    for (size_t i = 0; ok && i < s->count; i++)
        if (seen[i] != 1)
            ok = 0;
    /* The spheres are a permutation of the file's. */
    memset(seen, 0, s->count);
    for (size_t i = 0; ok && i < s->count; i++)
        if (file_position(s, i) >= s->count || seen[file_position(s, i)]++)
            ok = 0;
    /* The rest of each sphere went with it. */
    for (size_t i = 0; ok && i < s->count; i++)
        if (ptr_sphere_material(s, i) != material_at(file_position(s, i), materials) ||
            s->color[3 * i + 2] != 0)
            ok = 0;
    /* Padding: at least a block of NaN radii past the last sphere. */
    for (size_t i = s->count; ok && i < s->count + PTR_SPHERE_BLOCK; i++)
        if (i >= s->capacity || !isnan(s->radius[i]))
            ok = 0;
    if (!ok)
        fprintf(stderr, "%s: tree structure broken\n", name);
    CHECK(ok);
    free(seen);
}

/* Rays against the tree and against brute force: over the same arrays, the
 * same answer; over the file-order copy, the same t. */
static void check_rays(const PtrScene *file_order, const PtrScene *built, const PtrBvh *bvh,
                       int rays, const char *name)
{
    PtrRng rng = ptr_rng_for_sample(5, 0, 0);
    int differences = 0, hits = 0;
    for (int i = 0; i < rays; i++) {
        PtrRay ray = bvh_scene_ray(&file_order->spheres, &rng);
        if (i % 7 == 0)
            ray.tmin = 1e-3f;
        if (i % 5 == 0) /* a finite tmax, as a shadow ray would have */
            ray.tmax = bvh_uniform(&rng, 1.0f, 30.0f);
        PtrHit brute, tree, file;
        int brute_found = ptr_closest_hit_c(&ray, &built->spheres, built->spheres.count, &brute);
        int tree_found = ptr_bvh_closest_hit_c(&ray, bvh, &built->spheres, &tree);
        int file_found = ptr_closest_hit_c(&ray, &file_order->spheres, file_order->spheres.count,
                                           &file);
        hits += brute_found;
        if (brute_found != tree_found || memcmp(&brute.t, &tree.t, sizeof brute.t) ||
            brute.sphere != tree.sphere || file_found != tree_found ||
            memcmp(&file.t, &tree.t, sizeof file.t)) {
            if (differences++ < 5)
                fprintf(stderr,
                        "%s: ray %d: brute t %a sphere %u, tree t %a sphere %u, file order t %a\n",
                        name, i, brute.t, brute.sphere, tree.t, tree.sphere, file.t);
        }
    }
    CHECK_INT(differences, 0);
    CHECK(hits > rays / 10); /* the rays do meet the spheres */
}

static void test_scenes(void)
{
    for (int kind = 0; kind < BVH_SCENE_KIND_COUNT; kind++)
        for (int size = 0; size < 2; size++) {
            int n = size ? 2000 : 37;
            PtrScene a, b;
            ptr_scene_init(&a);
            ptr_scene_init(&b);
            CHECK(bvh_scene_make(&a, (BvhSceneKind)kind, n, 1));
            CHECK(bvh_scene_make(&b, (BvhSceneKind)kind, n, 1));
            tag_file_order(&b);
            /* Materials in 2 bytes, which fit in a prim with the colours;
             * in 4, which do not: then the prims hold their places. */
            const uint32_t materials = size ? 70001 : 300;
            give_materials(&b, materials);
            CHECK_INT(bvh_rest_by_place(&b.spheres), size);
            /* Ids, as an importer gives them (in file order), the build
             * frees. */
            if (size) {
                CHECK_INT(ptr_spheres_make_ids(&b.spheres, NULL), PTR_OK);
                for (size_t i = 0; i < b.spheres.count; i++)
                    b.spheres.id[i] = (uint32_t)i;
            }
            PtrBvh bvh;
            build_tree(&bvh, &b.spheres, 0);
            check_structure(&bvh, &b.spheres, materials, bvh_scene_names[kind]);
            check_rays(&a, &b, &bvh, size ? 10000 : 20000, bvh_scene_names[kind]);
            ptr_bvh_free(&bvh);
            ptr_scene_free(&a);
            ptr_scene_free(&b);
        }
}

/* The rule itself (scene.h), as the builder and the tree apply it: of the
 * spheres above the limit, the PTR_HUGE_MAX largest, on equal radii the
 * first in the file, handed back in the file's order. 40 spheres offered in
 * the arrays' order, whose file positions run backwards: radius 1 (below
 * the limit of 2) for even positions, else 10 for the positions of 30 and
 * over and 5 below. */
static void test_huge_rule(void)
{
    PtrHugeChoice choice = { .limit = 2.0 };
    for (size_t i = 0; i < 40; i++) {
        const size_t file = 39 - i;
        ptr_huge_offer(&choice, i, file, file % 2 == 0 ? 1.0 : file >= 30 ? 10.0 : 5.0);
    }
    ptr_huge_file_order(&choice);
    CHECK_INT(choice.count, PTR_HUGE_MAX);
    /* Odd positions: the five of radius 10 (31 .. 39), then of the fifteen
     * of radius 5 the first eleven in the file (1 .. 21). */
    size_t wrong = 0;
    for (size_t k = 0; k < choice.count; k++) {
        const size_t file = choice.sphere[k].file_position;
        const size_t expected = k < 11 ? 2 * k + 1 : 31 + 2 * (k - 11);
        wrong += file != expected || choice.sphere[k].index != 39 - file ||
                 choice.sphere[k].radius != (file >= 30 ? 10.0 : 5.0);
    }
    CHECK_INT(wrong, 0);
}

/* The huge grounds stay out of the tree; ordinary spheres do not. */
static void test_huge(void)
{
    const BvhSceneKind kinds[] = { BVH_SCENE_GROUND, BVH_SCENE_BIG_GROUND, BVH_SCENE_RANDOM };
    for (int k = 0; k < 3; k++) {
        PtrScene s;
        ptr_scene_init(&s);
        CHECK(bvh_scene_make(&s, kinds[k], 500, 2));
        tag_file_order(&s);
        PtrBvh bvh;
        build_tree(&bvh, &s.spheres, 1);
        CHECK_INT(bvh.huge_count, k < 2 ? 1 : 0);
        if (k < 2)
            CHECK_INT(file_position(&s.spheres, 0), 0);
        ptr_bvh_free(&bvh);
        ptr_scene_free(&s);
    }
}

static int compare_floats(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Builds trees over spheres of these radii (in a grid) on 1, 2 and 7
 * threads and checks that each keeps out the huge spheres the rule gives
 * (scene.h), with the tree's limit: 100 times the median radius
 * (bvh_prims.c's HUGE_RATIO), found here by sorting. */
static void check_huge_choice(const float *radius, int count)
{
    float *sorted = malloc((size_t)count * sizeof *sorted);
    CHECK(sorted != NULL);
    memcpy(sorted, radius, (size_t)count * sizeof *sorted);
    qsort(sorted, (size_t)count, sizeof *sorted, compare_floats);
    PtrHugeChoice rule = { .limit = sorted[count / 2] * 100.0f };
    free(sorted);
    for (int i = 0; i < count; i++)
        ptr_huge_offer(&rule, (size_t)i, (size_t)i, radius[i]);
    ptr_huge_file_order(&rule);
    for (int t = 0; t < 3; t++) {
        const int threads[] = { 1, 2, 7 };
        PtrScene s;
        ptr_scene_init(&s);
        for (int i = 0; i < count; i++)
            CHECK_INT(ptr_scene_add_sphere(&s, v3((float)(i % 60) * 5.0f, (float)(i / 60) * 5.0f,
                                                  -10.0f),
                                           radius[i], 0, NULL),
                      PTR_OK);
        tag_file_order(&s);
        PtrBvh bvh;
        build_tree(&bvh, &s.spheres, threads[t]);
        CHECK_INT(bvh.huge_count, rule.count);
        size_t wrong = 0;
        for (size_t k = 0; k < bvh.huge_count && k < rule.count; k++)
            wrong += file_position(&s.spheres, k) !=
                     rule.sphere[k].file_position;
        CHECK_INT(wrong, 0);
        ptr_bvh_free(&bvh);
        ptr_scene_free(&s);
    }
}

/* The tree's limit and choice of huge spheres, on any thread count as the
 * rule gives them, on 3,001 spheres of which 1,500 have radius 0.7, one 1.1
 * and the rest 1.7, so that the median is 1.1 (whose low 16 bits are not
 * zero) and the limit L = 1.1f * 100. Of the 1.7s, every 98th (spread over
 * every thread's share of the arrays) is replaced:
 * - by L (not huge) or the next float above it (huge), 15 of each: a limit
 *   one float off either way, from a median one float or one place off,
 *   moves 15 spheres in or out;
 * - by 100 (not huge), 150, 200 or 250: 22 huge ones with equal radii, more than
 *   PTR_HUGE_MAX: the pieces' choices joined must keep the largest, on equal
 *   radii the first in the file. */
static void test_huge_threads(void)
{
    enum { COUNT = 3001 };
    static float radius[COUNT];
    const float limit = 1.1f * 100.0f, above = nextafterf(limit, INFINITY);
    for (int i = 0; i < COUNT; i++)
        radius[i] = i == COUNT / 2 ? 1.1f : i % 2 ? 0.7f : 1.7f;
    for (int i = 98, k = 0; i < COUNT; i += 98, k++) /* a 1.7: the median stays */
        radius[i] = k % 2 ? limit : above;
    check_huge_choice(radius, COUNT);
    for (int i = 98, k = 0; i < COUNT; i += 98, k++)
        radius[i] = k % 4 == 0 ? 100.0f : 100.0f + 50.0f * (float)(k % 4);
    check_huge_choice(radius, COUNT);
}

/* Whether b, built over sb, is a built over sa to the byte: its nodes, and
 * the spheres in the same order (their tags: tag_file_order). */
static void check_same_tree(const PtrBvh *a, const PtrScene *sa, const PtrBvh *b,
                            const PtrScene *sb)
{
    CHECK_INT(b->depth, a->depth);
    CHECK_INT(b->huge_count, a->huge_count);
    CHECK(b->node_count == a->node_count &&
          !memcmp(b->nodes, a->nodes, b->node_count * sizeof *b->nodes));
    CHECK(sb->spheres.count == sa->spheres.count &&
          !memcmp(sb->spheres.color, sa->spheres.color,
                  sb->spheres.count * 3 * sizeof *sb->spheres.color));
}

/* The same tree bytes and sphere order with 1, 2 and 7 threads, on a set
 * with many tasks. */
static void test_threads(void)
{
    PtrBvh first = { 0 };
    PtrScene first_scene;
    for (int t = 0; t < 3; t++) {
        const int threads[] = { 1, 2, 7 };
        PtrScene s;
        ptr_scene_init(&s);
        CHECK(bvh_scene_make(&s, BVH_SCENE_CLUSTERS, 150000, 3));
        tag_file_order(&s);
        PtrBvh bvh;
        build_tree(&bvh, &s.spheres, threads[t]);
        if (t == 0) {
            first = bvh;
            first_scene = s;
            CHECK(bvh.node_count > 1000);
            continue;
        }
        check_same_tree(&first, &first_scene, &bvh, &s);
        ptr_bvh_free(&bvh);
        ptr_scene_free(&s);
    }
    ptr_bvh_free(&first);
    ptr_scene_free(&first_scene);
}

/* FNV-1a over bytes, for test_tree_bytes. */
static uint64_t fnv1a(uint64_t h, const void *data, size_t size)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; i++)
        h = (h ^ p[i]) * UINT64_C(0x100000001b3);
    return h;
}

/* The tree's bytes, for test_tree_bytes: its nodes, and the spheres in the
 * order the build leaves them (centres, radii and the tags of their places
 * in the file). */
static uint64_t tree_hash(const PtrBvh *bvh, const PtrSpheres *sp)
{
    uint64_t h = fnv1a(UINT64_C(0xcbf29ce484222325), bvh->nodes,
                       bvh->node_count * sizeof *bvh->nodes);
    h = fnv1a(h, sp->cx, sp->count * sizeof *sp->cx);
    h = fnv1a(h, sp->cy, sp->count * sizeof *sp->cy);
    h = fnv1a(h, sp->cz, sp->count * sizeof *sp->cz);
    h = fnv1a(h, sp->radius, sp->count * sizeof *sp->radius);
    /* Each colour as the 8 bytes it was stored in when the values were
     * set, 65535 the fourth. */
    for (size_t i = 0; i < sp->count; i++) {
        const uint16_t entry[4] = { sp->color[3 * i], sp->color[3 * i + 1], sp->color[3 * i + 2],
                                    UINT16_MAX };
        h = fnv1a(h, entry, sizeof entry);
    }
    return h;
}

/* Makes a set of spheres in s (initialised, empty), the same each time. */
typedef void (*SetMaker)(PtrScene *s);

/* The set make makes, built on one thread: every sphere once (huge_count
 * of them out of the tree), and brute force's answers to rays; and built
 * on three threads, the same tree. Returns its tree_hash. */
static uint64_t check_one_and_three_threads(SetMaker make, size_t huge_count, int rays,
                                            const char *name)
{
    uint64_t hash = 0;
    PtrScene file;
    ptr_scene_init(&file);
    make(&file);
    PtrBvh first = { 0 };
    PtrScene first_scene;
    for (int t = 0; t < 2; t++) {
        PtrScene s;
        ptr_scene_init(&s);
        make(&s);
        tag_file_order(&s);
        PtrBvh bvh;
        build_tree(&bvh, &s.spheres, t ? 3 : 1);
        CHECK(bvh.huge_count == huge_count);
        if (t == 0) {
            check_structure(&bvh, &s.spheres, 1, name);
            check_rays(&file, &s, &bvh, rays, name);
            hash = tree_hash(&bvh, &s.spheres);
            first = bvh;
            first_scene = s;
            continue;
        }
        check_same_tree(&first, &first_scene, &bvh, &s);
        ptr_bvh_free(&bvh);
        ptr_scene_free(&s);
    }
    ptr_bvh_free(&first);
    ptr_scene_free(&first_scene);
    ptr_scene_free(&file);
    return hash;
}

enum { ROOT_SORT_COUNT = PTR_PAGE_STEP + (1 << 16) + 4099, ROOT_SORT_BIG = 20 };

/* test_root_sort's set: clusters, with spheres above the huge limit (the
 * limit: 100 x the median radius, about 0.85) at the edges of blocks and
 * steps. */
static void make_root_sort_set(PtrScene *s)
{
    static const size_t big[ROOT_SORT_BIG] = {
        0,       1,       5,       65535,   65536,   65539,   131071,
        500000,  1048573, 1048574, 1048575, 1048576, 1048577, 1048580,
        1114111, 1114112, 1114113, ROOT_SORT_COUNT - 3, ROOT_SORT_COUNT - 2, ROOT_SORT_COUNT - 1
    };
    CHECK(bvh_scene_make(s, BVH_SCENE_CLUSTERS, ROOT_SORT_COUNT, 9));
    for (size_t k = 0; k < ROOT_SORT_BIG; k++)
        s->spheres.radius[big[k]] = 100.0f;
}

/* The root's children, into which the prims are sorted as they are copied
 * (bvh_prims.c), over more spheres than a page step (PTR_PAGE_STEP), so
 * in several steps of several blocks (of 65,536) each, with spheres above
 * the huge limit at the edges of blocks and steps: 20 of them, so that the
 * tree keeps out the first PTR_HUGE_MAX and holds the other 4. On 1 and 3
 * threads the same tree, every sphere once, and brute force's answers. */
static void test_root_sort(void)
{
    (void)check_one_and_three_threads(make_root_sort_set, PTR_HUGE_MAX, 100, "root sort");
}

/* 600,000 spheres at one centre: the root's samples give no split, nor do
 * those of its children (75,000 each, over the 65,536 a node is planned
 * above), so both are split in the middle of their order; the tree is
 * still whole, and answers as brute force does. */
static void test_plans_without_split(void)
{
    PtrScene file, s;
    ptr_scene_init(&file);
    ptr_scene_init(&s);
    CHECK(bvh_scene_make(&file, BVH_SCENE_SAME_CENTRE, 600000, 3));
    CHECK(bvh_scene_make(&s, BVH_SCENE_SAME_CENTRE, 600000, 3));
    tag_file_order(&s);
    PtrBvh bvh;
    build_tree(&bvh, &s.spheres, 2);
    check_structure(&bvh, &s.spheres, 1, "one centre, planned");
    check_rays(&file, &s, &bvh, 100, "one centre, planned");
    ptr_bvh_free(&bvh);
    ptr_scene_free(&s);
    ptr_scene_free(&file);
}

static void make_two_levels_set(PtrScene *s)
{
    CHECK(bvh_scene_make(s, BVH_SCENE_RANDOM, 5000000, 4));
}

/* 5,000,000 random spheres: the parts' children (planned, of some 78,000
 * spheres each, over the 65,536 a node is planned above) are planned with
 * them and sorted in the same pass (plan_below), both those built inline
 * (31 of them) and the tasks (of at most 78,125 spheres; 33), which then
 * build on their sorted children. The tree is whole, answers as brute
 * force does, is the same on one thread and three, and has the bytes it
 * had when this path was made (as test_tree_bytes' sets: a build that
 * planned no grandchildren, or planned them otherwise, shows here). Its
 * layout takes its nodes' pages from the page bank, in five batches. */
static void test_two_levels_planned(void)
{
    const uint64_t hash =
        check_one_and_three_threads(make_two_levels_set, 0, 10, "two levels planned");
    if (hash != UINT64_C(0x9461fc828aba9779))
        fprintf(stderr, "two levels planned: the tree's bytes hash to %016llx\n",
                (unsigned long long)hash);
    CHECK(hash == UINT64_C(0x9461fc828aba9779));
}

/* Random splits for a plan of count children, each on a coordinate of
 * about -8 .. 8 in 4 to 32 bins of its own (a scale of 0, as a flat box's
 * axis has, in one split of eight). */
static void random_plan(PtrRng *rng, int count, BvhChildren *plan)
{
    *plan = (BvhChildren){ .count = count };
    for (int s = 1; s < count; s++) {
        const int bins = 4 + (int)(ptr_rng_float(rng) * 29.0f);
        const float base = bvh_uniform(rng, -17.0f, -15.0f);
        plan->source[s] = (int)(ptr_rng_float(rng) * (float)s);
        plan->test[s] = (BvhSplitTest){
            .axis = (s + count) % 3,
            .split_bin = (int)(ptr_rng_float(rng) * (float)(bins - 1)),
            .base = base,
            .scale = ptr_rng_float(rng) < 0.125f ? 0.0f : (float)bins * 0.99999f / (-2.0f * base),
            .last = (float)(bins - 1),
        };
    }
}

/* The child of plan that p goes to, its splits made one at a time. */
static int plan_child(const BvhChildren *plan, const BvhPrim *p)
{
    int in = 0;
    for (int s = 1; s < plan->count; s++)
        if (in == plan->source[s] &&
            bvh_goes_right_at(&plan->test[s], p->centre[plan->test[s].axis]))
            in = s;
    return in;
}

/* Checks that plan's children tile begin .. end in bvh_children_order's
 * order, that each holds the prims its splits send it, in the order they
 * came if ordered (else sorted into its own children), and that each box is
 * its prims' to the bit. With seen, that the prims are those of begin ..
 * end (their rest), each once. */
static void check_children(const BvhPrim *prims, float magnitude, size_t begin, size_t end,
                           const BvhChildren *plan, int ordered, unsigned char *seen)
{
    int order[PTR_BVH_WIDTH];
    bvh_children_order(plan, order);
    size_t next = begin;
    for (int j = 0; j < plan->count; j++) {
        const int k = order[j];
        CHECK_INT(plan->begin[k], next);
        next = plan->end[k];
        float lower[3] = { INFINITY, INFINITY, INFINITY },
              upper[3] = { -INFINITY, -INFINITY, -INFINITY };
        for (size_t i = plan->begin[k]; i < plan->end[k]; i++) {
            /* In the order they came. */
            CHECK(!ordered || i == plan->begin[k] || prims[i].rest > prims[i - 1].rest);
            CHECK_INT(plan_child(plan, &prims[i]), k);
            if (seen) {
                CHECK(prims[i].rest >= begin && prims[i].rest < end && !seen[prims[i].rest]);
                seen[prims[i].rest] = 1;
            }
            float lo[3], hi[3];
            bvh_prim_box(&prims[i], magnitude, lo, hi);
            for (int a = 0; a < 3; a++) {
                lower[a] = ptr_minf(lower[a], lo[a]);
                upper[a] = ptr_maxf(upper[a], hi[a]);
            }
        }
        CHECK(!memcmp(lower, plan->lower[k], sizeof lower));
        CHECK(!memcmp(upper, plan->upper[k], sizeof upper));
    }
    CHECK_INT(next, end);
}

/* Whether bvh_least_right(c) splits x as c's split does, x in c's box. */
static int splits_as_test(const BvhCandidate *c, float least_right, float x)
{
    const BvhSplitTest t = bvh_split_test(c);
    return x < c->lower[c->axis] || x > c->upper[c->axis] ||
           (x >= least_right) == bvh_goes_right_at(&t, x);
}

/* bvh_least_right, with which the partitions test a prim by one
 * comparison, against bvh_goes_right_at's arithmetic: on splits of boxes
 * from 1e-30 to 1e30 wide, up to 1e30 from the origin on either side or
 * across it, a few floats wide, and up to FLT_MAX (whose doubled centres
 * overflow), of 4 to 32 bins and each of their split bins, the 64 floats
 * either side of the least right centre and random ones in the box go the
 * same way by both. */
static void test_least_right(void)
{
    PtrRng rng = ptr_rng_for_sample(7, 0, 0);
    int differ = 0;
    for (int n = 0; n < 4000; n++) {
        BvhCandidate c = { .axis = (int)(ptr_rng_next(&rng) % 3) };
        const int a = c.axis;
        const float width = powf(10.0f, bvh_uniform(&rng, -30.0f, 30.0f));
        const float centre = powf(10.0f, bvh_uniform(&rng, -30.0f, 30.0f)) *
                             (ptr_rng_next(&rng) & 1 ? -1.0f : 1.0f);
        switch (n % 5) {
        case 0: /* near the origin or across it */
            c.lower[a] = -width * bvh_uniform(&rng, 0.0f, 1.0f);
            c.upper[a] = c.lower[a] + width;
            break;
        case 1: /* a few floats wide */
            c.lower[a] = centre;
            c.upper[a] = centre;
            for (int k = 1 + (int)(ptr_rng_next(&rng) % 8); k > 0; k--)
                c.upper[a] = nextafterf(c.upper[a], INFINITY);
            break;
        case 2: /* out to FLT_MAX, where doubled centres overflow */
            c.lower[a] = 0.5f * FLT_MAX;
            c.upper[a] = FLT_MAX;
            if (ptr_rng_next(&rng) & 1) {
                c.lower[a] = -FLT_MAX;
                c.upper[a] = -0.5f * FLT_MAX;
            }
            break;
        default:
            c.lower[a] = ptr_minf(centre, centre + width);
            c.upper[a] = ptr_maxf(centre, centre + width);
            break;
        }
        const float extent = 2.0f * (c.upper[a] - c.lower[a]);
        if (!(extent > 0.0f) || !isfinite(extent))
            continue; /* no split on this axis, as bvh_candidate_init finds */
        c.bins = 4 + (int)(ptr_rng_next(&rng) % 29);
        c.split_bin = (int)(ptr_rng_next(&rng) % (uint64_t)(c.bins - 1));
        c.bin_base[a] = 2.0f * c.lower[a];
        c.bin_scale[a] = (float)c.bins * 0.99999f / extent;
        const float least_right = bvh_least_right(&c);
        int ok = 1;
        float x = least_right, y = least_right;
        for (int k = 0; k < 64; k++) {
            ok &= splits_as_test(&c, least_right, x) && splits_as_test(&c, least_right, y);
            x = nextafterf(x, -INFINITY);
            y = nextafterf(y, INFINITY);
        }
        for (int k = 0; k < 64; k++)
            ok &= splits_as_test(&c, least_right,
                                 c.lower[a] + (c.upper[a] - c.lower[a]) * ptr_rng_float(&rng));
        if (!ok && differ++ < 5)
            fprintf(stderr, "least right %a of [%a, %a], %d bins, split bin %d: splits "
                    "otherwise than the bins\n", least_right, c.lower[a], c.upper[a], c.bins,
                    c.split_bin);
        CHECK(ok);
    }
}

/* The boxes a binned split gives its halves, the bins', against the boxes
 * of the prims the partition sends each way, bit for bit, with each
 * binning: on ranges of 17 to 3,000 prims, some of whose corners are
 * exactly 0 (a centre equal to its extent, or to minus it: a lower corner
 * of +0, negated to -0 in the bins, or an upper one of +0), some on one
 * centre. */
static void test_split_boxes(void)
{
    enum { MAX = 3000 };
    const float magnitude = 4.0f;
    BvhPrim *prims = malloc(MAX * sizeof *prims),
            *scratch = malloc(BVH_PLANNED_ABOVE * sizeof *scratch);
    CHECK(prims && scratch);
    PtrRng rng = ptr_rng_for_sample(11, 0, 0);
    int splits = 0;
    for (int level = PTR_CPU_NONE; level <= (int)ptr_cpu_level(); level++) {
        if (!binning_is_new(level))
            continue;
        const BvhPrimSet set = { prims, magnitude, bvh_bin_for_level((PtrCpuLevel)level).bin };
        for (int n = 0; n < 300; n++) {
            const size_t count = 17 + ptr_rng_next(&rng) % (MAX - 16);
            for (size_t i = 0; i < count; i++) {
                BvhPrim *p = &prims[i];
                p->radius = bvh_uniform(&rng, 0.01f, 0.3f);
                p->rest = i;
                const float extent = bvh_prim_extent(p, magnitude);
                for (int a = 0; a < 3; a++) {
                    const uint64_t kind = ptr_rng_next(&rng) % 8;
                    p->centre[a] = kind == 0 ? extent
                                   : kind == 1 ? -extent
                                   : kind == 2 ? 1.5f
                                               : bvh_uniform(&rng, -2.0f, 2.0f);
                }
            }
            BvhCandidate c, left, right, bound;
            bvh_candidate_init(&set, &c, 0, count, NULL, NULL);
            if (c.axis < 0)
                continue;
            bvh_split(&set, &c, 0, scratch, &left, &right);
            splits++;
            const BvhCandidate *half[2] = { &left, &right };
            for (int h = 0; h < 2; h++) {
                bvh_candidate_init(&set, &bound, half[h]->begin, half[h]->end, NULL, NULL);
                CHECK(!memcmp(half[h]->lower, bound.lower, sizeof bound.lower));
                CHECK(!memcmp(half[h]->upper, bound.upper, sizeof bound.upper));
            }
        }
    }
    CHECK(splits > 250);
    free(prims);
    free(scratch);
}

/* bvh_split_children against the plan's splits made one at a time with
 * bvh_goes_right_at: every prim of a child goes there by the splits, in the
 * order it came, the children tile the range in bvh_children_order's order,
 * each box is its prims' to the bit, and no prim is lost or copied. With
 * the children's own splits (below), each child's prims likewise go to its
 * children, of 1 to 8 (one child: none), as a sort of the child's range by
 * them would leave them. The ranges hold from under one to some 150 of its
 * sort's blocks. The prims: random centres, some on bin edges, in ranges
 * whose length leaves 0 to 3 at the end of the four-at-a-time pass, inside
 * a larger array. */
static void test_split_children(void)
{
    enum { TOTAL = 20000 };
    BvhPrim *prims = malloc(TOTAL * sizeof *prims);
    unsigned char *seen = malloc(TOTAL);
    BvhSortRoom room = { 0 };
    CHECK(prims && seen && bvh_sort_room_reserve(&room, TOTAL) == PTR_OK);
    PtrRng rng = ptr_rng_for_sample(11, 0, 0);
    const size_t ranges[][2] = { { 0, TOTAL }, { 3, 9001 }, { 100, 102 }, { 17, 18 },
                                 { 5000, 5003 } };
    for (int two_levels = 0; two_levels < 2; two_levels++)
        for (size_t r = 0; r < sizeof ranges / sizeof ranges[0]; r++) {
            for (uint32_t i = 0; i < TOTAL; i++) {
                prims[i] = (BvhPrim){ .rest = i, .radius = bvh_uniform(&rng, 0.01f, 0.5f) };
                for (int a = 0; a < 3; a++)
                    /* One in eight on the grid of the splits' bin edges. */
                    prims[i].centre[a] = ptr_rng_float(&rng) < 0.125f
                                             ? (float)(int)bvh_uniform(&rng, -8, 8)
                                             : bvh_uniform(&rng, -8, 8);
            }
            const BvhPrimSet set = { prims, 8.5f, bvh_bin_c };
            BvhChildren plan, below[PTR_BVH_WIDTH];
            random_plan(&rng, r == 3 ? 1 : PTR_BVH_WIDTH, &plan);
            for (int k = 0; k < plan.count; k++)
                random_plan(&rng, 1 + (k + (int)r) % PTR_BVH_WIDTH, &below[k]);
            const size_t begin = ranges[r][0], end = ranges[r][1];
            bvh_split_children(&set, begin, end, &plan, two_levels ? below : NULL, &room);
            memset(seen, 0, TOTAL);
            check_children(prims, set.magnitude, begin, end, &plan, !two_levels, seen);
            for (int k = 0; two_levels && k < plan.count; k++)
                check_children(prims, set.magnitude, plan.begin[k], plan.end[k], &below[k], 1,
                               NULL);
            for (size_t i = 0; i < TOTAL; i++)
                if (i < begin || i >= end)
                    CHECK_INT(prims[i].rest, i);
        }
    free(seen);
    free(prims);
    bvh_sort_room_free(&room);
}


/* The trees of four fixed sets, to the byte, with every binning: their nodes,
 * and the spheres in the order the build leaves them (centres, radii and the
 * tags of their places in the file), as the build has made them since it was
 * last meant to change them. Images depend on the tree where two spheres tie,
 * and are promised the same from one build to the next: a change that moves
 * any split shows here, and one meant to updates these values and says why.
 * The sets take every path of the build: the clusters' 300,000 spheres a root
 * chosen from samples, its parts and the tasks; the clusters' 1,000,000 the
 * nodes of its parts planned from samples; the random 5,000 a root chosen from
 * all of them and the binning of every prim; the sheet's 19,881 centres on a
 * regular grid the same. The root's split tests, made four spheres at once
 * where the partitions test one, must agree with them to leave the last two as
 * the build made them when it split the root in place.
 * (The random set's value is that of the build before the binning moved into
 * SSE registers, which left it unchanged, as did the bins' negated lower
 * corners and the AVX2 binning; the sheet's that of the build just before the
 * root was chosen before the copy. The clusters' changed with that: the root's
 * splits came from samples of each range, and now of the whole. The 300,000
 * clusters' value held when the nodes of more than 65,536 spheres came to be
 * planned from samples, since none of its nodes has so many. Both clusters'
 * values changed when every partition came to keep each side's order: a range
 * split in the middle of its order (its centres all in one bin, or deep in the
 * tree) has other halves. All four changed when a colour's fourth entry came
 * to be always 65535, where the tags had 0: the build before gave the random
 * and sheet sets' values with such tags. The 1,000,000 clusters' value and
 * depth changed when a planned node came to sample one prim in 16 where it
 * sampled 32,768: its tree's surface area heuristic cost rose by 0.04%.) */
static void test_tree_bytes(void)
{
    const struct {
        BvhSceneKind kind;
        int count;
        uint64_t hash;
        int depth; /* the traversal's stack is sized by it */
    } sets[] = {
        { BVH_SCENE_CLUSTERS, 300000, UINT64_C(0x382d3ad9389d3640), 7 },
        { BVH_SCENE_CLUSTERS, 1000000, UINT64_C(0x08ad6aa4f706257a), 7 },
        { BVH_SCENE_RANDOM, 5000, UINT64_C(0x132ed326d6e4f85b), 3 },
        { BVH_SCENE_SHEET, 20000, UINT64_C(0xf3d534216486cce2), 3 },
    };
    /* With each binning this CPU reaches (bvh_bin_for_level's, once a
     * kernel), the tree the same. */
    for (int level = PTR_CPU_NONE; level <= (int)ptr_cpu_level(); level++)
        for (size_t k = 0; k < sizeof sets / sizeof sets[0]; k++) {
            if (!binning_is_new(level))
                break;
            PtrScene s;
            ptr_scene_init(&s);
            CHECK(bvh_scene_make(&s, sets[k].kind, sets[k].count, 5));
            tag_file_order(&s);
            PtrBvh bvh;
            CHECK_INT(ptr_bvh_build(&bvh, &s.spheres, s.spheres.count, 2, (PtrCpuLevel)level,
                                    NULL), PTR_OK);
            const uint64_t h = tree_hash(&bvh, &s.spheres);
            if (h != sets[k].hash)
                fprintf(stderr,
                        "%s, %d spheres, CPU level %s: the tree's bytes hash to %016llx, "
                        "not %016llx\n", bvh_scene_names[sets[k].kind], sets[k].count,
                        ptr_cpu_level_name((PtrCpuLevel)level), (unsigned long long)h,
                        (unsigned long long)sets[k].hash);
            CHECK(h == sets[k].hash);
            CHECK_INT(bvh.depth, sets[k].depth);
            ptr_bvh_free(&bvh);
            ptr_scene_free(&s);
        }
}

/* No spheres, one sphere: nothing to build, and the traversal still answers. */
static void test_small(void)
{
    PtrScene s;
    ptr_scene_init(&s);
    PtrBvh bvh;
    build_tree(&bvh, &s.spheres, 0);
    CHECK(bvh.nodes == NULL);
    PtrRay ray = { { 0, 0, 0 }, 0.0f, { 0, 0, -1 }, INFINITY };
    PtrHit hit;
    CHECK(!ptr_bvh_closest_hit_c(&ray, &bvh, &s.spheres, &hit));
    CHECK_INT(hit.sphere, PTR_NO_HIT);
    CHECK_FLOAT_EQ(hit.t, INFINITY);
    CHECK_INT(ptr_scene_add_sphere(&s, v3(0, 0, -5), 1.0f, 0, NULL), PTR_OK);
    build_tree(&bvh, &s.spheres, 0);
    CHECK(ptr_bvh_closest_hit_c(&ray, &bvh, &s.spheres, &hit));
    CHECK_FLOAT_EQ(hit.t, 4.0f);
    CHECK_INT(hit.sphere, 0);
    ptr_bvh_free(&bvh);
    ptr_scene_free(&s);
}

/* Renders scene with the C kernels through the structure chosen; returns
 * the image (3 floats a pixel) or NULL. */
static float *render_with(PtrScene *scene, PtrAccelChoice choice, int width, int height,
                          const char **used)
{
    PtrIsectTable c;
    ptr_isect_init_level(&c, PTR_CPU_NONE);
    PtrAccel accel;
    CHECK_INT(ptr_accel_init(&accel, choice, &c, 0, scene, 3, NULL), PTR_OK);
    *used = ptr_accel_name(&accel);
    PtrRenderSettings settings = { .width = width, .height = height, .samples = 3, .seed = 9,
                                   .max_depth = 12, .threads = 2 };
    float *rgb = malloc((size_t)width * (size_t)height * 3 * sizeof *rgb);
    PtrError err = { 0 };
    CHECK_INT(ptr_render(scene, &accel, &settings, rgb, NULL, &err), PTR_OK);
    ptr_accel_free(&accel);
    return rgb;
}

/* Brute force and the tree render the same image, bit for bit. */
static void check_same_render(PtrScene *brute, PtrScene *tree, int width, int height,
                              const char *name)
{
    const char *a, *b;
    float *x = render_with(brute, PTR_ACCEL_BRUTE, width, height, &a);
    float *y = render_with(tree, PTR_ACCEL_BVH, width, height, &b);
    CHECK_STR(a, "brute");
    CHECK_STR(b, "bvh");
    int same = !memcmp(x, y, (size_t)width * (size_t)height * 3 * sizeof *x);
    if (!same)
        fprintf(stderr, "%s: brute force and the tree render differently\n", name);
    CHECK(same);
    free(x);
    free(y);
}

static void test_renders_files(void)
{
    const char *files[] = { PTR_SOURCE_DIR "/scenes/seed.gltf", PTR_SOURCE_DIR "/scenes/final.gltf" };
    for (int f = 0; f < 2; f++) {
        PtrScene a, b;
        PtrStrings warnings = { 0 };
        PtrError err = { 0 };
        CHECK_INT(ptr_import_scene(files[f], NULL, &a, &warnings, &err), PTR_OK);
        CHECK_INT(ptr_import_scene(files[f], NULL, &b, &warnings, &err), PTR_OK);
        ptr_strings_free(&warnings);
        check_same_render(&a, &b, 48, 27, files[f]);
        ptr_scene_free(&a);
        ptr_scene_free(&b);
    }
}

/* The hard sets with mixed materials and some spheres' own colours (the
 * attributes the tree leaves in file order), seen from outside their
 * bounds. */
static void test_renders_hard(void)
{
    const PtrMaterial materials[3] = {
        { .kind = PTR_MATERIAL_DIFFUSE, .albedo = { 0.6f, 0.4f, 0.3f } },
        { .kind = PTR_MATERIAL_METAL, .albedo = { 0.9f, 0.9f, 0.9f } },
        { .kind = PTR_MATERIAL_DIELECTRIC, .albedo = { 1, 1, 1 }, .ior = 1.5f },
    };
    for (int kind = 0; kind < BVH_SCENE_KIND_COUNT; kind++) {
        PtrScene s[2];
        for (int k = 0; k < 2; k++) {
            ptr_scene_init(&s[k]);
            for (int m = 0; m < 3; m++) {
                uint32_t index;
                CHECK_INT(ptr_scene_add_material(&s[k], &materials[m], &index, NULL), PTR_OK);
            }
            CHECK(bvh_scene_make(&s[k], (BvhSceneKind)kind, 600, 4));
            float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
            PtrSpheres *sp = &s[k].spheres;
            for (size_t i = 0; i < sp->count; i++) {
                ptr_sphere_set_material(sp, i, (uint32_t)(i % 3));
                if (i % 4 == 0)
                    CHECK_INT(ptr_scene_set_sphere_color(&s[k], i, v3((float)(i % 5) / 4.0f, 0.5f,
                                                                      (float)(i % 7) / 6.0f), NULL),
                              PTR_OK);
                if (sp->radius[i] > 100.0f) /* a ground: look at what stands on it */
                    continue;
                float c[3] = { sp->cx[i], sp->cy[i], sp->cz[i] };
                for (int a = 0; a < 3; a++) {
                    lo[a] = fminf(lo[a], c[a] - sp->radius[i]);
                    hi[a] = fmaxf(hi[a], c[a] + sp->radius[i]);
                }
            }
            PtrVec3 centre = v3(0.5f * (lo[0] + hi[0]), 0.5f * (lo[1] + hi[1]), 0.5f * (lo[2] + hi[2]));
            float size = fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
            s[k].camera = (PtrCamera){ .lookfrom = v3_add(centre, v3(0.3f * size, 0.5f * size, 1.5f * size)),
                                       .lookat = centre, .up = v3(0, 1, 0), .vfov_deg = 50.0f,
                                       .focus_distance = 1.0f };
        }
        check_same_render(&s[0], &s[1], 40, 30, bvh_scene_names[kind]);
        ptr_scene_free(&s[0]);
        ptr_scene_free(&s[1]);
    }
}

/* auto: brute force below the crossover, the tree from it on. */
static void test_auto(void)
{
    PtrIsectTable c;
    ptr_isect_init_level(&c, PTR_CPU_NONE);
    for (int n = PTR_ACCEL_CROSSOVER_C - 1; n <= PTR_ACCEL_CROSSOVER_C; n++) {
        PtrScene s;
        ptr_scene_init(&s);
        CHECK(bvh_scene_make(&s, BVH_SCENE_RANDOM, n, 1));
        PtrAccel accel;
        CHECK_INT(ptr_accel_init(&accel, PTR_ACCEL_AUTO, &c, 0, &s, 0, NULL), PTR_OK);
        CHECK_STR(ptr_accel_name(&accel), n < PTR_ACCEL_CROSSOVER_C ? "brute" : "bvh");
        ptr_accel_free(&accel);
        ptr_scene_free(&s);
    }
}

/* Coincident spheres, which a ray meets at the same t, show the first in
 * the file, through the tree and through brute force alike: they share a
 * leaf, which keeps the file's order. A grid of 1000 spheres apart from
 * each other; ten of them repeated at the end of the file in another
 * material. */
static void test_coincident(void)
{
    PtrIsectTable c;
    ptr_isect_init_level(&c, PTR_CPU_NONE);
    for (int choice = PTR_ACCEL_BRUTE; choice <= PTR_ACCEL_BVH; choice++) {
        PtrScene s;
        ptr_scene_init(&s);
        const PtrMaterial grey = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = { 0.5f, 0.5f, 0.5f } };
        uint32_t m;
        for (int k = 0; k < 3; k++)
            CHECK_INT(ptr_scene_add_material(&s, &grey, &m, NULL), PTR_OK);
        for (int i = 0; i < 1000; i++) {
            PtrVec3 at = v3(3.0f * (float)(i % 10), 3.0f * (float)(i / 10 % 10),
                            -3.0f * (float)(i / 100) - 10.0f);
            CHECK_INT(ptr_scene_add_sphere(&s, at, 1.0f, i % 100 == 7 ? 1 : 0, NULL), PTR_OK);
        }
        for (int i = 7; i < 1000; i += 100)
            CHECK_INT(ptr_scene_add_sphere(&s, ptr_sphere_centre(&s.spheres, (size_t)i), 1.0f, 2, NULL),
                      PTR_OK);
        PtrVec3 centres[10];
        for (int k = 0; k < 10; k++)
            centres[k] = ptr_sphere_centre(&s.spheres, (size_t)(100 * k + 7));
        PtrAccel accel;
        CHECK_INT(ptr_accel_init(&accel, (PtrAccelChoice)choice, &c, 0, &s, 0, NULL), PTR_OK);
        CHECK_STR(ptr_accel_name(&accel), choice == PTR_ACCEL_BVH ? "bvh" : "brute");
        int first = 0;
        for (int k = 0; k < 10; k++) {
            /* From between the grid's spheres, straight at one of the pair. */
            PtrRay ray = { { centres[k].x, centres[k].y, centres[k].z + 1.5f }, 0.0f,
                           { 0, 0, -1 }, INFINITY };
            PtrHit hit;
            first += ptr_trace(&accel, &ray, &hit) && hit.t == 0.5f &&
                     ptr_sphere_material(&s.spheres, hit.sphere) == 1;
        }
        CHECK_INT(first, 10);
        ptr_accel_free(&accel);
        ptr_scene_free(&s);
    }
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_small),
        TEST_CASE(test_coincident),
        TEST_CASE(test_huge_rule),
        TEST_CASE(test_huge),
        TEST_CASE(test_huge_threads),
        TEST_CASE(test_scenes),
        TEST_CASE(test_threads),
        TEST_CASE(test_root_sort),
        TEST_CASE(test_least_right),
        TEST_CASE(test_split_boxes),
        TEST_CASE(test_split_children),
        TEST_CASE(test_plans_without_split),
        TEST_CASE(test_two_levels_planned),
        TEST_CASE(test_tree_bytes),
        TEST_CASE(test_auto),
        TEST_CASE(test_renders_files),
        TEST_CASE(test_renders_hard),
    };
    TEST_RUN(cases);
    return test_report();
}
