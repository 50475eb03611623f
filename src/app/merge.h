/* ptr merge: parts of one render (sample ranges, regions, or both) into one
 * image, denoised with --denoise; and ptr denoise, the merge of one image. */
#ifndef PTR_MERGE_H
#define PTR_MERGE_H

#include "app/cli_options.h"
#include "app/report.h"
#include "color/color.h"

/* Reads the parts (scene-linear EXRs written by ptr), checks that they belong
 * together (same scene hash, image size, seed and depth limit; overlapping
 * regions with disjoint sample ranges; every pixel covered), and writes each
 * pixel's mean over all the samples the parts hold, weighted by their counts
 * (a part's noisy colour where it was denoised), then denoises that with
 * options' denoiser, if any. Fills report; returns its result. */
PtrResult ptr_merge(char **parts, int count, const char *output, const PtrOptions *options,
                    const PtrColor *color, PtrJobReport *report);

#endif /* PTR_MERGE_H */
