/* gs_feet.c - lifts and touches of two foot points against their floor level (gs_feet.h). */
#include "gravscale/gs_feet.h"

#include <math.h>
#include <string.h>

#include "gs_finite.h"
#include "gs_inline.h"
#include "gs_median.h"

/* thresholds in units of the body's size (stature, px) */
#define STILL_REL   0.25f  /* resting: slower than this x size per second (as a standing body) */
#define FAST_REL    0.5f   /* a falling foot meets the floor faster than this x size per second */
#define FALL_REL    1.0f   /* ... and still falls this fast after a recrossing only in the air (a heel drops slower) */
#define MARGIN_REL  0.01f  /* a lift is confirmed this far above its crossing level (noise) */
#define STOP_RATIO  3.0f   /* stopped: falling less than a third as fast as the frame before */
#define REST_MIN_N  3u     /* ... and at least this many resting samples */
#define REST_AVG_N  32u    /* the floor level follows its resting samples as their mean, then 1/(this + 1) of each */
#define LAG_US      100000u /* stillness: the height against the frame about this far back */
#define UP_COS_MIN  0.9998f /* cos 1.15 deg: a larger turn of up forgets the levels */
#define RISE_REST_K 3       /* a floor higher than the last one must be rested on this many times longer
                             * (stepping onto a box takes long; a foot at its apex in the air is still briefly) */
/* the touch by recrossing serves ankles (COCO-17) only: a build without that layout has none */
#define RECROSS GS_WITH_COCO17  /* (touch_unsure is 2 after a recrossing only) */
/* ... and the touch by the stop toes (BlazePose-33): a build with only one of the layouts has
 * only its touch, so the caller's choice (stop) is read only where both are built in */
#define STOP_TOUCH(stop) (!RECROSS || (GS_WITH_BLAZEPOSE33 && (stop)))
#define NOISE_K     3.0f   /* margins at least this many of the point's own jitter */
#define SPIKE_REL   0.03f  /* a lone frame this far off both neighbours (x size) is an outlier */
#define BRAKE_RATIO 2.0f   /* a falling point slowed more than this in a frame was stopped within it */
#define LAND_G_REL  5.8f   /* gravity in statures per s^2 (9.81 m/s^2 over a 1.7 m body): a landing foot's fall */
#define WAIT_SLOTS  2u    /* history slots 0 and 1: the frame after the pending one, and the pending one */

/* one copy: called for nearly every height read */
static NOINLINE bool fin(float v) { return gs_finite_f(v); }

/* the tracking state of a point, not its logged events */
static NOINLINE void reset_track(gs_foot *f)
{
    for (int k = 0; k < GS_FEET_HIST; k++) f->u_px[k] = NAN;
    f->rest_px = f->floor_px = NAN;
    f->rest_for_us = 0;
    f->rested_from_us = f->rested_to_us = f->sank_us = GS_T_NONE;
    f->rest_n = 0;
    f->armed = f->lift_pending = f->lifted = f->touch_unsure = f->falling = 0;
    f->low_px = NAN;
}

void gs_feet_init(gs_feet *ft, float delta_rel, bool stop_touch)
{
    memset(ft, 0, sizeof *ft);
    ft->up_y = -1.0f;
    ft->delta_rel = delta_rel;
    ft->stop_touch = STOP_TOUCH(stop_touch);
    ft->pend_t_us = ft->t_last_us = ft->t_prev_us = ft->unseen_us = GS_T_NONE;
    for (int p = 0; p < GS_FEET_POINTS; p++) {
        reset_track(&ft->pt[p]);
        for (int k = 0; k < GS_FEET_LOG; k++) ft->pt[p].lift[k].t_us = ft->pt[p].touch[k].t_us = GS_T_NONE;
    }
}

/* the newest event first (a lift's from_px is not read: only a touch's is set) */
static void log_event(gs_feet_event *ev, int64_t t_us, float level_px)
{
    memmove(ev + 1, ev, (GS_FEET_LOG - 1) * sizeof *ev);
    ev->t_us = t_us;
    ev->level_px = level_px;
}

/* slot of the frame `back` frames before the newest (0: the newest): the history moves
 * one slot per frame examined, so that every read is at a fixed offset */
static unsigned slot(uint32_t back) { return back + WAIT_SLOTS; }

/* frames held in the history (two slots are the pending frame and the one after it) */
#define HELD_MAX (GS_FEET_HIST - WAIT_SLOTS)
static uint32_t held(const gs_feet *ft) { return ft->n; }

/* microseconds from the frame `back` frames before the newest to the newest (modulo 2^32: exact) */
static ALWAYS_INLINE uint32_t age_us(const gs_feet *ft, uint32_t back) { return ft->t_us[slot(0)] - ft->t_us[slot(back)]; }

/* the point's height `back` frames before the newest (inline: one load at a fixed slot, shorter than a call) */
static inline float u_at(const gs_foot *f, uint32_t back) { return f->u_px[slot(back)]; }

/* The point's known heights in the history, newest first (a missing or outlier frame is
 * bridged), and their ages in us: their count. */
static NOINLINE unsigned known_heights(const gs_feet *ft, const gs_foot *f, float uk[GS_FEET_HIST],
                                       uint32_t ak[GS_FEET_HIST])
{
    unsigned n = 0;
    for (uint32_t b = 0; b < held(ft); b++) {
        float u = u_at(f, b);
        if (fin(u)) {
            uk[n] = u;
            ak[n++] = age_us(ft, b);
        }
    }
    return n;
}

/* The newest crossing of level L among the n known heights, rising (up) or falling: the
 * index i of the frame after it (uk[i + 1] the one before), n when none. */
static ALWAYS_INLINE unsigned crossing_at(const float *uk, unsigned n, float L, bool up)
{
    for (unsigned i = 0; i + 1u < n; i++)
        if ((uk[i + 1u] <= L) == up && (uk[i] <= L) != up) return i;
    return n;
}

/* The instant of that crossing, interpolated between the two frames around it. */
static int64_t crossing_time(const gs_feet *ft, const float *uk, const uint32_t *ak, unsigned i, float L)
{
    float w = (L - uk[i + 1u]) / (uk[i] - uk[i + 1u]);
    return ft->t_last_us - (int64_t)ak[i + 1u] + (int32_t)(w * (float)(ak[i + 1u] - ak[i]) + 0.5f);
}

/* The newest crossing of level L by the point within the history, rising (up) or falling,
 * interpolated, to *t_us; false when none. */
static bool crossing_us(const gs_feet *ft, const gs_foot *f, float L, bool up, int64_t *t_us)
{
    float uk[GS_FEET_HIST];
    uint32_t ak[GS_FEET_HIST];
    unsigned n = known_heights(ft, f, uk, ak), i = crossing_at(uk, n, L, up);
    if (i == n) return false;
    *t_us = crossing_time(ft, uk, ak, i, L);
    return true;
}

/* The newest downward crossing of level L by a point the floor stops there (a toe landing),
 * placed by its speed in the air. The floor halts it within the frame interval around the
 * impact, so a straight line through that interval puts the landing late (the interval's
 * mean speed mixes the fall with the standstill). Frames within margin (the point's noise)
 * of L, or braked harder than a foot in the air is, may already touch, or be a blurred mix
 * of both: from the last frame surely above them the point falls on to L from its speed
 * between that frame and the one before, accelerating as a body falls, and reaches L no
 * later than the straight line down to the first frame at L would. To *t_us; false when none. */
static bool landing_us(const gs_feet *ft, const gs_foot *f, float L, float margin, float size_px, int64_t *t_us)
{
    float uk[GS_FEET_HIST];
    uint32_t ak[GS_FEET_HIST];
    unsigned n = known_heights(ft, f, uk, ak);
    unsigned c = crossing_at(uk, n, L, false);  /* the first frame at L after the newest crossing */
    if (c == n) return false;
    unsigned a = c;  /* the last frame surely in the air before it: clear of L, and not braked */
    for (unsigned i = c + 1; i < n; i++) {
        float u = uk[i];
        if (!(u > L)) break;  /* (an earlier dip: no clear bracket) */
        if (!(u > L + margin)) continue;
        if (i + 2u < n) {  /* a fall into it under half the one before is no free fall: the impact's blur */
            float u1 = uk[i + 1u], u2 = uk[i + 2u];
            float t0 = (float)ak[i], t1 = (float)ak[i + 1u], t2 = (float)ak[i + 2u];
            if ((u1 - u) * BRAKE_RATIO * (t2 - t1) < (u2 - u1) * (t1 - t0)) continue;
        }
        a = i;
        break;
    }
    if (a == c) {
        *t_us = crossing_time(ft, uk, ak, c, L);
        return true;
    }
    float ua = uk[a];
    float ta = (float)ak[a] * 1e-6f, tc = (float)ak[c] * 1e-6f;  /* s before the newest */
    float tau = (ta - tc) * (ua - L) / (ua - uk[c]);  /* the chord's: the latest */
    if (a + 1u < n) {
        /* falling on from its speed between a and the frame before, as a body falls */
        float g = LAND_G_REL * size_px, tb = (float)ak[a + 1u] * 1e-6f;
        float v = (uk[a + 1u] - ua) / (tb - ta) + 0.5f * g * (tb - ta);
        float disc = v * v + 2.0f * g * (ua - L);
        float tq = disc >= 0.0f ? (sqrtf(disc) - v) / g : NAN;
        if (tq >= 0.0f && tq < tau) tau = tq;
    }
    *t_us = ft->t_last_us - (int32_t)((ta - tau) * 1e6f + 0.5f);  /* (int32: no 64-bit conversion on the target) */
    return true;
}

/* the median of the point's heights `back`, `back`+1 and `back`+2 frames before the newest
 * (a lone outlier does not move it); the height `back` alone when those are not all known */
static float med3_at(const gs_foot *f, uint32_t back)
{
    float a = u_at(f, back);
    if (back + 3u > HELD_MAX) return a;  /* (within the history; past the held frames heights are NaN) */
    float b = u_at(f, back + 1u), c = u_at(f, back + 2u);
    if (!fin(a) || !fin(b) || !fin(c)) return a;
    return gs_med3_f(a, b, c);
}

/* still: the (median) height u_now moved less than STILL_REL x size per second against the
 * median about LAG_US back (the oldest held when the history is shorter): a detector's lone
 * jittery frame, there or here, is no motion, nor is the point's own jitter (jitter_px) */
static bool still(const gs_feet *ft, const gs_foot *f, float u_now, float size_px, float jitter_px)
{
    uint32_t n = held(ft), b = 1;
    if (n < 2) return false;
    while (b + 1 < n && age_us(ft, b) < LAG_US) b++;
    float du = u_now - med3_at(f, b), lim = STILL_REL * size_px * (float)age_us(ft, b) * 1e-6f;
    if (jitter_px > lim) lim = jitter_px;  /* (jitter is no motion) */
    return fabsf(du) < lim;  /* false for NaN (fabsf: a mask, no branch) */
}

/* speed over the interval ending `back` frames before the newest, px/s (NaN unknown) */
static float speed(const gs_feet *ft, const gs_foot *f, uint32_t back)
{
    /* (NaN unless both frames are held: the slots past the held frames are NaN; back <= 2) */
    uint32_t dt = age_us(ft, back + 1) - age_us(ft, back);
    return (u_at(f, back) - u_at(f, back + 1)) / ((float)dt * 1e-6f);
}


static void point_step(gs_feet *ft, gs_foot *f, int64_t t_us, float u, float size_px)
{
    float d = ft->delta_rel * size_px;
    bool stop_touch = STOP_TOUCH(ft->stop_touch);
    if (!fin(u)) return;  /* a missing frame changes nothing */
    float v1 = speed(ft, f, 1), v2 = speed(ft, f, 0);  /* (nothing below changes the history) */
    /* the point's own jitter, learnt while it is still: a detector's toes jitter more than its COM */
    float margin = MARGIN_REL * size_px, jitter = NOISE_K * f->noise_px;
    if (jitter > margin) margin = jitter;
    if (u < f->low_px) f->low_px = u;  /* (NaN before a lift: no change) */
    /* a floor holds the point: the frame after a stop stays at its level; after a recrossing
     * (ankles) the heel comes down onto that level, not past it */
    if (f->touch_unsure) {
        if (u < f->touch[0].level_px - (RECROSS ? (float)f->touch_unsure * margin : margin)) {
            memmove(f->touch, f->touch + 1, (GS_FEET_LOG - 1) * sizeof f->touch[0]);  /* it fell on */
            f->touch[GS_FEET_LOG - 1].t_us = GS_T_NONE;
            /* (a recrossing it fell past: still in the air; a stop's touch cleared lifted) */
            if (RECROSS) f->lifted = f->touch_unsure == 2;
            f->touch_unsure = 0;
        } else if (!RECROSS || f->touch_unsure == 1 || !(v2 < 0.0f)) {
            f->touch_unsure = 0;
        }
    }
    /* a lift: it rested, and rose clearly past its level plus delta in two frames running
     * (one is an outlier) */
    float lift_px = f->rest_px + d;  /* the lift level */
    bool above = u > lift_px + margin;
    if (above && f->lift_pending) {  /* (lift_pending only while armed) */
        int64_t tc;
        if (crossing_us(ft, f, lift_px, true, &tc)) {
            log_event(f->lift, tc, f->rest_px);
            f->lifted = 1;
            f->low_px = u;
        }
        f->armed = 0;
    }
    f->lift_pending = f->armed && above;
    /* a touch by the stop: falling fast, then (nearly) stopped by the floor (for ankles only
     * well below the level they left: a lower floor) */
    /* the floor slows the point at once (a heel comes down at well under a stature per second); in the air it falls on */
    if (RECROSS) f->falling = v2 < -FALL_REL * size_px;  /* (read for recrossings only) */
    float vf = speed(ft, f, 2);  /* (the impact may fall inside the last falling interval) */
    if (!(vf < v1)) vf = v1;
    /* (stopped against v1 is stopped against vf too: vf <= v1 once vf is a fall) */
    if (vf < -FAST_REL * size_px && v2 > v1 / STOP_RATIO &&
        (stop_touch || !(u > f->floor_px - 2.0f * margin))) {
        int64_t tc;
        if (landing_us(ft, f, u + d, margin, size_px, &tc)) {
            log_event(f->touch, tc, u);
            f->touch[0].from_px = f->floor_px;
            f->touch_unsure = 1;
            f->lifted = 0;
        }
    }
    /* a touch by the recrossing (ankles): back down through the level it left, plus delta */
    float back_px = f->floor_px + d;  /* (the recrossing's level) */
    if (RECROSS && !stop_touch && f->lifted && u <= back_px) {
        int64_t tc;
        if (crossing_us(ft, f, back_px, false, &tc)) {
            log_event(f->touch, tc, f->floor_px);
            f->touch[0].from_px = f->floor_px;
            f->touch_unsure = 2;
            f->falling = 0;  /* the next frame tells */
        }
        f->lifted = 0;
    }
    /* the floor level: what the point rests on at its lowest (median heights: an outlier is
     * no step). A rest below it is a new floor, one far above it too (stepping up); a slow
     * rise in between (a heel or a toe rolling up before take-off) is leaving it */
    float m = med3_at(f, 0);
    bool st = still(ft, f, m, size_px, jitter);  /* (noise_px is learnt below) */
    if (st) {  /* |second difference| of a still point: 1.954 sigma on average (NaN: fewer than 3 held) */
        float d2 = fabsf(u - 2.0f * u_at(f, 1) + u_at(f, 2)) / 1.954f;
        if (f->noise_px > 0.0f && d2 > 3.0f * f->noise_px) d2 = 3.0f * f->noise_px;  /* (an outlier) */
        if (d2 == d2) f->noise_px += (f->noise_px > 0.0f ? 0.1f : 1.0f) * (d2 - f->noise_px);
    }
    bool resting = st && m <= f->rest_px + margin;  /* still throughout, at its level */
    /* (outside the band around the floor, or no floor: NaN compares false) */
    if (st && !(m >= f->rest_px - 2.0f * margin && m <= f->rest_px + 3.0f * d + margin)) {
        f->rest_px = m;  /* a new floor */
        f->rest_n = 0;
        resting = true;
        f->rest_for_us = 0;
    } else {
        f->rest_for_us = resting ? f->rest_for_us + (age_us(ft, 1)) : 0u;
    }
    if (resting) {
        f->rest_px += (m - f->rest_px) / (float)(f->rest_n + 1u);
        if (f->rest_n < REST_AVG_N) f->rest_n++;
    }
    uint32_t need_us = f->rest_px > f->floor_px + d + GS_FEET_SINK_REL * size_px ? RISE_REST_K * GS_FEET_REST_US : GS_FEET_REST_US;
    bool rested = resting && f->rest_n >= REST_MIN_N && f->rest_for_us >= need_us;
    lift_px = f->rest_px + d;  /* (the level as it is now) */
    f->armed = (rested && m <= lift_px) || (f->armed && (u <= lift_px + margin || f->lift_pending));
    if (f->armed) f->floor_px = f->rest_px;
    if (m < f->floor_px - d - GS_FEET_SINK_REL * size_px) f->sank_us = t_us;  /* (an ankle may rest delta up, on its toes) */
    /* on the floor: still there, or (toes) not yet risen clear of it since; the run of such frames */
    if (rested || (stop_touch && f->armed)) {
        if (f->rested_to_us != ft->t_prev_us) f->rested_from_us = t_us;
        f->rested_to_us = t_us;
    }
}

/* Examine the pending frame (slot n), once the one after it (next, NaN-free or NULL at the
 * end) shows whether it was a lone outlier: a height away from both neighbours, the same
 * way, by more than SPIKE_REL of the size (feet do not jump there and back in a frame). */
static void process_pending(gs_feet *ft, const float *next)
{
    unsigned s = WAIT_SLOTS - 1u;  /* the pending frame's */
    float size = ft->pend_size_px, spike = SPIKE_REL * size;
    if (next && ft->n > 0)
        for (int p = 0; p < GS_FEET_POINTS; p++) {
            float a = u_at(&ft->pt[p], 0), b = ft->pt[p].u_px[s], c = next[p];
            float da = b - a, dc = b - c;  /* (a - b is -(b - a) exactly) */
            if ((da > spike && dc > spike) || (da < -spike && dc < -spike)) ft->pt[p].u_px[s] = NAN;
        }
    if (ft->n < HELD_MAX) ft->n++;
    /* the history one slot older (each point's just before its step, which reads only its own) */
    for (unsigned k = GS_FEET_HIST - 1u; k > 0u; k--) ft->t_us[k] = ft->t_us[k - 1u];
    ft->t_prev_us = ft->t_last_us;
    ft->t_last_us = ft->pend_t_us;
    for (int p = 0; p < GS_FEET_POINTS; p++) {
        gs_foot *f = &ft->pt[p];
        for (unsigned k = GS_FEET_HIST - 1u; k > 0u; k--) f->u_px[k] = f->u_px[k - 1u];
        float u = u_at(f, 0);  /* the pending frame, now the newest */
        if (!fin(u)) ft->unseen_us = ft->t_last_us;
        point_step(ft, f, ft->t_last_us, u, size);
    }
    ft->pending = 0;
}

void gs_feet_flush(gs_feet *ft)
{
    if (ft->pending) process_pending(ft, NULL);
}

void gs_feet_push(gs_feet *ft, int64_t t_us, const float x_px[GS_FEET_POINTS],
                  const float y_px[GS_FEET_POINTS], gs_real up_x, gs_real up_y, gs_real size_px)
{
    if (!(size_px > 0) || !(size_px < INFINITY) || t_us == GS_T_NONE) return;
    /* (pend_t_us: the newest frame pushed, pending or examined; GS_T_NONE, the lowest int64, before one) */
    if (t_us <= ft->pend_t_us) return;
    float ux = (float)up_x, uy = (float)up_y;
    if (!(ux * ft->up_x + uy * ft->up_y >= UP_COS_MIN)) {
        /* heights along another direction: the levels go, the logged events stay */
        gs_feet_flush(ft);
        for (int p = 0; p < GS_FEET_POINTS; p++) reset_track(&ft->pt[p]);
        ft->epoch++;
        ft->up_x = ux;
        ft->up_y = uy;
    }
    /* this frame waits in the slot after the pending one until the next shows it is no outlier */
    unsigned w = WAIT_SLOTS - 1u - ft->pending;
    ft->t_us[w] = (uint32_t)t_us;
    float u[GS_FEET_POINTS];
    for (int p = 0; p < GS_FEET_POINTS; p++) ft->pt[p].u_px[w] = u[p] = x_px[p] * ux + y_px[p] * uy;
    if (ft->pending) process_pending(ft, u);
    ft->pending = 1;
    ft->pend_t_us = t_us;
    ft->pend_size_px = (float)size_px;
}

int64_t gs_feet_takeoff(const gs_feet *ft, int64_t from_us, int64_t to_us, float *level_px)
{
    int64_t lift[GS_FEET_POINTS], best = GS_T_NONE;
    float sum = 0.0f;
    if (level_px) *level_px = NAN;
    for (int p = 0; p < GS_FEET_POINTS; p++) {
        const gs_feet_event *e = ft->pt[p].lift;
        int k = 0;  /* newest first: each point's last lift in the window */
        while (k < GS_FEET_LOG && !(e[k].t_us != GS_T_NONE && e[k].t_us >= from_us && e[k].t_us < to_us)) k++;
        if (k == GS_FEET_LOG) return GS_T_NONE;  /* both feet must have left */
        lift[p] = e[k].t_us;
        sum += e[k].level_px;
        if (lift[p] > best) best = lift[p];
    }
    /* in the air together: neither came down before the other left (a step is no flight) */
    for (int p = 0; p < GS_FEET_POINTS; p++)
        for (int k = 0; k < GS_FEET_LOG; k++) {
            int64_t t = ft->pt[p].touch[k].t_us;
            if (t > lift[p] && t < best) return GS_T_NONE;  /* (GS_T_NONE is below any time) */
        }
    if (level_px) *level_px = sum / (float)GS_FEET_POINTS;
    return best;
}

int64_t gs_feet_landing(const gs_feet *ft, int64_t from_us, int64_t to_us, float *level_px, float *before_px)
{
    const gs_feet_event *best = NULL;
    for (int p = 0; p < GS_FEET_POINTS; p++)
        for (int k = 0; k < GS_FEET_LOG; k++) {
            const gs_feet_event *e = &ft->pt[p].touch[k];
            /* a recrossing the point is still falling fast past is not a landing (yet) */
            if (RECROSS && k == 0 && ft->pt[p].touch_unsure == 2 && ft->pt[p].falling) continue;
            /* (GS_T_NONE, the lowest int64, is never after from_us) */
            if (e->t_us > from_us && e->t_us <= to_us && (!best || e->t_us < best->t_us))
                best = e;
        }
    static const gs_feet_event none = {GS_T_NONE, NAN, NAN};
    if (!best) best = &none;
    if (level_px) *level_px = best->level_px;
    if (before_px) *before_px = best->from_px;
    return best->t_us;
}

bool gs_feet_resting_at(const gs_feet *ft, int64_t t_us)
{
    for (int p = 0; p < GS_FEET_POINTS; p++) {
        const gs_foot *f = &ft->pt[p];
        if (f->rested_from_us != GS_T_NONE && f->rested_from_us <= t_us && t_us <= f->rested_to_us) return true;
    }
    return false;
}

bool gs_feet_sank_since(const gs_feet *ft, int64_t t_us)
{
    for (int p = 0; p < GS_FEET_POINTS; p++)
        if (ft->pt[p].sank_us != GS_T_NONE && ft->pt[p].sank_us >= t_us) return true;
    return false;
}

bool gs_feet_airborne(const gs_feet *ft)
{
    /* (an ankle's recrossing is a landing only once its heel is down or it stops falling) */
    for (int p = 0; p < GS_FEET_POINTS; p++)
        if (ft->pt[p].lifted || (RECROSS && ft->pt[p].touch_unsure == 2)) return true;
    return false;
}

float gs_feet_low_px(const gs_feet *ft)
{
    float low = NAN;
    for (int p = 0; p < GS_FEET_POINTS; p++)
        if (ft->pt[p].low_px == ft->pt[p].low_px && !(ft->pt[p].low_px >= low)) low = ft->pt[p].low_px;
    return low;
}

bool gs_feet_seen_since(const gs_feet *ft, int64_t t_us)
{
    return ft->n > 0 && (ft->unseen_us == GS_T_NONE || ft->unseen_us < t_us);
}

float gs_feet_floor_px(const gs_feet *ft)
{
    float sum = 0.0f;
    int n = 0;
    for (int p = 0; p < GS_FEET_POINTS; p++) {
        const gs_foot *f = &ft->pt[p];
        if (f->armed && fin(f->rest_px)) { sum += f->rest_px; n++; }
    }
    return n ? sum / (float)n : NAN;
}
