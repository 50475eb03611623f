/* A macromolecular structure (PDB or mmCIF, gzipped or not) as plain C data:
 * the atoms of its first model that a selection keeps, read through gemmi.
 * What the atoms become (spheres, colours, values) lives in
 * structure_import.c; this layer only reads the file. */
#ifndef PTR_STRUCTURE_DOC_H
#define PTR_STRUCTURE_DOC_H

#include <stddef.h>

#include "base/result.h"
#include "structure_parts.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct StructureAtom {
    double position[3]; /* angstrom, finite */
    int element;        /* atomic number (deuterium: 1); 0 where gemmi knows none */
    float bfactor, occupancy;
    int serial;         /* the file's serial number of the atom */
} StructureAtom;

/* Reads path (.pdb, .ent, .cif or .mmcif, each optionally .gz): of its first
 * model, the atoms of the residues select keeps (PTR_STRUCTURE_PROTEIN ...), hydrogens (and deuterium)
 * only with hydrogens, and of an atom's alternate locations the one of
 * highest occupancy (the first of equals) where the first stood. On success
 * *atoms (free with structure_doc_free) holds *count atoms in the file's
 * order, and *models the number of models the file has. Fails with PTR_ERR_SCENE_UNREADABLE or PTR_ERR_SCENE_INVALID (a
 * number that is not one, a malformed file), PTR_ERR_NOMEM, each with one
 * line naming the file. */
PtrResult structure_doc_read(const char *path, unsigned select, int hydrogens,
                             StructureAtom **atoms, size_t *count, size_t *models,
                             PtrError *err);
void structure_doc_free(StructureAtom *atoms);

#ifdef __cplusplus
}
#endif

#endif /* PTR_STRUCTURE_DOC_H */
