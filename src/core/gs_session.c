/* gs_session.c - sessions: presence, a reference standing size, per-visit results. */
#include "gravscale/gs_session.h"

#include <math.h>
#include <string.h>

#include "gs_finite.h"
#include "gs_inline.h"
#include "gs_median.h"

#define GAP_MAX_US 500000  /* an absence this long (or the absence limit, when shorter) is a gap */
#define ODD_RUN_NEEDED 6u  /* standing frames off the reference that make a new body (noise is single frames) */

/* the per-visit state: every field from gap_since_ref to the end (gs_session.h) */
static void reset_visit(gs_session *s)
{
    memset(&s->gap_since_ref, 0, sizeof *s - offsetof(gs_session, gap_since_ref));
    s->ref_px = (gs_real)NAN;
    s->best_jump_m = s->best_flight_s = (gs_real)NAN;
}

void gs_session_init(gs_session *s, int64_t absence_us, gs_real new_body_rel)
{
    if (!s) return;
    /* each field before the visit's, which reset_visit sets */
    s->absence_us = absence_us;
    s->new_body_rel = new_body_rel;
    s->gap_us = absence_us < GAP_MAX_US ? absence_us : GAP_MAX_US;
    s->id = 0;
    s->open = false;
    s->t_start_us = s->t_seen_us = GS_T_NONE;
    reset_visit(s);
}

/* the median of GS_SESSION_REF_N sizes (sorted in place where gs_real is float: they
 * are not read again) */
static gs_real median_ref(float *v)
{
    if (GS_REAL_IS_FLOAT) return gs_sort_median((gs_real *)(void *)v, GS_SESSION_REF_N);
    gs_real t[GS_SESSION_REF_N];
    for (uint32_t i = 0; i < GS_SESSION_REF_N; i++) t[i] = v[i];
    return gs_sort_median(t, GS_SESSION_REF_N);
}

static uint32_t start(gs_session *s, int64_t t_us)
{
    s->id++;
    s->open = true;
    s->t_start_us = s->t_seen_us = t_us;
    reset_visit(s);
    return GS_SESSION_STARTED;
}

/* t is at least span after t0 (an earlier t never is); the difference as uint64 is
 * exact for any two times, where int64 would overflow */
static bool elapsed(int64_t t_us, int64_t t0_us, int64_t span_us)
{
    return t_us >= t0_us && (span_us <= 0 || (uint64_t)t_us - (uint64_t)t0_us >= (uint64_t)span_us);
}

/* finite and > 0 */
static NOINLINE bool positive(gs_real x) { return x > GS_R(0.0) && x < (gs_real)INFINITY; }

uint32_t gs_session_frame(gs_session *s, int64_t t_us, bool present, gs_real stand_px, const char **end_reason)
{
    if (!s || t_us == GS_T_NONE) return 0;
    if (end_reason) *end_reason = NULL;
    if (!present) {
        if (s->open && elapsed(t_us, s->t_seen_us, s->absence_us)) {
            if (end_reason) *end_reason = "absence";
            return GS_SESSION_ENDED;  /* the caller emits the end, then gs_session_close */
        }
        return 0;
    }
    if (!s->open) return start(s, t_us);
    if (elapsed(t_us, s->t_seen_us, s->gap_us) && s->ref_n >= GS_SESSION_REF_N) s->gap_since_ref = true;
    s->t_seen_us = t_us;
    if (!positive(stand_px)) return 0;
    if (s->ref_n < GS_SESSION_REF_N) {
        s->ref_acc[s->ref_n++] = (float)stand_px;
        if (s->ref_n == GS_SESSION_REF_N) s->ref_px = median_ref(s->ref_acc);
        return 0;
    }
    /* the same person stepping closer changes size while seen; someone else appears after a gap */
    if (s->gap_since_ref && GS_FABSR(stand_px / s->ref_px - GS_R(1.0)) > s->new_body_rel) {
        if (++s->odd_run >= ODD_RUN_NEEDED) {
            if (end_reason) *end_reason = "new_body";
            return GS_SESSION_ENDED;
        }
    } else {
        s->odd_run = 0;
    }
    return 0;
}

/* a known value into a sum and its count, and into the best (largest) when given */
static NOINLINE void tally(gs_real x, gs_real *sum, uint32_t *n, gs_real *best)
{
    if (!gs_finite_r(x)) return;
    *sum += x;
    ++*n;
    if (best && !(x <= *best)) *best = x; /* NaN best: the first */
}

void gs_session_jump(gs_session *s, const gs_ev_jump *j)
{
    if (!s || !j || !s->open) return;
    if (!j->accepted) {
        s->n_rejected++;
        return;
    }
    s->n_jumps++;
    tally(j->jump_height_m, &s->sum_jump_m, &s->n_jump_h, &s->best_jump_m);
    tally(j->flight_time_s, &s->sum_flight_s, &s->n_flight_t, &s->best_flight_s);
    tally(j->takeoff_velocity_m_s, &s->sum_v_m_s, &s->n_v, NULL);
}

/* a tally's mean, NaN without values */
static NOINLINE gs_real mean_of(gs_real sum, uint32_t n)
{
    return n ? sum / (gs_real)n : (gs_real)NAN;
}

void gs_session_event(const gs_session *s, bool ended, const char *reason, const gs_ev_height *stature,
                      uint32_t track, gs_event *ev)
{
    memset(ev, 0, sizeof *ev);  /* (no reason while the session is open) */
    ev->type = GS_EV_SESSION;
    gs_ev_session *e = &ev->u.session;
    e->track = track;
    e->session = s->id;
    e->ended = ended;
    e->t_start_us = s->t_start_us;
    e->n_jumps = s->n_jumps;
    e->n_rejected = s->n_rejected;
    if (!ended) {
        /* the results come with the end */
        e->t_end_us = GS_T_NONE;
        e->stature_m = e->ci95_lo_m = e->ci95_hi_m = (gs_real)NAN;
        e->best_jump_m = e->mean_jump_m = e->best_flight_s = e->mean_flight_s = e->mean_takeoff_velocity_m_s =
            (gs_real)NAN;
        return;
    }
    e->reason = reason;
    e->t_end_us = s->t_seen_us;
    if (stature) {
        e->stature_m = stature->height_m;
        e->ci95_lo_m = stature->ci95_lo_m;
        e->ci95_hi_m = stature->ci95_hi_m;
    } else {
        e->stature_m = e->ci95_lo_m = e->ci95_hi_m = (gs_real)NAN;
    }
    e->best_jump_m = s->best_jump_m;
    e->best_flight_s = s->best_flight_s;
    e->mean_jump_m = mean_of(s->sum_jump_m, s->n_jump_h);
    e->mean_flight_s = mean_of(s->sum_flight_s, s->n_flight_t);
    e->mean_takeoff_velocity_m_s = mean_of(s->sum_v_m_s, s->n_v);
}

void gs_session_close(gs_session *s)
{
    if (s) s->open = false;
}
