/* The scene as JSON, as the importer understood it (ptr --dump-scene). */
#ifndef PTR_SCENE_JSON_H
#define PTR_SCENE_JSON_H

#include <stdio.h>

#include "importer.h"
#include "scene/scene.h"

/* PTR_ERR_NOMEM if memory runs out before anything is written. */
PtrResult ptr_scene_write_json(FILE *out, const char *path, const PtrScene *scene,
                               const PtrStrings *warnings);

#endif /* PTR_SCENE_JSON_H */
