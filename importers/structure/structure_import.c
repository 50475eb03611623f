/* Structures (PDB, mmCIF) as spheres: one an atom, its radius the element's
 * van der Waals radius and its colour the element's CPK colour, from the
 * table scripts/molecule_to_glb.py uses too (elements.def), or the colour of
 * its chain, entity, residue or secondary structure (--color-by); each
 * atom's B-factor and occupancy as the values --color-by reads (_BFACTOR,
 * _OCCUPANCY, the names the converter gives them). A biological assembly is
 * made of instances of the asymmetric unit's atoms, each placed by its
 * operator as the spheres are filled in. docs/scenes.md. */
#include <stdlib.h>
#include <string.h>

#include "attribute_name.h"
#include "base/cpu.h"
#include "base/threads.h"
#include "importer_internal.h"
#include "scene/colormap.h"
#include "structure_doc.h"

static const struct {
    const char *symbol;
    double radius; /* 0: Alvarez (2013) gives none */
    unsigned char srgb[3];
} elements[] = {
#define PTR_ELEMENT(symbol, number, radius, r, g, b) [number] = { #symbol, radius, { r, g, b } },
#include "elements.def"
#undef PTR_ELEMENT
};

#define ELEMENT_COUNT (sizeof elements / sizeof elements[0])

/* The categorical palette of chains and entities, the n-th taking entry
 * n mod 10: Tableau 10, matplotlib's "tab10" (sRGB). */
static const unsigned char categories[10][3] = {
    { 31, 119, 180 }, { 255, 127, 14 }, { 44, 160, 44 },  { 214, 39, 40 },
    { 148, 103, 189 }, { 140, 86, 75 }, { 227, 119, 194 }, { 127, 127, 127 },
    { 188, 189, 34 }, { 23, 190, 207 },
};

/* Residues: RasMol's "shapely" colours, with Jmol's for the nucleotides
 * (DNA's as RNA's), and shapely's magenta for every other residue. */
static const struct {
    const char *name;
    unsigned char srgb[3];
} residues[] = {
    { "ALA", { 140, 255, 140 } }, { "ARG", { 0, 0, 124 } },     { "ASN", { 255, 124, 112 } },
    { "ASP", { 160, 0, 66 } },    { "CYS", { 255, 255, 112 } }, { "GLN", { 255, 76, 76 } },
    { "GLU", { 102, 0, 0 } },     { "GLY", { 255, 255, 255 } }, { "HIS", { 112, 112, 255 } },
    { "ILE", { 0, 76, 0 } },      { "LEU", { 69, 94, 69 } },    { "LYS", { 71, 71, 184 } },
    { "MET", { 184, 160, 66 } },  { "PHE", { 83, 76, 66 } },    { "PRO", { 82, 82, 82 } },
    { "SER", { 255, 112, 66 } },  { "THR", { 184, 76, 0 } },    { "TRP", { 79, 70, 0 } },
    { "TYR", { 140, 112, 76 } },  { "VAL", { 255, 140, 255 } }, { "A", { 160, 160, 255 } },
    { "DA", { 160, 160, 255 } },  { "C", { 255, 140, 75 } },    { "DC", { 255, 140, 75 } },
    { "G", { 255, 112, 112 } },   { "DG", { 255, 112, 112 } },  { "T", { 160, 255, 160 } },
    { "DT", { 160, 255, 160 } },  { "U", { 255, 128, 128 } },   { "DU", { 255, 128, 128 } },
    { "I", { 128, 255, 255 } },   { "DI", { 128, 255, 255 } },
};
static const unsigned char other_residue[3] = { 255, 0, 255 };

/* Secondary structure: RasMol's and Jmol's "structure" colours (coil,
 * helix, sheet, in STRUCTURE_COIL's order). */
static const unsigned char secondary[3][3] = {
    { 255, 255, 255 }, { 255, 0, 128 }, { 255, 200, 0 },
};

/* What --color-by asks of a structure: a colour scheme, or a per-atom value
 * (on the element's colours) that the colormap then maps. */
typedef enum AtomColoring {
    BY_ELEMENT, BY_CHAIN, BY_ENTITY, BY_RESIDUE, BY_SECONDARY, BY_BFACTOR, BY_OCCUPANCY
} AtomColoring;

static PtrResult atom_coloring(const char *path, const char *name, AtomColoring *coloring,
                               PtrError *err)
{
    static const char *const names[] = { "element", "chain",    "entity",   "residue",
                                         "secondary", "_BFACTOR", "_OCCUPANCY" };
    *coloring = BY_ELEMENT;
    for (size_t i = 0; name && i < sizeof names / sizeof names[0]; i++)
        if (ptr_attribute_named(names[i], name)) {
            *coloring = (AtomColoring)i;
            return PTR_OK;
        }
    return name ? ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                                "%s: no colour scheme or per-atom value '%s' (--color-by); a "
                                "structure has element, chain, entity, residue, secondary, "
                                "_BFACTOR and _OCCUPANCY", path, name)
                : PTR_OK;
}

static const unsigned char *residue_color(const char *name)
{
    for (size_t i = 0; i < sizeof residues / sizeof residues[0]; i++)
        if (!strcmp(residues[i].name, name))
            return residues[i].srgb;
    return other_residue;
}

/* An atom's sphere before it is placed: radius, then colour in linear
 * light. Fails for an element without a radius, naming the atom. */
static PtrResult atom_look(const char *path, const StructureAtom *a, AtomColoring coloring,
                           double look[4], PtrError *err)
{
    const int known = a->element > 0 && (size_t)a->element < ELEMENT_COUNT;
    if (!known)
        return ptr_error_set(err, PTR_ERR_SCENE_INVALID, "%s: atom %d: no element ptr knows",
                             path, a->serial);
    if (!(elements[a->element].radius > 0))
        return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                             "%s: atom %d: %s has no van der Waals radius in Alvarez (2013)",
                             path, a->serial, elements[a->element].symbol);
    const unsigned char *srgb = coloring == BY_CHAIN       ? categories[a->chain % 10]
                                : coloring == BY_ENTITY    ? categories[a->entity % 10]
                                : coloring == BY_RESIDUE   ? residue_color(a->residue)
                                : coloring == BY_SECONDARY ? secondary[a->secondary]
                                                           : elements[a->element].srgb;
    look[0] = elements[a->element].radius;
    for (int k = 0; k < 3; k++)
        look[1 + k] = ptr_srgb_to_linear(srgb[k] / 255.0f);
    return PTR_OK;
}

/* The spheres of a structure: slot n of generator g's run (its spheres,
 * one operator's atoms after another) is the builder's sphere first +
 * slot_start[g] + n; without generators, the asymmetric unit's atoms as the
 * file places them. */
typedef struct Expansion {
    PtrSceneBuilder *builder;
    const StructureDoc *doc;
    const double (*looks)[4];  /* each atom's, see atom_look */
    AtomColoring coloring;
    uint32_t material;
    size_t first;
    size_t *members;    /* each generator's atoms, one generator after another */
    size_t *slot_start; /* each generator's first slot, then the total */
    size_t *member_start; /* each generator's first in members */
} Expansion;

static void fill_atom(const Expansion *e, size_t atom, const StructureOperator *op, size_t n)
{
    const StructureAtom *a = &e->doc->atoms[atom];
    double centre[3];
    if (op)
        for (int i = 0; i < 3; i++)
            centre[i] = op->rotation[i][0] * a->position[0] +
                        op->rotation[i][1] * a->position[1] +
                        op->rotation[i][2] * a->position[2] + op->translation[i];
    else
        memcpy(centre, a->position, sizeof centre);
    ptr_builder_fill_sphere(e->builder, e->first + n, centre, e->looks[atom][0], e->material,
                            &e->looks[atom][1]);
    if (e->coloring == BY_BFACTOR || e->coloring == BY_OCCUPANCY)
        ptr_builder_fill_value(e->builder, e->first + n,
                               e->coloring == BY_BFACTOR ? a->bfactor : a->occupancy);
}

static void fill_slots(void *arg, size_t begin, size_t end)
{
    const Expansion *e = arg;
    const StructureDoc *doc = e->doc;
    if (!doc->generator_count) {
        for (size_t n = begin; n < end; n++)
            fill_atom(e, n, NULL, n);
        return;
    }
    size_t g = 0;
    while (e->slot_start[g + 1] <= begin)
        g++;
    for (size_t n = begin; n < end; n++) {
        while (e->slot_start[g + 1] <= n)
            g++;
        const StructureGenerator *gen = &doc->generators[g];
        const size_t slot = n - e->slot_start[g];
        fill_atom(e, e->members[e->member_start[g] + slot % gen->atoms],
                  &doc->operators[gen->first_operator + slot / gen->atoms], n);
    }
}

/* Each generator's atoms in the file's order within each of its parts (see
 * Expansion.members), and where each generator's start. */
static PtrResult list_members(Expansion *e)
{
    const StructureDoc *doc = e->doc;
    size_t parts = 0, members = 0;
    for (size_t i = 0; i < doc->count; i++)
        parts = doc->atoms[i].part + 1 > parts ? doc->atoms[i].part + 1 : parts;
    for (size_t g = 0; g < doc->generator_count; g++)
        members += doc->generators[g].atoms;
    size_t *part_start = calloc(parts + 1, sizeof *part_start);
    size_t *by_part = malloc((doc->count ? doc->count : 1) * sizeof *by_part);
    e->members = malloc((members ? members : 1) * sizeof *e->members);
    e->member_start = malloc((doc->generator_count + 1) * sizeof *e->member_start);
    if (!part_start || !by_part || !e->members || !e->member_start) {
        free(part_start);
        free(by_part);
        return PTR_ERR_NOMEM;
    }
    for (size_t i = 0; i < doc->count; i++)
        part_start[doc->atoms[i].part + 1]++;
    for (size_t p = 0; p < parts; p++)
        part_start[p + 1] += part_start[p];
    for (size_t i = 0; i < doc->count; i++)
        by_part[part_start[doc->atoms[i].part]++] = i;
    for (size_t p = parts; p > 0; p--) /* back to each part's start */
        part_start[p] = part_start[p - 1];
    part_start[0] = 0;
    size_t m = 0;
    for (size_t g = 0; g < doc->generator_count; g++) {
        const StructureGenerator *gen = &doc->generators[g];
        e->member_start[g] = m;
        for (size_t k = 0; k < gen->part_count; k++) {
            const unsigned p = doc->parts[gen->first_part + k];
            for (size_t j = part_start[p]; j < part_start[p + 1]; j++)
                e->members[m++] = by_part[j];
        }
    }
    free(part_start);
    free(by_part);
    return PTR_OK;
}

/* A structure of this many spheres or more is filled on all cores. Every
 * structure is filled a block at a time (ptr_builder_block_end): where the
 * builder stops keeping floats (a decimal coordinate seldom is one), that
 * block is filled again, not the whole structure (ptr_builder_refill). */
enum { PARALLEL_SPHERES = 1 << 15 };

/* The spheres of the doc's atoms, or of its assembly: one white diffuse
 * material, which each sphere's own colour tints, as the converter's .glb
 * does. */
static PtrResult add_atoms(PtrSceneBuilder *builder, const char *path, const StructureDoc *doc,
                           AtomColoring coloring, PtrError *err)
{
    Expansion e = { .builder = builder, .doc = doc, .coloring = coloring };
    e.slot_start = malloc((doc->generator_count + 1) * sizeof *e.slot_start);
    if (!e.slot_start)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    e.slot_start[0] = 0;
    for (size_t g = 0; g < doc->generator_count; g++)
        e.slot_start[g + 1] =
            e.slot_start[g] + doc->generators[g].atoms * doc->generators[g].operator_count;
    const size_t spheres = doc->generator_count ? e.slot_start[doc->generator_count] : doc->count;
    PtrResult res = ptr_import_check_memory(path, spheres, err);
    if (res != PTR_OK) {
        free(e.slot_start);
        return res;
    }
    double(*looks)[4] = malloc(doc->count * sizeof *looks);
    res = looks ? PTR_OK : PTR_ERR_NOMEM;
    for (size_t i = 0; i < doc->count && res == PTR_OK; i++)
        res = atom_look(path, &doc->atoms[i], coloring, looks[i], err);
    e.looks = (const double(*)[4])looks;
    if (res == PTR_OK && doc->generator_count)
        res = list_members(&e);
    const PtrMaterial white = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(1), .ior = 1.5f };
    const int valued = coloring == BY_BFACTOR || coloring == BY_OCCUPANCY;
    if (res == PTR_ERR_NOMEM ||
        (res == PTR_OK &&
         (ptr_scene_add_material(builder->scene, &white, &e.material, NULL) != PTR_OK ||
          (valued && ptr_builder_keep_attributes(builder, 0, 1, NULL) != PTR_OK) ||
          ptr_builder_add_spheres(builder, spheres, 1, &e.first, NULL) != PTR_OK)))
        res = ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    const int threads = spheres >= PARALLEL_SPHERES ? ptr_usable_cpus() : 1;
    if (res == PTR_OK &&
        ptr_builder_fill_blocks(builder, e.first, spheres, threads, fill_slots, NULL, &e) != PTR_OK)
        res = ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    free(looks);
    free(e.slot_start);
    free(e.members);
    free(e.member_start);
    return res;
}

PtrResult ptr_import_structure(const char *path, const PtrImportOptions *options,
                               PtrScene *scene, PtrStrings *warnings, PtrError *err)
{
    const StructureRequest request = {
        .select = options && options->structure_select ? options->structure_select
                                                       : PTR_STRUCTURE_DEFAULT,
        .hydrogens = !(options && options->drop_hydrogens),
        .assembly = options ? options->structure_assembly : NULL,
        .model = options && options->structure_model ? options->structure_model - 1 : 0,
    };
    AtomColoring coloring;
    PtrResult res =
        atom_coloring(path, options ? options->value_attribute : NULL, &coloring, err);
    StructureDoc doc = { 0 };
    if (res == PTR_OK)
        res = structure_doc_read(path, &request, options ? options->structure_file : NULL, &doc,
                                 err);
    if (res == PTR_OK && doc.models > 1 && !(options && options->structure_model))
        ptr_warn(warnings, "%s: the first of %zu models is read, the others are left out (# in "
                 "-o renders each as a frame)", path, doc.models);
    if (res == PTR_OK && doc.count == 0)
        res = ptr_error_set(err, PTR_ERR_SCENE_INVALID, "%s: no atoms%s", path,
                            request.select == PTR_STRUCTURE_ALL ? "" : " of those --select keeps");
    PtrSceneBuilder builder;
    ptr_builder_init(&builder, scene, options);
    if (res == PTR_OK)
        res = add_atoms(&builder, path, &doc, coloring, err);
    structure_doc_free(&doc);
    if (res == PTR_OK)
        res = ptr_import_finish(&builder, path, err);
    ptr_builder_free(&builder);
    return res;
}


PtrResult ptr_structure_open(const char *path, const char *assembly, PtrStructureFile **out,
                             PtrError *err)
{
    return structure_file_open(path, assembly, out, err);
}

size_t ptr_structure_models(const PtrStructureFile *file)
{
    return structure_file_models(file);
}

void ptr_structure_close(PtrStructureFile *file)
{
    structure_file_free(file);
}

PtrResult ptr_structure_select_parse(const char *text, unsigned *parts, PtrError *err)
{
    static const struct {
        const char *name;
        unsigned parts;
    } names[] = {
        { "protein", PTR_STRUCTURE_PROTEIN }, { "nucleic", PTR_STRUCTURE_NUCLEIC },
        { "ligand", PTR_STRUCTURE_LIGAND },   { "water", PTR_STRUCTURE_WATER },
        { "all", PTR_STRUCTURE_ALL },
    };
    unsigned chosen = 0;
    for (const char *word = text;; word++) {
        const size_t length = strcspn(word, ",");
        unsigned found = 0;
        for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
            if (strlen(names[i].name) == length && !strncmp(word, names[i].name, length))
                found = names[i].parts;
        if (!found)
            return ptr_error_set(err, PTR_ERR_USAGE,
                                 "'%s' is not a comma-separated list of protein, nucleic, "
                                 "ligand, water or all", text);
        chosen |= found;
        word += length;
        if (!*word)
            break;
    }
    *parts = chosen;
    return PTR_OK;
}
