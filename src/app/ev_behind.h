/* ev_behind.h - events handed to a second thread that formats and writes them,
 * in order, while the caller's thread runs the pipeline on. */
#ifndef GS_EV_BEHIND_H
#define GS_EV_BEHIND_H

#include "gravscale/gs_flight.h" /* gs_event_fn */

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ev_behind ev_behind;

/* Starts a thread that calls fn(ctx, ev) on every event put, in order. NULL
 * when a thread cannot be had: the caller then calls fn itself. */
ev_behind *ev_behind_start(gs_event_fn fn, void *ctx);

/* Copies ev for the thread (an event's strings are static or outlive the
 * thread); waits while the thread is a full queue behind. */
void ev_behind_put(ev_behind *q, const gs_event *ev);

/* Waits until fn has run on every event put, stops the thread, frees q. */
void ev_behind_stop(ev_behind *q);

#ifdef __cplusplus
}
#endif

#endif
