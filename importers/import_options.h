/* What the command line asks of an import: the camera, the framing of a
 * scene without one, the --color-by attribute, what of a structure is kept.
 * Apart from importer.h so that the builder, which importer.c uses, reads it
 * without importer.h. */
#ifndef PTR_IMPORT_OPTIONS_H
#define PTR_IMPORT_OPTIONS_H

#include <stddef.h>

#include "base/result.h"
#include "scene/scene.h"
#include "structure/structure_parts.h"

/* A structure file parsed for the imports of its models (importer.h). */
typedef struct PtrStructureFile PtrStructureFile;

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

/* A texture's texels as stored (8-bit values over 255: no transfer function
 * undone): width x height RGBA floats, rows top to bottom. */
typedef struct PtrTexels {
    int width, height;
    float *rgba; /* malloc'd: the importer frees it */
    /* 8 where the file holds bytes, each value then n / 255 for a byte n
     * (in float, n times 1 / 255, as OpenImageIO converts); else the bits
     * of its integers, or 0 (floats, or not known). */
    int bits_per_channel;
} PtrTexels;

/* Decodes an image file held in memory, size bytes (a texture a glTF
 * embeds or names), in the format name's extension gives (PNG, JPEG, WebP),
 * into *out. name is also what messages give. Importers stand below the
 * image layer: whoever runs the import, which owns the image module's
 * loader, hands them this (the app's reads through src/image). */
typedef struct PtrTextureDecoder {
    PtrResult (*decode)(void *context, const char *name, const unsigned char *bytes, size_t size,
                        PtrTexels *out, PtrError *err);
    void *context;
} PtrTextureDecoder;

typedef struct PtrImportOptions {
    const char *camera_name; /* glTF: use the camera (node or camera name); NULL: the first */
    const PtrCameraSpec *camera; /* if set, the camera, whatever the file says */
    int fit_all_objects;     /* OBJ: fit every object, not only those named *sphere* */
    /* glTF: read each sphere's value of this instance or point attribute
     * (--color-by) into PtrSpheres.value; NULL: none. A scene where no
     * sphere has it is refused. Structures: also a colour scheme (element,
     * chain, ...), which colours the spheres without values. */
    const char *value_attribute;
    /* The automatic camera of a scene that has none: its projection, and the
     * width / height of the image it frames the spheres in (0: the scene's
     * resolution, else 16:9). */
    PtrProjection auto_projection;
    double auto_aspect;
    /* Degrees the camera, whichever it is, turns about the vertical axis
     * (+Y) through the spheres' centre: a frame of a turntable. */
    double orbit_degrees;
    /* Structures (PDB, mmCIF): the residues kept, a set of
     * PTR_STRUCTURE_PROTEIN ... (0: PTR_STRUCTURE_DEFAULT), and whether
     * hydrogens are dropped (--select, --hydrogens). */
    unsigned structure_select;
    int drop_hydrogens;
    /* Structures: the biological assembly built (--assembly): its name,
     * "none" for the asymmetric unit; NULL: the file's first, if any. */
    const char *structure_assembly;
    /* Structures: the model read, 1 the first (a frame of a sequence of
     * models); 0: the first, with a warning where the file has more. */
    size_t structure_model;
    /* Structures: the file, read and parsed already (ptr_structure_open,
     * with structure_assembly) for a sequence of its models; NULL: the
     * import reads it. */
    const PtrStructureFile *structure_file;
    /* If set, receives the other files the scene was read from (a glTF's
     * external buffers): what --watch must watch besides the scene file. */
    PtrStrings *dependencies;
    /* glTF: reads the textures that colour spheres; decode NULL: they are
     * not read (a warning names the first material that has one). */
    PtrTextureDecoder textures;
} PtrImportOptions;

#endif /* PTR_IMPORT_OPTIONS_H */
