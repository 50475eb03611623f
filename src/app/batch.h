/* What one command line renders: every scene to its output, or a numbered
 * sequence of frames (scene files f_0001.glb, f_0002.glb, ..., one scene
 * seen from a turning camera, or a structure's models), each frame to its
 * own file. */
#ifndef PTR_BATCH_H
#define PTR_BATCH_H

#include "app/cli_options.h"
#include "base/result.h"

enum { PTR_PATH_SIZE = 4096 };

/* One render of a batch. */
typedef struct PtrBatchItem {
    char *scene, *output; /* owned by the item */
    double orbit_degrees; /* the turntable's turn of the camera for this frame */
    size_t model;         /* a structure's model for this frame (1 the first); 0: none */
} PtrBatchItem;

/* The output for one scene: -o with {name} replaced by the scene's name; a
 * folder (existing, or written with a trailing /) gets NAME.exr; a plain
 * file name serves one scene only. */
PtrResult ptr_batch_output(const PtrOptions *o, const char *scene, char *out, PtrError *err);

/* The renders the options ask for, in order, in a new array (for
 * ptr_batch_free):
 * each scene to its output, or with a frame pattern (a run of '#' in the
 * scene, with --turntable, or in -o for a structure: its models numbered
 * from 1) the frames found or asked for. Outputs are
 * checked as ptr_output_check does, and must differ. For a structure's
 * models, *structure is the file, parsed once for all of them (for
 * ptr_structure_close); else NULL. */
PtrResult ptr_batch_plan(const PtrOptions *o, PtrBatchItem **items, int *count,
                         PtrStructureFile **structure, PtrError *err);

void ptr_batch_free(PtrBatchItem *items, int count);

/* Whether text holds a frame pattern: a run of '#'. */
int ptr_batch_is_pattern(const char *text);

#endif /* PTR_BATCH_H */
