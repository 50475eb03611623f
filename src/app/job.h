/* Rendering one scene to one image, as the command line's options say. */
#ifndef PTR_JOB_H
#define PTR_JOB_H

#include "app/cli_options.h"
#include "app/report.h"
#include "color/color.h"

/* Imports the scene, renders it (in passes, with progress, stopping cleanly
 * when ptr_stop_requested is set) and writes output. Always fills report;
 * returns its result: PTR_ERR_INTERRUPTED when stopped early, with the image
 * of the samples done written. dependencies (may be NULL) receives the other
 * files the scene was read from. */
PtrResult ptr_job_render(const PtrOptions *options, const char *scene, const char *output,
                         const PtrColor *color, PtrStrings *dependencies, PtrJobReport *report);

#endif /* PTR_JOB_H */
