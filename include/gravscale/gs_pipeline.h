/* gs_pipeline.h - the whole core: keypoints -> COM sample -> ring -> flight
 * detection and fit -> height aggregate -> events. Caller owns all memory. */
#ifndef GS_PIPELINE_H
#define GS_PIPELINE_H

#include "gs_types.h"
#include "gs_com.h"
#include "gs_ring.h"
#include "gs_flight.h"
#include "gs_agg.h"
#include "gs_config.h"
#include "gs_session.h"

/* The front end's say on a flight before it is reported and aggregated: it may
 * add warnings or reject it (accepted = false and a reason), from what the
 * frames show and the keypoints cannot (the core cannot see the frames). */
typedef void (*gs_jump_judge_fn)(void *ctx, gs_ev_jump *jump);

typedef struct {
    gs_core_config cfg;        /* the caller's copy; left zeroed in a baked build (GS_BAKED_PROFILE), which reads its own constant */
    gs_layout layout;
    gs_ring ring;
    gs_flight flight;
    gs_agg agg;                /* per session for bodies (a new person starts afresh) */
    gs_session session;        /* body layouts only; a ball has no visits */
    bool sessions;
    gs_event_fn on_event;
    void *ctx;
    gs_jump_judge_fn judge;    /* NULL: none */
    void *judge_ctx;
    bool finished;
} gs_pipeline;

/* Bytes of storage gs_pipeline_init needs for cfg->ring_capacity. */
size_t gs_pipeline_storage_bytes(const gs_core_config *cfg);

/* storage: at least gs_pipeline_storage_bytes(cfg) bytes, aligned for double. A core
 * built with its profile baked in (GS_BAKED_PROFILE, docs/firmware.md) takes only that
 * profile: any other cfg gives GS_EINVAL. */
gs_status gs_pipeline_init(gs_pipeline *p, const gs_core_config *cfg, gs_layout layout,
                           void *storage, size_t storage_bytes,
                           gs_event_fn on_event, void *ctx);
/* Number this pipeline's object: every jump/height/summary event carries it
 * (one pipeline per tracked object when several are followed). Default 0. */
void gs_pipeline_set_track(gs_pipeline *p, uint32_t track);
/* A judge for every flight (see gs_jump_judge_fn); NULL removes it. */
void gs_pipeline_set_judge(gs_pipeline *p, gs_jump_judge_fn fn, void *ctx);
/* Also emit GS_EV_STATE / GS_EV_SAMPLE / GS_EV_FIT trace events. */
void gs_pipeline_set_trace(gs_pipeline *p, bool on);
/* Run every flight's close whole in its landing's frame rather than in steps over the
 * next frames (GS_CLOSE_LAG_FRAMES): for a caller whose judge or event handler reads
 * that frame's own state, such as the video detectors. The events are the same. */
void gs_pipeline_set_close_whole(gs_pipeline *p, bool on);

/* One frame of keypoints (gs_layout_kp_count(layout) of them) at t_us
 * microseconds. t_us must not decrease (GS_EORDER, sample dropped); equal
 * times are dropped silently; GS_EINVAL for GS_T_NONE, GS_ERANGE beyond
 * GS_T_MAX_US. */
gs_status gs_pipeline_push_keypoints_us(gs_pipeline *p, int64_t t_us, const gs_kp *kp);
/* gs_pipeline_push_keypoints_us in its two steps, gs_pipeline_com then
 * gs_pipeline_push_com_us, so that a host can compute the COM in another
 * thread: gs_pipeline_com reads only what gs_pipeline_init set (the layout,
 * mass table, stature method and min_conf), so it may run on later frames
 * while p takes earlier ones. The keypoints go with their COM (they give the
 * feet). GS_EINVAL for NULL. */
gs_status gs_pipeline_com(const gs_pipeline *p, const gs_kp *kp, gs_com_out *com);
gs_status gs_pipeline_push_com_us(gs_pipeline *p, int64_t t_us, const gs_kp *kp, const gs_com_out *com);
/* One frame of a tracked point (GS_LAYOUT_POINT) with its size (NaN unknown). */
gs_status gs_pipeline_push_point_us(gs_pipeline *p, int64_t t_us, float x_px, float y_px,
                                    float c, float size_px);
/* The same with t_s in seconds (hosts), rounded to the microsecond
 * (gs_time_us_of_s): GS_EINVAL when not finite. */
gs_status gs_pipeline_push_keypoints(gs_pipeline *p, double t_s, const gs_kp *kp);
gs_status gs_pipeline_push_com(gs_pipeline *p, double t_s, const gs_kp *kp, const gs_com_out *com);
gs_status gs_pipeline_push_point(gs_pipeline *p, double t_s, float x_px, float y_px,
                                 float c, float size_px);
/* End of stream: finish open flights and emit GS_EV_SUMMARY. Further pushes: GS_ESTATE. */
gs_status gs_pipeline_flush(gs_pipeline *p);

#endif
