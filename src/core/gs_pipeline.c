/* gs_pipeline.c - keypoints -> COM sample -> ring -> flights -> aggregate -> events.
 * Times are the caller's microseconds (the ring keeps them modulo 2^32 from a base);
 * the double-seconds entry points only convert at the edge (hosts). */
#include "gravscale/gs_pipeline.h"

#include <math.h>
#include <string.h>

#include "gs_cfg_in.h"
#include "gs_dbits.h"
#include "gs_finite.h"

/* the layout's foot points: toes (BlazePose-33: they leave the floor last and meet it first),
 * else ankles (COCO-17); their lift at the instant a foot leaves, x stature: a toe rolls up on
 * its tip by about 1.5 cm, an ankle rides a plantarflexed foot about 9 cm above its rest */
#define TOE_LIFT_REL   0.009f
#define ANKLE_LIFT_REL 0.064f
#define COCO17_LEFT_ANKLE     15  /* the right one follows */
#define BLAZEPOSE33_LEFT_TOE  31

/* the pipeline's layout (one built in: gs_pipeline_init checks) is the point, or BlazePose-33;
 * constant where the build has one layout (gs_features.h) */
static bool is_point(gs_layout l) { return GS_WITH_POINT && (!GS_WITH_POSE || l == GS_LAYOUT_POINT); }
static bool is_blaze(gs_layout l)
{
    return GS_WITH_BLAZEPOSE33 && ((!GS_WITH_POINT && !GS_WITH_COCO17) || l == GS_LAYOUT_BLAZEPOSE33);
}

/* the pipeline tracks visits (a skeleton layout): always where no point layout is built in */
static bool has_sessions(const gs_pipeline *p) { return GS_WITH_POSE && (!GS_WITH_POINT || p->sessions); }

#define ALIGN_UP(n, a) (((n) + ((a) - 1u)) & ~((size_t)(a) - 1u))

size_t gs_pipeline_storage_bytes(const gs_core_config *cfg)
{
    if (!cfg) return 0;
    size_t cap = cfg->ring_capacity;
    /* the ring, then one bit per ring slot for the robust fits' inlier flags */
    return ALIGN_UP(cap * sizeof(gs_sample), 8u) + ALIGN_UP((cap + 31u) / 32u * sizeof(uint32_t), 8u);
}

static void emit(gs_pipeline *p, const gs_event *ev)
{
    if (p->on_event) p->on_event(p->ctx, ev);
}

/* The aggregate as a GS_EV_HEIGHT or GS_EV_SUMMARY event of track. */
static void emit_height(gs_pipeline *p, gs_event_type type, uint32_t track)
{
    gs_event h;
    memset(&h, 0, sizeof h);
    h.type = type;
    gs_agg_get(&p->agg, &h.u.height);
    h.u.height.track = track;
    emit(p, &h);
}

/* Flight events pass through here: accepted jumps feed the aggregate, which
 * reports the running height right after the jump. */
static void on_flight_event(void *ctx, const gs_event *ev)
{
    gs_pipeline *p = (gs_pipeline *)ctx;
    gs_event judged;
    if (ev->type == GS_EV_JUMP && p->judge) {
        judged = *ev;
        p->judge(p->judge_ctx, &judged.u.jump);
        ev = &judged;
    }
    emit(p, ev);
    if (ev->type != GS_EV_JUMP) return;
    if (has_sessions(p)) gs_session_jump(&p->session, &ev->u.jump);
    if (!ev->u.jump.accepted) {
        gs_agg_reject(&p->agg);
    } else if (gs_finite_r(ev->u.jump.height_m)) {  /* a jump of unknown stature (no_size, depth_changed) adds none */
        gs_agg_add(&p->agg, ev->u.jump.height_m, ev->u.jump.height_se_m);
        emit_height(p, GS_EV_HEIGHT, ev->u.jump.track);
    }
}

gs_status gs_pipeline_init(gs_pipeline *p, const gs_core_config *cfg, gs_layout layout,
                           void *storage, size_t storage_bytes,
                           gs_event_fn on_event, void *ctx)
{
    if (!p || !cfg || !storage || gs_layout_kp_count(layout) == 0) return GS_EINVAL;
    if (((uintptr_t)storage & 7u) != 0) return GS_EINVAL;
    if (!gs_cfg_is_baked(cfg)) return GS_EINVAL;  /* a baked build takes its own profile only */
    const gs_core_config *in = GS_CFG_IN(cfg);  /* (so its ring's size is a constant there) */
    size_t need = gs_pipeline_storage_bytes(in);
    if (need == 0 || storage_bytes < need) return GS_ENOMEM;
    memset(p, 0, sizeof *p);
#ifndef GS_BAKED_PROFILE
    p->cfg = *cfg;  /* (read through GS_CFG_IN, which a baked build points at its own constant) */
#endif
    p->layout = layout;
    p->on_event = on_event;
    p->ctx = ctx;
    uint32_t cap = in->ring_capacity;
    gs_sample *samples = (gs_sample *)storage;
    uint32_t *scratch = (uint32_t *)((unsigned char *)storage + ALIGN_UP(cap * sizeof(gs_sample), 8u));
    gs_status st = gs_ring_init(&p->ring, samples, cap);
    if (st != GS_OK) {
        p->finished = true;  /* no ring: every push is refused (GS_ESTATE) */
        return st;
    }
    gs_agg_init(&p->agg);
    p->sessions = GS_WITH_POSE && !is_point(layout);
    if (GS_WITH_POSE)
        gs_session_init(&p->session, gs_time_us_of_cfg_s(in->session_absence_s), (gs_real)in->session_new_body_rel);
    /* (a baked build hands the flight its constant: checked above, and the flight's check folds) */
    st = gs_flight_init(&p->flight, GS_CFG_IN(&p->cfg), &p->ring, scratch, is_point(layout),
                        on_flight_event, p);
    if (st == GS_OK && !is_point(layout))
        gs_flight_use_feet(&p->flight, is_blaze(layout) ? TOE_LIFT_REL : ANKLE_LIFT_REL, is_blaze(layout));
    return st;
}

void gs_pipeline_set_track(gs_pipeline *p, uint32_t track)
{
    if (p) p->flight.track = track;
}

void gs_pipeline_set_judge(gs_pipeline *p, gs_jump_judge_fn fn, void *ctx)
{
    if (!p) return;
    p->judge = fn;
    p->judge_ctx = ctx;
}

void gs_pipeline_set_trace(gs_pipeline *p, bool on)
{
    if (p) p->flight.trace = on;
}

void gs_pipeline_set_close_whole(gs_pipeline *p, bool on)
{
#if GS_CLOSE_LAG_FRAMES > 0
    if (p) p->flight.close_whole = on;
#else
    (void)p;
    (void)on;
#endif
}

static void emit_session(gs_pipeline *p, bool ended, const char *reason)
{
    gs_event ev;
    gs_ev_height h;  /* (gs_session_event reads the stature and its interval) */
    gs_agg_get(&p->agg, &h);
    gs_session_event(&p->session, ended, reason, &h, p->flight.track, &ev);
    emit(p, &ev);
}

/* A visit ends after a long absence or when someone else stands there; the
 * next one starts with its own aggregate and standing size. */
static void track_session(gs_pipeline *p, const gs_sample_full *s)
{
    bool present = s->w >= 0.05f;  /* (a sample's w is 0 where its position is not finite) */
    const char *why;  /* (set by gs_session_frame with every GS_SESSION_ENDED) */
    uint32_t r = gs_session_frame(&p->session, s->t_us, present, gs_flight_stand_at(&p->flight, s->t_us), &why);
    if (r & GS_SESSION_ENDED) {
        emit_session(p, true, why);
        gs_session_close(&p->session);
        gs_agg_init(&p->agg);
        gs_flight_forget_body(&p->flight);
        /* the frame again, for the next visit: present, it starts one (absent, it does nothing) */
        r = gs_session_frame(&p->session, s->t_us, present, (gs_real)NAN, &why);
    }
    if (r & GS_SESSION_STARTED) emit_session(p, false, NULL);
}

static gs_status push_sample(gs_pipeline *p, const gs_sample_full *s, const float *feet_xy)
{
    if (p->finished) return GS_ESTATE;
    if (s->t_us == GS_T_NONE) return GS_EINVAL;
    const int64_t last_us = p->ring.t_last_us;  /* the newest frame's, GS_T_NONE before the first */
    /* (GS_T_NONE before the first frame is the lowest int64: neither test holds) */
    if (s->t_us < last_us) return GS_EORDER;
    if (s->t_us == last_us) return GS_OK;  /* a repeated frame carries nothing new */
    if (!gs_time_ok(s->t_us)) return GS_ERANGE;
    /* after a gap beyond the ring's time span its samples leave it: a flight
     * left open must close on them first (as it would on any long gap); the
     * difference as uint64 is exact for any two accepted times, and at least 2^62
     * before the first frame (GS_T_NONE), where the break, as a flush would, finds
     * neither a sample nor a flight */
    if ((uint64_t)s->t_us - (uint64_t)last_us >= (uint64_t)GS_RING_SPAN_US)
        gs_flight_break(&p->flight);
    gs_ring_store(&p->ring, s);  /* (checked above as gs_ring_push would) */
    if (feet_xy) gs_flight_feet(&p->flight, s->t_us, feet_xy, feet_xy + GS_FEET_POINTS, s->size_px);
    if (GS_WITH_TRACE && p->flight.trace && p->on_event) {
        gs_event ev;
        memset(&ev, 0, sizeof ev);
        ev.type = GS_EV_SAMPLE;
        ev.u.sample.t_us = s->t_us;
        ev.u.sample.x_px = s->x_px;
        ev.u.sample.y_px = s->y_px;
        ev.u.sample.w = s->w;
        ev.u.sample.size_px = s->size_px;
        ev.u.sample.upright = s->upright;
        p->on_event(p->ctx, &ev);
    }
    gs_flight_update(&p->flight);
    if (has_sessions(p)) track_session(p, s);
    return GS_OK;
}

gs_status gs_pipeline_com(const gs_pipeline *p, const gs_kp *kp, gs_com_out *com)
{
    if (!p || !kp || !com) return GS_EINVAL;
    const gs_core_config *c = GS_CFG_IN(&p->cfg);
    return gs_com_compute(p->layout, c->mass_table, c->stature, c->min_conf, kp, com);
}

/* com's sample with weight w, and the feet from kp */
static gs_status push_com(gs_pipeline *p, int64_t t_us, const gs_kp *kp, const gs_com_out *com, float w)
{
    gs_sample_full s;
    s.t_us = t_us;
    s.x_px = com->x_px;
    s.y_px = com->y_px;
    s.w = w;
    s.size_px = com->stature_px;
    s.up_x = com->up_x;
    s.up_y = com->up_y;
    s.upright = com->upright;
    float feet[2 * GS_FEET_POINTS];  /* x then y of each point, NaN missing */
    for (int k = 0; k < GS_FEET_POINTS; k++) {
        float x = NAN, y = NAN;  /* a point has no feet */
        if (!is_point(p->layout)) {
            const gs_kp *f = &kp[(is_blaze(p->layout) ? BLAZEPOSE33_LEFT_TOE : COCO17_LEFT_ANKLE) + k];
            float min_conf = GS_CFG_IN(&p->cfg)->min_conf;
            if (f->c >= min_conf && (min_conf > 0.0f || f->c > 0.0f)) {  /* (as in gs_com.c) */
                x = f->x_px;
                y = f->y_px;
            }
        }
        feet[k] = x;
        feet[GS_FEET_POINTS + k] = y;
    }
    return push_sample(p, &s, feet);
}

gs_status gs_pipeline_push_com_us(gs_pipeline *p, int64_t t_us, const gs_kp *kp, const gs_com_out *com)
{
    if (!p || !kp || !com) return GS_EINVAL;
    return push_com(p, t_us, kp, com, gs_finite2_f(com->x_px, com->y_px) ? com->w : 0.0f);
}

gs_status gs_pipeline_push_keypoints_us(gs_pipeline *p, int64_t t_us, const gs_kp *kp)
{
    gs_com_out c;
    gs_status st = gs_pipeline_com(p, kp, &c);
    if (st != GS_OK) return st;
    return push_com(p, t_us, kp, &c, c.w); /* (gs_com_compute's w is 0 where its COM is not finite) */
}

gs_status gs_pipeline_push_point_us(gs_pipeline *p, int64_t t_us, float x_px, float y_px,
                                    float c, float size_px)
{
    if (!p) return GS_EINVAL;
    gs_sample_full s;
    s.t_us = t_us;
    s.x_px = x_px;
    s.y_px = y_px;
    s.w = (gs_finite2_f(x_px, y_px) && c > 0.0f) ? (c < 1.0f ? c : 1.0f) : 0.0f;
    s.size_px = size_px;
    s.up_x = NAN;
    s.up_y = NAN;
    s.upright = 1.0f;
    return push_sample(p, &s, NULL);
}

/* t_s in microseconds for push_sample: not finite -> GS_T_NONE (GS_EINVAL); finite
 * beyond the range -> +-INT64_MAX, which meet the order check as before and then
 * are refused (GS_ERANGE) */
static int64_t edge_us(double t_s)
{
    int64_t t_us = gs_time_us_of_s(t_s);
    if (t_us != GS_T_NONE || !gs_dfinite(t_s)) return t_us;
    return (gs_dbits(t_s) & GS_DBITS_SIGN) ? -INT64_MAX : INT64_MAX;
}

gs_status gs_pipeline_push_keypoints(gs_pipeline *p, double t_s, const gs_kp *kp)
{
    return gs_pipeline_push_keypoints_us(p, edge_us(t_s), kp);
}

gs_status gs_pipeline_push_com(gs_pipeline *p, double t_s, const gs_kp *kp, const gs_com_out *com)
{
    return gs_pipeline_push_com_us(p, edge_us(t_s), kp, com);
}

gs_status gs_pipeline_push_point(gs_pipeline *p, double t_s, float x_px, float y_px, float c, float size_px)
{
    return gs_pipeline_push_point_us(p, edge_us(t_s), x_px, y_px, c, size_px);
}

gs_status gs_pipeline_flush(gs_pipeline *p)
{
    if (!p) return GS_EINVAL;
    if (p->finished) return GS_ESTATE;
    gs_flight_finish(&p->flight);
    p->finished = true;
    if (has_sessions(p) && p->session.open) {
        emit_session(p, true, "end_of_stream");
        gs_session_close(&p->session);
    }
    emit_height(p, GS_EV_SUMMARY, p->flight.track);
    return GS_OK;
}
