/* A macromolecular structure (PDB or mmCIF, gzipped or not) as plain C data:
 * the atoms of one of its models that a selection keeps, what each belongs to
 * (chain, entity, residue, secondary structure), and the biological assembly
 * asked for as instances of those atoms, read through gemmi. What the atoms
 * become (spheres, colours, values) lives in structure_import.c; this layer
 * only reads the file. */
#ifndef PTR_STRUCTURE_DOC_H
#define PTR_STRUCTURE_DOC_H

#include <stddef.h>

#include "base/result.h"
#include "structure_parts.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The secondary structure the file records for a residue. */
enum { STRUCTURE_COIL, STRUCTURE_HELIX, STRUCTURE_SHEET };

/* The most instances an assembly may have: the largest in the PDB archive
 * have a few thousand operators. Of an mmCIF file only the assembly asked
 * for is expanded, and refused as soon as its operators would pass this,
 * before they are made; a PDB file's are those of its REMARK 350 lines,
 * which gemmi reads whole. */
enum { STRUCTURE_MAX_INSTANCES = 100000 };

typedef struct StructureAtom {
    double position[3]; /* angstrom, finite */
    int element;        /* atomic number (deuterium: 1); 0 where gemmi knows none */
    float bfactor, occupancy;
    int serial;         /* the file's serial number of the atom */
    char residue[6];    /* its residue's name, cut to 5 characters */
    unsigned char secondary; /* STRUCTURE_COIL, _HELIX or _SHEET */
    unsigned chain;     /* its chain's number: chain names in order of first appearance */
    unsigned entity;    /* its entity's number in the file's list of entities (after
                         * gemmi's setup_entities); one past the last for none */
    unsigned part;      /* the number of its chain and subchain (mmCIF label_asym_id)
                         * together, which an assembly's generators name */
} StructureAtom;

/* An operator of an assembly: a position p goes to rotation * p +
 * translation. */
typedef struct StructureOperator {
    double rotation[3][3], translation[3];
} StructureOperator;

/* Part of an assembly: each of its operators applied to the atoms of its
 * parts (each atom's part: StructureAtom.part). */
typedef struct StructureGenerator {
    size_t first_part, part_count;         /* StructureDoc.parts[first_part ...] */
    size_t first_operator, operator_count; /* StructureDoc.operators[first_operator ...] */
    size_t atoms;                          /* the atoms kept that its parts hold */
} StructureGenerator;

typedef struct StructureDoc {
    StructureAtom *atoms; /* the asymmetric unit's atoms kept, in the file's order */
    size_t count;
    size_t models;        /* the models the file has */
    /* The assembly asked for: its generators in the file's order; none for
     * the asymmetric unit (none asked for, or the file has none). At most
     * STRUCTURE_MAX_INSTANCES operators in all. */
    StructureGenerator *generators;
    size_t generator_count;
    unsigned *parts;
    StructureOperator *operators;
} StructureDoc;

typedef struct StructureRequest {
    unsigned select;      /* PTR_STRUCTURE_PROTEIN ...: the residues kept */
    int hydrogens;        /* whether hydrogens (and deuterium) are kept */
    const char *assembly; /* its name; NULL: the file's first, if any; "none": the asymmetric unit */
    size_t model;         /* the model read: 0 the first */
} StructureRequest;

/* A structure file read and parsed once, for several of its models (the
 * frames of a sequence). */
typedef struct PtrStructureFile PtrStructureFile;

/* Reads path as structure_doc_read does, with the assembly asked for, into
 * *out (for structure_file_free). Fails as structure_doc_read does for the
 * file itself; an assembly it cannot read fails each structure_doc_read of
 * it instead, so that its models are still counted. */
PtrResult structure_file_open(const char *path, const char *assembly, PtrStructureFile **out,
                              PtrError *err);
/* The number of models the file has. */
size_t structure_file_models(const PtrStructureFile *file);
void structure_file_free(PtrStructureFile *file);

/* Reads path (.pdb, .ent, .cif or .mmcif, each optionally .gz), or takes it
 * from file (opened for path with request->assembly) where that is not NULL: of the
 * model request->model, the atoms of the residues request->select keeps, hydrogens only
 * with request->hydrogens, and of an atom's alternate locations the one of
 * highest occupancy (the first of equals) where the first stood; and the
 * assembly asked for, from an mmCIF's _pdbx_struct_assembly_gen and
 * _pdbx_struct_oper_list or a PDB file's REMARK 350. On success doc (free
 * with structure_doc_free) holds them. Fails with PTR_ERR_SCENE_UNREADABLE
 * or PTR_ERR_SCENE_INVALID (a number that is not one, a malformed file, an
 * operator missing, more than STRUCTURE_MAX_INSTANCES instances),
 * PTR_ERR_USAGE (an assembly or a model the file does not have: the message
 * names those it has), PTR_ERR_NOMEM, each with one line naming the file. */
PtrResult structure_doc_read(const char *path, const StructureRequest *request,
                             const PtrStructureFile *file, StructureDoc *doc, PtrError *err);
void structure_doc_free(StructureDoc *doc);

#ifdef __cplusplus
}
#endif

#endif /* PTR_STRUCTURE_DOC_H */
