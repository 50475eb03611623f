/* Scene files in, one PtrScene out. The importer chosen by the file's
 * extension follows docs/scenes.md; everything it could not represent is
 * reported as a warning naming the object. */
#ifndef PTR_IMPORTER_H
#define PTR_IMPORTER_H

#include <stddef.h>

#include "base/result.h"
#include "scene/scene.h"

/* A list of lines of text (warnings, file names). */
typedef struct PtrStrings {
    char **lines;
    size_t count;
} PtrStrings;

/* A camera given on the command line, in world coordinates: it replaces the
 * scene's. */
typedef struct PtrCameraSpec {
    double lookfrom[3], lookat[3], up[3];
    double vfov_deg;
    double ortho_height;   /* above 0: orthographic, the view this high; vfov_deg unused */
    double aperture;       /* lens diameter; 0: a pinhole */
    double focus_distance; /* 0: the distance from lookfrom to lookat */
} PtrCameraSpec;

typedef struct PtrImportOptions {
    const char *camera_name; /* glTF: use the camera (node or camera name); NULL: the first */
    const PtrCameraSpec *camera; /* if set, the camera, whatever the file says */
    int fit_all_objects;     /* OBJ: fit every object, not only those named *sphere* */
    /* glTF: read each sphere's value of this instance or point attribute
     * (--color-by) into PtrSpheres.value; NULL: none. A scene where no
     * sphere has it is refused. */
    const char *value_attribute;
    /* The automatic camera of a scene that has none: its projection, and the
     * width / height of the image it frames the spheres in (0: the scene's
     * resolution, else 16:9). */
    PtrProjection auto_projection;
    double auto_aspect;
    /* Degrees the camera, whichever it is, turns about the vertical axis
     * (+Y) through the spheres' centre: a frame of a turntable. */
    double orbit_degrees;
    /* If set, receives the other files the scene was read from (a glTF's
     * external buffers): what --watch must watch besides the scene file. */
    PtrStrings *dependencies;
} PtrImportOptions;

/* Reads path into scene (which the call initialises). On failure the scene
 * is left empty and err holds one line naming the file and the problem:
 * PTR_ERR_SCENE_UNREADABLE if it could not be read, PTR_ERR_SCENE_INVALID if
 * it was read and is wrong. Warnings are appended to warnings either way. */
PtrResult ptr_import_scene(const char *path, const PtrImportOptions *options,
                           PtrScene *scene, PtrStrings *warnings, PtrError *err);

/* The glTF extensions ptr reads, NULL-terminated: a file that requires any
 * other is refused, naming it. */
extern const char *const ptr_gltf_extensions[];

/* Appends a printf-formatted line. */
void ptr_warn(PtrStrings *lines, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
void ptr_strings_free(PtrStrings *lines);

#endif /* PTR_IMPORTER_H */
