/* Structures (PDB, mmCIF) as spheres: one an atom, its radius the element's
 * van der Waals radius and its colour the element's CPK colour, from the
 * table scripts/molecule_to_glb.py uses too (elements.def); each atom's
 * B-factor and occupancy as the values --color-by reads (_BFACTOR,
 * _OCCUPANCY, the names the converter gives them). docs/scenes.md. */
#include <string.h>

#include "attribute_name.h"
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

/* The per-atom values --color-by can ask for. */
typedef enum AtomValue { NO_VALUE, BFACTOR, OCCUPANCY } AtomValue;

static PtrResult atom_value(const char *path, const char *name, AtomValue *value, PtrError *err)
{
    *value = NO_VALUE;
    if (!name)
        return PTR_OK;
    if (ptr_attribute_named("_BFACTOR", name))
        *value = BFACTOR;
    else if (ptr_attribute_named("_OCCUPANCY", name))
        *value = OCCUPANCY;
    else
        return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                             "%s: no per-atom value '%s' (--color-by); a structure has "
                             "_BFACTOR and _OCCUPANCY", path, name);
    return PTR_OK;
}

/* The spheres of atoms[0 .. count): one white diffuse material, which each
 * sphere's own colour (its element's) tints, as the converter's .glb does. */
static PtrResult add_atoms(PtrSceneBuilder *builder, const char *path, const StructureAtom *atoms,
                           size_t count, AtomValue value, PtrError *err)
{
    PtrResult res = ptr_import_check_memory(path, count, err);
    if (res != PTR_OK)
        return res;
    const PtrMaterial white = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(1), .ior = 1.5f };
    uint32_t material;
    if (ptr_scene_add_material(builder->scene, &white, &material, NULL) != PTR_OK ||
        ptr_builder_reserve(builder, count, NULL) != PTR_OK)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    for (size_t i = 0; i < count; i++) {
        const StructureAtom *a = &atoms[i];
        const int known = a->element > 0 && (size_t)a->element < ELEMENT_COUNT;
        if (!known)
            return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                                 "%s: atom %d: no element ptr knows", path, a->serial);
        if (!(elements[a->element].radius > 0))
            return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                                 "%s: atom %d: %s has no van der Waals radius in Alvarez (2013)",
                                 path, a->serial, elements[a->element].symbol);
        const unsigned char *srgb = elements[a->element].srgb;
        const double rgb[3] = { ptr_srgb_to_linear(srgb[0] / 255.0f),
                                ptr_srgb_to_linear(srgb[1] / 255.0f),
                                ptr_srgb_to_linear(srgb[2] / 255.0f) };
        if (ptr_builder_add_sphere(builder, a->position, elements[a->element].radius, material,
                                   NULL) != PTR_OK ||
            ptr_builder_set_color(builder, rgb, NULL) != PTR_OK ||
            (value != NO_VALUE &&
             ptr_builder_set_value(builder, value == BFACTOR ? a->bfactor : a->occupancy,
                                   NULL) != PTR_OK))
            return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    }
    return PTR_OK;
}

PtrResult ptr_import_structure(const char *path, const PtrImportOptions *options,
                               PtrScene *scene, PtrStrings *warnings, PtrError *err)
{
    const unsigned select = options && options->structure_select
                                ? options->structure_select
                                : PTR_STRUCTURE_DEFAULT;
    AtomValue value;
    PtrResult res = atom_value(path, options ? options->value_attribute : NULL, &value, err);
    StructureAtom *atoms = NULL;
    size_t count = 0, models = 0;
    if (res == PTR_OK)
        res = structure_doc_read(path, select, !(options && options->drop_hydrogens), &atoms,
                                 &count, &models, err);
    if (res == PTR_OK && models > 1)
        ptr_warn(warnings, "%s: the first of %zu models is read, the others are left out", path,
                 models);
    if (res == PTR_OK && count == 0)
        res = ptr_error_set(err, PTR_ERR_SCENE_INVALID, "%s: no atoms%s", path,
                            select == PTR_STRUCTURE_ALL ? "" : " of those --select keeps");
    PtrSceneBuilder builder;
    ptr_builder_init(&builder, scene, options);
    if (res == PTR_OK)
        res = add_atoms(&builder, path, atoms, count, value, err);
    structure_doc_free(atoms);
    if (res == PTR_OK)
        res = ptr_import_finish(&builder, path, err);
    ptr_builder_free(&builder);
    return res;
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
