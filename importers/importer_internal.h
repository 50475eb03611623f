/* What the format-specific importers share with importer.c. */
#ifndef PTR_IMPORTER_INTERNAL_H
#define PTR_IMPORTER_INTERNAL_H

#include "builder.h"
#include "importer.h"

PtrResult ptr_import_obj(const char *path, const PtrImportOptions *options,
                         PtrScene *scene, PtrStrings *warnings, PtrError *err);

PtrResult ptr_import_gltf(const char *path, const PtrImportOptions *options,
                          PtrScene *scene, PtrStrings *warnings, PtrError *err);

/* ptr_builder_finish with ptr's own flags, its failure told as what it is:
 * out of memory, or a sphere too far from the camera. */
PtrResult ptr_import_finish(PtrSceneBuilder *builder, const char *path, PtrError *err);

#endif /* PTR_IMPORTER_INTERNAL_H */
