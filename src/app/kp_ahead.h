/* kp_ahead.h - a keypoint file read ahead in a second thread: the reader parses
 * the next batches while the caller runs the pipeline on the current one, so a
 * replay of a large file takes the longer of the two, not their sum. Frames,
 * the end and the first error come out exactly as gs_kpread_next gives them. */
#ifndef GS_KP_AHEAD_H
#define GS_KP_AHEAD_H

#include <stdint.h>

#include "gravscale/gs_pipeline.h"
#include "gs_kpread.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct kp_ahead kp_ahead;

/* A frame's COM sample, gs_pipeline_com's result computed in the reader's thread. */
typedef struct {
    gs_status st;
    gs_com_out out;
} kp_ahead_com;

/* Starts reading r ahead (r is the thread's until kp_ahead_stop). com_of: the
 * pipeline whose gs_pipeline_com the reader runs on every frame (a skeleton
 * layout), NULL for none. NULL when a thread or its buffers cannot be had: the
 * caller then reads r itself. */
kp_ahead *kp_ahead_start(gs_kpread *r, const gs_pipeline *com_of);

/* The next frame and its COM (NULL without com_of; both valid until the next
 * call), or the reader's end/error status with err filled as gs_kpread_next
 * fills it. */
gs_kpr_status kp_ahead_next(kp_ahead *q, const gs_kpframe **f, const kp_ahead_com **com,
                            gs_kpread_error *err);

/* Bytes of the file read by the frames handed out so far, and the file's size. */
void kp_ahead_progress(const kp_ahead *q, uint64_t *done_bytes, uint64_t *total_bytes);

/* Stops the reader (it may be mid-file: the caller gave up), joins it, frees q. */
void kp_ahead_stop(kp_ahead *q);

#ifdef __cplusplus
}
#endif

#endif
