/* What the format-specific importers share with importer.c. */
#ifndef PTR_IMPORTER_INTERNAL_H
#define PTR_IMPORTER_INTERNAL_H

#include "importer.h"

PtrResult ptr_import_obj(const char *path, const PtrImportOptions *options,
                         PtrScene *scene, PtrStrings *warnings, PtrError *err);

PtrResult ptr_import_gltf(const char *path, const PtrImportOptions *options,
                          PtrScene *scene, PtrStrings *warnings, PtrError *err);

#endif /* PTR_IMPORTER_INTERNAL_H */
