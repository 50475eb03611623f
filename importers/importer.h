/* Scene files in, one PtrScene out. The importer chosen by the file's
 * extension follows docs/scenes.md; everything it could not represent is
 * reported as a warning naming the object. */
#ifndef PTR_IMPORTER_H
#define PTR_IMPORTER_H

#include "base/result.h"
#include "import_options.h"
#include "scene/scene.h"

/* Reads path into scene (which the call initialises). On failure the scene
 * is left empty and err holds one line naming the file and the problem:
 * PTR_ERR_SCENE_UNREADABLE if it could not be read, PTR_ERR_SCENE_INVALID if
 * it was read and is wrong. Warnings are appended to warnings either way. */
PtrResult ptr_import_scene(const char *path, const PtrImportOptions *options,
                           PtrScene *scene, PtrStrings *warnings, PtrError *err);

/* The glTF extensions ptr reads, NULL-terminated: a file that requires any
 * other is refused, naming it. */
extern const char *const ptr_gltf_extensions[];

/* Parses --select's list (protein, nucleic, ligand, water, all; comma-
 * separated) into a set of PTR_STRUCTURE_PROTEIN ... (import_options.h).
 * Fails with PTR_ERR_USAGE and "'TEXT' is not ...". */
PtrResult ptr_structure_select_parse(const char *text, unsigned *parts, PtrError *err);

/* Whether path names a structure (PDB or mmCIF, by its extension), whose
 * models a sequence's frames can be. */
int ptr_import_is_structure(const char *path);

/* The structure path names, read and parsed once for the imports of its
 * models (PtrImportOptions.structure_file), with the assembly they ask for
 * (PtrImportOptions.structure_assembly), into *out (for
 * ptr_structure_close): fails as its import does, but for an assembly it
 * cannot read, which fails each import of a model instead. */
PtrResult ptr_structure_open(const char *path, const char *assembly, PtrStructureFile **out,
                             PtrError *err);
/* The number of models the structure has. */
size_t ptr_structure_models(const PtrStructureFile *file);
void ptr_structure_close(PtrStructureFile *file);

/* Appends a printf-formatted line. */
void ptr_warn(PtrStrings *lines, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
void ptr_strings_free(PtrStrings *lines);

#endif /* PTR_IMPORTER_H */
