/* Claims on outputs, for --skip-existing: several ptr processes, on one
 * machine or many sharing a folder, render a sequence together, each frame
 * once. Before rendering OUTPUT a process creates OUTPUT.claim exclusively
 * (O_CREAT | O_EXCL, atomic on local file systems and NFS v3 on), holding
 * "HOST PID"; whoever finds the output or a live claim moves on. The image
 * itself is still written to a temporary file and renamed into place, so an
 * output that exists is whole. The claim goes once the output is written or
 * the render fails or is interrupted (an interrupted frame is then not
 * written, so that the next run renders it whole).
 *
 * A claim is stale, and taken over, when the process that made it is gone:
 * on the same host, when no process has its PID; from another host (or a
 * claim that names none, its maker having died before writing it), when
 * its file has not been touched for PTR_CLAIM_STALE_SECONDS (a live holder
 * touches it every PTR_CLAIM_REFRESH_SECONDS). Two processes taking over one
 * stale claim at the same instant may both render that frame: the images
 * are the same pixels (an image depends only on scene, options and seed),
 * each written whole, so no work is lost. */
#ifndef PTR_CLAIM_H
#define PTR_CLAIM_H

#include <stddef.h>

#include "app/batch.h"
#include "base/result.h"

enum { PTR_CLAIM_STALE_SECONDS = 600, PTR_CLAIM_REFRESH_SECONDS = 60 };

typedef enum PtrClaimState {
    PTR_CLAIM_TAKEN,  /* render it */
    PTR_CLAIM_EXISTS, /* the output exists */
    PTR_CLAIM_BUSY,   /* another process holds a live claim */
    PTR_CLAIM_FAILED, /* the claim cannot be made: err says why */
} PtrClaimState;

/* Tries to claim output. holder (size bytes) receives who holds a claim
 * found live, or taken over. */
PtrClaimState ptr_claim_take(const char *output, char *holder, size_t size, PtrError *err);

/* Removes the claim on output this process took, if it is still there. */
void ptr_claim_release(const char *output);

/* Starts the thread that keeps this process's claim fresh; call it before
 * other threads load libraries (see base/threads.h). PTR_ERR_NOMEM if it
 * cannot start. */
PtrResult ptr_claim_keeper_start(PtrError *err);

/* Stops that thread, if it runs. */
void ptr_claim_keeper_stop(void);

#endif /* PTR_CLAIM_H */
