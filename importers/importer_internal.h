/* What the format-specific importers share with importer.c. */
#ifndef PTR_IMPORTER_INTERNAL_H
#define PTR_IMPORTER_INTERNAL_H

#include "builder.h"
#include "importer.h"

PtrResult ptr_import_obj(const char *path, const PtrImportOptions *options,
                         PtrScene *scene, PtrStrings *warnings, PtrError *err);

PtrResult ptr_import_gltf(const char *path, const PtrImportOptions *options,
                          PtrScene *scene, PtrStrings *warnings, PtrError *err);

/* PDB and mmCIF, gzipped or not, through gemmi (structure/). */
PtrResult ptr_import_structure(const char *path, const PtrImportOptions *options,
                               PtrScene *scene, PtrStrings *warnings, PtrError *err);

/* ptr_builder_finish with ptr's own flags, its message naming the file. */
PtrResult ptr_import_finish(PtrSceneBuilder *builder, const char *path, PtrError *err);

/* Bytes a sphere takes at the peak of its import and the tree's build
 * (bench/scale.sh measures 37 to 44 a sphere above a one-sphere render from
 * 10^6 to 10^8 spheres with their own colours: the tree's prims, 32, and
 * its nodes; an import whose coordinates are not floats holds 41 at its
 * own peak, the builder's 32 of centre and radius in double, 8 of colour
 * and the material's index), with room for a --color-by value. */
#define PTR_SPHERE_PEAK_BYTES 64

/* Before a file's spheres are allocated: refuses (PTR_ERR_NOMEM, one line
 * with what they would need and what there is) a count that would not fit
 * in the memory the process can still take (base/memory.h), so that a file
 * claiming more spheres than the machine holds fails at once instead of
 * swapping or meeting the OOM killer. */
PtrResult ptr_import_check_memory(const char *path, uint64_t spheres, PtrError *err);

#endif /* PTR_IMPORTER_INTERNAL_H */
