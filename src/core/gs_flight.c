/* gs_flight.c - online flight detection and per-flight measurement.
 *
 * A flight is seeded at a prominent apex of the COM along the image "up"
 * direction. Its right side then grows sample by sample against the running
 * fit's prediction until the body is decelerated by the ground (contact shows
 * as a one-sided deviation against gravity); the left side is grown from the
 * ring history when the flight closes. Take-off and landing are then refined
 * to sub-frame times with a piecewise model (parabola plus 1/2 da (t-T)^2 past
 * the boundary) and the final robust 2D fit uses only samples in free flight.
 * On hosts the close runs in bounded steps over the frames after the landing
 * (gs_close): no sample is examined meanwhile, so each step reads the landing's state.
 *
 * Numbers: every value (u, noise, levels, CUSUM, sizes, fits, boundary models,
 * apex, SE, q, height) is gs_real: float on the M4 (single-precision FPU), double
 * on hosts. Every time is integer microseconds (gs_time.h), and so is every
 * decision taken from times: gaps, latency and settling against the configured
 * spans, and the frame counts taken from the frame interval (kept in 1/16 us) by
 * an integer ceil (core width, boundary grid steps, speed lag). Those are knife
 * edges (a span of exactly 6 frames rounds up or not); in integers the device
 * decides them exactly as the host does. Only spans inside a flight window become
 * gs_real seconds (gs_time_span_s). */
#include "gravscale/gs_flight.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#define GS_PI GS_R(3.14159265358979323846)

#ifdef GS_FLIGHT_DEBUG
#include <stdio.h>
#define DBG(...) fprintf(stderr, __VA_ARGS__)
#else
#define DBG(...) ((void)0)
#endif

#include "gs_cfg_in.h"
#include "gs_finite.h"
#include "gs_inline.h"
#include "gs_median.h"
#include "gs_select.h"


/* tuning: thresholds in units of the noise or of the object's size */
#define CFG(f) GS_CFG_IN((f)->cfg)  /* gs_cfg_in.h: a constant where the profile is baked */
/* the feet time the flights: always where no point layout is built (every object is a body) */
#define FEET_ON(f) (!GS_WITH_POINT || (f)->feet_on)
#define USABLE_W_MIN     0.05f  /* lighter frames are left out of flight detection */
#define SEED_RISE_REL    GS_R(0.03)   /* apex must rise this x size above the recent minimum */
#define SEED_RISE_NOISE  GS_R(8.0)    /* ... and this x noise */
#define SEED_DROP_NOISE  GS_R(2.5)    /* apex confirmed once u fell this x noise below it */
#define CORE_HALF_US     70000        /* half-width of the seed's core window */
#define CUSUM_K          GS_R(1.3)    /* CUSUM reference: deviations below k sigma drain it */
#define CUSUM_H          GS_R(5.0)    /* CUSUM alarm: contact */
#define VERIFY_RMS       GS_R(2.5)    /* ... and only when the refit's residual is near the noise */
#define VERIFY_Z         GS_R(2.0)    /* after a refit through an alarm, edge samples below this: false alarm */
#define CUSUM_ZMAX       GS_R(6.0)    /* one sample adds at most this (a lone glitch cannot end a flight) */
#define BOUNDARY_IN_US   25000        /* boundary search reaches this far (at least a frame) inside the grown flight */
#define GROSS_OUTLIER    GS_R(7.0)    /* perpendicular or downward deviation = bad keypoints, skipped */
#define CONTACT_MIN_G    GS_R(0.5)    /* contact force past a boundary: at least half of g */
#define DROP_PENALTY     GS_R(4.0)    /* SSR gain (x sigma^2) needed to drop a sample the online test kept */
#define TAKEOFF_MAX_G    GS_R(4.0)    /* contact force past take-off: (push-off + g) at most 4 g */
#define LANDING_MAX_G    GS_R(30.0)   /* ... and past landing (impacts are harder) */
#define CONTACT_SAMPLES_MAX 4   /* contact samples past each boundary seen by the piecewise model */
#define BOUNDARY_STEPS   4      /* grid points per frame interval for sub-frame boundaries */
#define STAND_SPEED_REL  GS_R(0.25)   /* standing: |du/dt| below this x size per second */
#define STAND_UPRIGHT    GS_R(0.7)
#define LOOSE_UPRIGHT    GS_R(0.5)    /* fallback size samples (no settled stance seen yet) */
#define MEDIAN_MAX       64     /* largest set a median is taken of */
#define NOISE_INIT_N     9      /* second differences whose median starts the noise estimate */
#define STAND_SETTLE_US  200000       /* still this long before a frame counts as standing */
#define SPEED_LAG_US     100000       /* stillness for the noise: speed against the sample this far back */
/* stillness for a stance: a little further back, so that a span of exactly 0.1 s counts
 * one frame more (4 at 30 fps, not 3): a longer lag averages more keypoint noise, which a
 * brief stance needs (the jumpvision gym clip's only still upright frames are three at
 * the apex); on the held-out-like set it also gave the smaller height errors */
#define STAND_LAG_US     101000
#define LEVEL_BLOCK_US   500000       /* the recent minimum's blocks */
#define DT_DEFAULT_Q4    533333u      /* 1/30 s in 1/16 us: the frame interval before one is seen */
#define DT_MAX_US        (INT64_C(1) << 26)  /* longer frame intervals count as this (67 s) */
#define EMIT_FACTOR      GS_R(2.0)    /* candidates implying a size beyond [min/2, max*2] are not flights */
/* the feet (body layouts) */
#define FEET_BEFORE_COM_US 150000     /* the feet's take-off and landing lie after the COM's boundary minus this */
#define FEET_AFTER_COM_US  100000     /* ... and the landing before the COM's plus this (the COM keeps falling a frame or two) */
#define FEET_FREE_EDGE_US 50000      /* the fit takes samples this far past the feet's boundaries (30-60 ms of push-off below body weight) */
#define FALL_FLOOR_REL   0.1f         /* landed this x size below the floor it left (a box, 20-60 cm): a fall, not a jump; less is a jump toward the camera */
#define FEET_WAIT_US     100000       /* after the COM's landing, wait this long for feet still in the air */
#define STRIDE_REL       GS_R(0.5)    /* a short COM-timed flight moving across faster than this x size per second is a stride */
#define CONTACT_MAX_US   1000000      /* a rebound leaves the ground within this of the landing (drop jumps: 0.2-0.9 s) */
#define DEPTH_TOL_REL    GS_R(0.015)  /* standing at the flight's place: its floor row within this x size */
#define COM_MISMATCH_REL GS_R(0.04)   /* the COM at landing this x size off its take-off height: flagged */
#define GRAV_DIR_SE_K    GS_R(2.0)    /* gravity's direction may differ from the expected by this many SE ... */
#define GRAV_DIR_MIN_DEG GS_R(8.0)    /* ... plus this (a standing body's axis leans a few degrees, most seen from the side) */

/* isfinite of a gs_real (or float) value, in one place */
static NOINLINE bool finite_r(gs_real x) { return gs_finite_r(x); }


/* The flight's sample indices are 32-bit offsets from f->base (64-bit compares and
 * adds cost code on a 32-bit core): the ring index of offset i, and the offset of a
 * held ring index (held samples are never before the base: see rebase). */
static uint64_t ring_idx(const gs_flight *f, uint32_t i) { return f->base + i; }
static uint32_t idx_of(const gs_flight *f, uint64_t ring_i) { return (uint32_t)(ring_i - f->base); }

/* The ring's head and its oldest held sample as offsets (f->ring is set at init, never NULL:
 * read without the accessors' NULL test) */
static uint32_t head_idx(const gs_flight *f) { return idx_of(f, f->ring->head); }
static uint32_t oldest_idx(const gs_flight *f) { return idx_of(f, f->ring->valid_from); }

/* Ring sample i unpacked into *buf; NULL when the ring no longer holds it. */
static const gs_sample_full *at(const gs_flight *f, uint32_t i, gs_sample_full *buf)
{
    return gs_ring_get(f->ring, ring_idx(f, i), buf) ? buf : NULL;
}

/* The flight's times (_lus): int32 microseconds from f->tb_us (gs_flight.h). The local
 * time of an absolute one within their range: the low words alone give it exactly, and a
 * 32-bit core loads and subtracts only those. */
static ALWAYS_INLINE int32_t lt_of(const gs_flight *f, int64_t t_us)
{
    return (int32_t)((uint32_t)(uint64_t)t_us - (uint32_t)(uint64_t)f->tb_us);
}

/* ... and the absolute time of a local one */
static NOINLINE int64_t abs_of(const gs_flight *f, int32_t t_lus) { return f->tb_us + t_lus; }

/* local time of ring sample i (the packed field is its low word), GS_LT_NONE when not held */
static int32_t lt_at(const gs_flight *f, uint32_t i)
{
    const gs_sample *s = gs_ring_at(f->ring, ring_idx(f, i));
    return s ? (int32_t)(s->t_us - (uint32_t)(uint64_t)f->tb_us) : GS_LT_NONE;
}

/* time of ring sample i, GS_T_NONE when not held */
static int64_t t_at(const gs_flight *f, uint32_t i)
{
    const gs_sample *s = gs_ring_at(f->ring, ring_idx(f, i));
    return s ? gs_ring_sample_t_us(f->ring, s) : GS_T_NONE;
}

/* Frames that weigh almost nothing (the COM lacks a whole segment, e.g. the head
 * out of the frame at the apex) take no part in detecting flights either. */
static bool usable(const gs_sample_full *s)
{
    return s && s->w >= USABLE_W_MIN && gs_finite2_f(s->x_px, s->y_px);
}

/* t1 - t0 longer than a span (false when either time is unknown); both are held samples'
 * times, less than 2^31 us apart */
static NOINLINE bool span_over(int32_t t1_lus, int32_t t0_lus, int32_t span_us)
{
    return t1_lus != GS_LT_NONE && t0_lus != GS_LT_NONE && t1_lus - t0_lus > span_us;
}

/* t1 - t0 for two times less than 2^31 us apart (two held ring samples; a time inside a
 * flight window and its fit's centre, the window's samples held with it): the low words
 * alone give it exactly, and a 32-bit core loads and subtracts only those. */
static ALWAYS_INLINE int32_t near_us(int64_t t1_us, int64_t t0_us)
{
    return (int32_t)(uint32_t)((uint64_t)t1_us - (uint64_t)t0_us);
}

/* Does t lie past T toward side (+1: later, -1: earlier), away from the flight? */
static bool beyond(int32_t t_lus, int32_t T_lus, int side)
{
    return side < 0 ? t_lus < T_lus : t_lus > T_lus;
}

/* How far t lies past T toward side in seconds; negative: on the flight's side. In 64 bits:
 * a grid point may lie up to a frame beyond the held samples (see refine_boundary). */
static gs_real past_s(int32_t t_lus, int32_t T_lus, int side)
{
    int64_t d = (int64_t)t_lus - T_lus;
    return gs_time_span_s(side < 0 ? -d : d, 0);
}

/* Ring sample i unpacked into *buf when held and usable, else NULL. */
static const gs_sample_full *usable_at(const gs_flight *f, uint32_t i, gs_sample_full *buf)
{
    const gs_sample_full *s = at(f, i, buf);
    return usable(s) ? s : NULL;
}

/* usable samples among [lo, hi] */
static NOINLINE uint32_t count_usable(const gs_flight *f, uint32_t lo, uint32_t hi)
{
    uint32_t n = 0;
    gs_sample_full b;
    for (uint32_t i = lo; i <= hi; i++) n += usable_at(f, i, &b) ? 1u : 0u;
    return n;
}

/* a measured size: positive and finite */
static NOINLINE bool size_ok(float size_px) { return size_px > 0.0f && size_px < INFINITY; }

static NOINLINE gs_real u_of(const gs_flight *f, const gs_sample_full *s)
{
    return (gs_real)s->x_px * f->up_x + (gs_real)s->y_px * f->up_y;
}

static void emit(const gs_flight *f, const gs_event *ev)
{
    if (f->on_event) f->on_event(f->ctx, ev);
}

const char *gs_flight_state_name(gs_flight_state s)
{
    switch (s) {
    case GS_FS_IDLE: return "idle";
    case GS_FS_GROUND: return "ground";
    case GS_FS_AIRBORNE: return "airborne";
    }
    return "?";
}

static NOINLINE void set_state(gs_flight *f, gs_flight_state to, int64_t t_us)
{
    if (GS_WITH_TRACE && f->trace && f->state != to) {
        gs_event ev;
        memset(&ev, 0, sizeof ev);
        ev.type = GS_EV_STATE;
        ev.u.state.t_us = t_us;
        ev.u.state.from = gs_flight_state_name(f->state);
        ev.u.state.to = gs_flight_state_name(to);
        emit(f, &ev);
    }
    f->state = to;
}

static void trace_fit(const gs_flight *f, const char *purpose, int64_t t0_us, int64_t t1_us,
                      const gs_fit_result *r)
{
    if (!GS_WITH_TRACE || !f->trace) return;
    gs_event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_FIT;
    ev.u.fit.purpose = purpose;
    ev.u.fit.t_first_us = t0_us;
    ev.u.fit.t_last_us = t1_us;
    ev.u.fit.n = r ? r->n : 0;
    ev.u.fit.a_px_s2 = r ? r->a_px_s2 : NAN;
    ev.u.fit.g_dir_deg = r ? r->g_dir_deg : NAN;
    ev.u.fit.rms_px = r ? r->rms_px : NAN;
    emit(f, &ev);
}

/* Medians of bounded arrays of finite values (v may be reordered). Where the build
 * optimises for speed, the middle one by rank (up to 32 values on AVX2 hosts) or by
 * Wirth's selection (afterwards nothing before it is larger, nothing after it smaller;
 * for even n the lower middle is the largest before it); where it optimises for size,
 * an insertion sort. The same values. */
static gs_real median_f(float *v, uint32_t n)
{
    if (n == 0) return NAN;
#if GS_SELECT_AVX2
    if (n <= 32u && gs_select_avx2()) {
        uint32_t key[32] = {0}, at = n / 2u, k = n / 2u;  /* (lanes past n are masked) */
        for (uint32_t i = 0; i < n; i++) key[i] = gs_select_float_key(v[i]);
        uint32_t hi = gs_select_rank_avx2(key, n, k, &at);
        if (n & 1u) return (gs_real)gs_select_key_float(hi);
        /* the lower middle: the largest key below hi, or hi itself when fewer than k lie below it */
        uint32_t below = 0, lo = 0;
        for (uint32_t i = 0; i < n; i++) {
            uint32_t lt = key[i] < hi;
            below += lt;
            lo = lt && key[i] > lo ? key[i] : lo;
        }
        lo = below < k ? hi : lo;
        return GS_R(0.5) * ((gs_real)gs_select_key_float(lo) + (gs_real)gs_select_key_float(hi));
    }
#endif
#ifndef __OPTIMIZE_SIZE__
    int32_t l = 0, r = (int32_t)n - 1, k = (int32_t)(n / 2);
    while (l < r) {
        float x = v[k];
        int32_t i = l, j = r;
        do {
            while (v[i] < x) i++;
            while (x < v[j]) j--;
            if (i <= j) {
                float t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++;
                j--;
            }
        } while (i <= j);
        if (j < k) l = i;
        if (k < i) r = j;
    }
    if (n & 1u) return (gs_real)v[k];
    float lo = v[0];
    for (int32_t i = 1; i < k; i++) lo = v[i] > lo ? v[i] : lo;
    return GS_R(0.5) * ((gs_real)lo + (gs_real)v[k]);
#else
    /* gs_real is float on the device: the aggregate's insertion sort, the same values */
    if (GS_REAL_IS_FLOAT) return gs_sort_median((gs_real *)(void *)v, n);
#endif
    for (uint32_t i = 1; i < n; i++) {
        float x = v[i];
        uint32_t j = i;
        while (j > 0 && v[j - 1] > x) { v[j] = v[j - 1]; j--; }
        v[j] = x;
    }
    return (n & 1u) ? (gs_real)v[n / 2] : GS_R(0.5) * ((gs_real)v[n / 2 - 1] + (gs_real)v[n / 2]);
}

static gs_real med3(gs_real a, gs_real b, gs_real c)
{
    if (GS_REAL_IS_FLOAT) return (gs_real)gs_med3_f((float)a, (float)b, (float)c);
    return (gs_real)gs_med3_d((double)a, (double)b, (double)c);
}

static void restart_levels(gs_flight *f, uint32_t i);
static NOINLINE float last_stand_size(const gs_flight *f);

/* The local times' base (gs_flight.h): examine sets it, when no close is pending */
#define LT_NEWEST 0x8000000  /* the newest sample's local time: 2^27 */
static void set_time_base(gs_flight *f)
{
    /* (before the first sample, GS_T_NONE: no sample to examine, the base goes unused) */
    f->tb_us = (int64_t)((uint64_t)f->ring->t_last_us - LT_NEWEST);
}

/* a configured span in microseconds, false when it is not within [0, GS_FLIGHT_SPAN_MAX_US] */
static bool span_cfg_us(float s, int32_t *span_us)
{
    int64_t us = gs_time_us_of_cfg_s(s);
    *span_us = (int32_t)(us & 0x7FFFFFFF);
    return us != GS_T_NONE && us <= GS_FLIGHT_SPAN_MAX_US;
}

gs_status gs_flight_init(gs_flight *f, const gs_core_config *cfg, const gs_ring *ring,
                         uint32_t *keep, bool rigid, gs_event_fn on_event, void *ctx)
{
    if (!f || !cfg || !ring || !keep || ring->capacity >= GS_FLIGHT_IDX_KEEP || !gs_cfg_is_baked(cfg)) return GS_EINVAL;
    memset(f, 0, sizeof *f);  /* (GS_FS_IDLE, no frame interval, no feet, no close pending) */
    f->cfg = cfg;
    f->ring = ring;
    f->keep = keep;
    f->rigid = rigid;
    f->on_event = on_event;
    f->ctx = ctx;
    cfg = GS_CFG_IN(cfg);
    f->g_m_s2 = gs_core_config_g(cfg);
    /* the configured spans into f's four span fields, in turn */
    static const uint8_t span_cfg[4] = {offsetof(gs_core_config, min_flight_s), offsetof(gs_core_config, max_flight_s),
                                        offsetof(gs_core_config, max_gap_s), offsetof(gs_core_config, landing_latency_s)};
    _Static_assert(offsetof(gs_flight, max_flight_us) == offsetof(gs_flight, min_flight_us) + 4 &&
                   offsetof(gs_flight, max_gap_us) == offsetof(gs_flight, min_flight_us) + 8 &&
                   offsetof(gs_flight, landing_latency_us) == offsetof(gs_flight, min_flight_us) + 12,
                   "the span fields follow each other");
    for (unsigned k = 0; k < 4; k++)
        if (!span_cfg_us(*(const float *)(const void *)((const char *)cfg + span_cfg[k]),
                         (int32_t *)(void *)((char *)f + offsetof(gs_flight, min_flight_us) + 4u * k)))
            return GS_EINVAL;
    uint64_t head = gs_ring_head(ring);
    f->base = head > GS_FLIGHT_IDX_KEEP ? head - GS_FLIGHT_IDX_KEEP : 0u;
    f->next = idx_of(f, head);
    f->quiet_from = f->next;
    f->last_t_us = GS_T_NONE;
    f->up_y = -GS_R(1.0);  /* image up (0, -1) until the body axis or a flight says otherwise */
    f->noise_px = NAN;
    restart_levels(f, GS_NO_IDX);  /* no level seen yet */
    gs_flight_forget_body(f);       /* no standing size yet */
    f->last_a_px_s2 = NAN;
    f->last_g_dir_deg = NAN;
    /* (f->feet is set up by gs_flight_use_feet, which a body's layout calls next: gs_flight.h) */
    f->last_land_us = GS_T_NONE;
    f->feet_wait_us = GS_T_NONE;
    return GS_OK;
}

void gs_flight_use_feet(gs_flight *f, float delta_rel, bool stop_touch)
{
    if (!f) return;
    if (GS_WITH_POINT) f->feet_on = true;  /* (without a point layout every object has feet: FEET_ON) */
    gs_feet_init(&f->feet, delta_rel, stop_touch);
}

#if GS_CLOSE_LAG_FRAMES > 0
static void close_finish(gs_flight *f);

/* A pending job reads the feet as they were when it began: the frames since wait with
 * their samples (out of the frame's common path). A full hold: a caller skips
 * gs_flight_update. */
static __attribute__((cold, noinline)) void feet_hold(gs_flight *f, int64_t t_us, const float x_px[GS_FEET_POINTS],
                                                      const float y_px[GS_FEET_POINTS], float size_px)
{
    if (f->feet_held_n == GS_CLOSE_LAG_FRAMES) {
        close_finish(f);  /* (no job pends after it) */
        gs_flight_feet(f, t_us, x_px, y_px, size_px);
        return;
    }
    gs_feet_frame *h = &f->feet_held[f->feet_held_n++];
    h->t_us = t_us;
    memcpy(h->x_px, x_px, sizeof h->x_px);
    memcpy(h->y_px, y_px, sizeof h->y_px);
    h->size_px = size_px;
}
#endif

void gs_flight_feet(gs_flight *f, int64_t t_us, const float x_px[GS_FEET_POINTS],
                    const float y_px[GS_FEET_POINTS], float size_px)
{
    if (!GS_WITH_POSE || !f || !FEET_ON(f)) return;
#if GS_CLOSE_LAG_FRAMES > 0
    if (f->close.stage != GS_CLOSE_NONE) {
        feet_hold(f, t_us, x_px, y_px, size_px);
        return;
    }
#endif
    /* the standing size scales the thresholds; before one is known, the frame's own */
    gs_real size = f->stand_n > 0 ? (gs_real)last_stand_size(f) : (gs_real)size_px;
    gs_feet_push(&f->feet, t_us, x_px, y_px, f->up_x, f->up_y, size);
}

/* ---- per-flight helpers ---------------------------------------------------- */

static gs_real noise_floor(const gs_flight *f)
{
    gs_real n = finite_r(f->noise_px) ? f->noise_px : GS_R(1.0);
    return n > GS_R(0.05) ? n : GS_R(0.05);
}

/* sigma of one axis from the running fit, at least the ground noise */
static gs_real fit_sigma(const gs_flight *f, const gs_fit_result *r)
{
    gs_real s = noise_floor(f);
    if (r->n >= 8 && finite_r(r->rms_px)) {
        gs_real sf = r->rms_px / GS_SQRT(GS_R(2.0)) * GS_SQRT((gs_real)r->n / (gs_real)(r->n - 3));
        if (sf > s) s = sf;
    }
    return s;
}

/* variance factor of the fitted value at t: |R^-T x|^2 with x = (1, tau, tau^2) (not finite
 * where R is singular) */
static gs_real pred_var_factor(const gs_fit *fit, int32_t dt_us)
{
    gs_real tau = gs_time_span32_s(dt_us) / fit->tscale_s;
    gs_real x0 = GS_R(1.0), x1 = tau, x2 = tau * tau;
    const gs_real *r = fit->r;  /* r00 r01 r02 r11 r12 r22 */
    gs_real z0 = x0 / r[0];
    gs_real z1 = (x1 - r[1] * z0) / r[3];
    gs_real z2 = (x2 - r[2] * z0 - r[4] * z1) / r[5];
    return z0 * z0 + z1 * z1 + z2 * z2;
}

/* Compare sample s with the fit's prediction. Returns false for a gross
 * outlier (bad keypoints: far off sideways or below the parabola); else *z is
 * the deviation against gravity in units of its standard deviation (contact
 * pushes the body above the parabola, so z grows quadratically after it). */
static bool test_sample(const gs_flight *f, const gs_fit_result *r, const gs_sample_full *s, gs_real *z)
{
    const gs_fit *fit = &f->fit;
    gs_real dt = gs_time_span32_s(near_us(s->t_us, r->t0_us));
    gs_real ax = (gs_real)r->ax_px_s2, ay = (gs_real)r->ay_px_s2, a = (gs_real)r->a_px_s2;
    gs_real px = (gs_real)r->x0_px + (gs_real)r->vx_px_s * dt + GS_R(0.5) * ax * dt * dt;
    gs_real py = (gs_real)r->y0_px + (gs_real)r->vy_px_s * dt + GS_R(0.5) * ay * dt * dt;
    gs_real ex = (gs_real)s->x_px - px, ey = (gs_real)s->y_px - py;
    gs_real gx = ax / a, gy = ay / a;
    if (!finite_r(gx) || !finite_r(gy)) { gx = (gs_real)-f->up_x; gy = (gs_real)-f->up_y; }
    gs_real up = -(ex * gx + ey * gy);
    gs_real perp = ex * (-gy) + ey * gx;
    gs_real sig = (gs_real)fit_sigma(f, r);
    gs_real vf = pred_var_factor(fit, near_us(s->t_us, fit->t0_us));
    gs_real tot = sig * GS_SQRT(GS_R(1.0) + (finite_r(vf) ? vf : GS_R(1e6)));
    *z = (gs_real)(up / tot);
    return !(GS_FABSR(perp) > GS_R(GROSS_OUTLIER) * tot || up < -GS_R(GROSS_OUTLIER) * tot);
}

/* Ring sample i when usable and no gross outlier against the fit r (its z in *z), else NULL. */
static const gs_sample_full *tested_at(const gs_flight *f, const gs_fit_result *r, uint32_t i,
                                       gs_sample_full *buf, gs_real *z)
{
    const gs_sample_full *s = usable_at(f, i, buf);
    return s && test_sample(f, r, s, z) ? s : NULL;
}

/* one-sided CUSUM of z: contact raises it, noise drains it. True: its alarm (contact) */
static NOINLINE bool cusum_step(gs_real *S, gs_real z)
{
    gs_real zc = z > CUSUM_ZMAX ? CUSUM_ZMAX : z;
    gs_real s = *S + (zc - CUSUM_K);
    *S = s > GS_R(0.0) ? s : GS_R(0.0);
    return *S > CUSUM_H && z > CUSUM_K;
}

/* typical frame interval from the history (for time-based spans), 1/16 us */
static NOINLINE uint32_t frame_dt_q4(const gs_flight *f)
{
    return f->dt_med_q4 ? f->dt_med_q4 : DT_DEFAULT_Q4;
}

/* the same in whole microseconds (at most DT_MAX_US) */
static int32_t frame_dt_us(const gs_flight *f)
{
    return (int32_t)((frame_dt_q4(f) + 8u) >> 4);
}

/* Frame steps in a span, ceil(span * per_frame / frame interval), where a span within
 * 1/64 of a step above a whole number counts as that number: sample times are whole
 * microseconds and the interval a running mean, so a span of exactly k frames comes out a
 * hair above or below k (an integer division; spans beyond 2^26 / per_frame us give
 * UINT32_MAX). */
static NOINLINE uint32_t frame_steps(const gs_flight *f, uint32_t span_us, uint32_t per_frame)
{
    if (span_us == 0) return 0;
    if (span_us > UINT32_MAX / (16u * per_frame)) return UINT32_MAX;
    uint32_t num = span_us * 16u * per_frame;
    uint32_t dt = frame_dt_q4(f), q = num / dt;
    return num - q * dt > dt / 64u ? q + 1u : q;
}

/* the frame interval follows the stream: a running mean of intervals, in 1/16 us */
static void track_frame_dt(gs_flight *f, int64_t dt_us)
{
    if (dt_us <= 0) return;
    int32_t dt_q4 = (int32_t)((dt_us < DT_MAX_US ? dt_us : DT_MAX_US) * 16);
    if (f->dt_med_q4 == 0) f->dt_med_q4 = (uint32_t)dt_q4;
    else if ((uint32_t)dt_q4 < 3u * f->dt_med_q4)
        f->dt_med_q4 = (uint32_t)((int32_t)f->dt_med_q4 + (dt_q4 - (int32_t)f->dt_med_q4) / 20);  /* 0.05 */
}

static gs_real stand_size(const gs_flight *f, gs_real *se_out);
static float last_stand_size(const gs_flight *f);
/* a rigid object (the point layout): always, where no skeleton layout is built in
 * (gs_features.h), so the standing tracker is left out of such builds */
#define IS_RIGID(f) (!GS_WITH_POSE || (GS_WITH_POINT && (f)->rigid))

/* Could this fit be free fall? Acceleration roughly along the expected gravity
 * direction, and of a size that makes the object's size plausible (loosely:
 * this gates candidates, the final checks are stricter). */
static bool plausible_fall(const gs_flight *f, const gs_fit_result *r, gs_real size_px)
{
    if (!(r->a_px_s2 > GS_R(0.0))) return false;
    /* a fit of few noisy samples gets the benefit of two standard errors */
    gs_real rel_se = (finite_r(r->a_se_px_s2) && r->a_se_px_s2 > GS_R(0.0)) ? r->a_se_px_s2 / r->a_px_s2 : GS_R(0.0);
    gs_real cosang = -(r->ax_px_s2 * f->up_x + r->ay_px_s2 * f->up_y) / r->a_px_s2;
    gs_real max_ang = f->up_from_flight ? GS_R(25.0) : (f->up_n > 0 ? GS_R(40.0) : GS_R(60.0));
    max_ang += GS_R(2.0) * rel_se * GS_R(180.0) / GS_PI;
    if (max_ang > GS_R(80.0)) max_ang = GS_R(80.0);
    /* a threshold: single precision is plenty where double is emulated */
    if (!(cosang > (gs_real)GS_COS(max_ang * GS_PI / GS_R(180.0)))) return false;
    gs_real a_hi = r->a_px_s2 + GS_R(2.0) * rel_se * r->a_px_s2, a_lo = r->a_px_s2 - GS_R(2.0) * rel_se * r->a_px_s2;
    gs_real a_min = -(gs_real)INFINITY, a_max = (gs_real)INFINITY;  /* no size, no flight yet: any */
    /* (size_px is NaN or a median of measured sizes, within their range: in float it is
     * positive and finite exactly where it is so in gs_real) */
    if (size_ok((float)size_px)) {
        /* the size this acceleration implies, h = size g / a, within the plausible range */
        a_min = size_px * f->g_m_s2 / ((gs_real)CFG(f)->size_max_m * EMIT_FACTOR);
        a_max = size_px * f->g_m_s2 / ((gs_real)CFG(f)->size_min_m / EMIT_FACTOR);
    } else if (finite_r(f->last_a_px_s2)) {
        a_min = f->last_a_px_s2 / EMIT_FACTOR;
        a_max = f->last_a_px_s2 * EMIT_FACTOR;
    }
    return !(a_hi < a_min || a_lo > a_max);
}

/* the object's size in px for gating: standing stature, or the rigid object's latest size */
static gs_real gate_size(const gs_flight *f, uint32_t idx)
{
    if (IS_RIGID(f)) {
        gs_sample_full s_b;
        const gs_sample_full *s = at(f, idx, &s_b);
        /* (a size of 0 gates as an unknown one: plausible_fall needs it positive) */
        return s && size_ok(s->size_px) ? (gs_real)s->size_px : NAN;
    }
#ifndef __OPTIMIZE_SIZE__
    {
        /* stand_size without the standard error it would compute and drop here */
        float tmp[GS_STAND_KEEP];
        const float *v = f->stand_n >= 3 ? f->stand_size : f->loose_size;
        uint32_t n = f->stand_n >= 3 ? f->stand_n : f->loose_n;
        if (n < 3) return NAN;
        if (n > GS_STAND_KEEP) n = GS_STAND_KEEP;
        memcpy(tmp, v, n * sizeof tmp[0]);
        return median_f(tmp, n);
    }
#else
    gs_real se;
    return stand_size(f, &se);
#endif
}

/* the fit's apex: where its velocity along its own gravity is zero, seconds after its t0 */
static gs_real fit_apex_s(const gs_fit_result *r)
{
    gs_real gx = r->ax_px_s2 / r->a_px_s2, gy = r->ay_px_s2 / r->a_px_s2;
    gs_real v_down = r->vx_px_s * gx + r->vy_px_s * gy;
    return -v_down / r->a_px_s2;  /* after the fit's t0 */
}

/* ... as a time (GS_T_NONE unknown) */
static int64_t fit_apex_us(const gs_fit_result *r)
{
    return gs_time_add_s(r->t0_us, fit_apex_s(r));
}

/* the fit's height at t along its own up (against its acceleration), px */
static gs_real fit_u_at(const gs_fit_result *r, int64_t t_us)
{
    gs_real dt = gs_time_span_s(t_us, r->t0_us);
    gs_real x = r->x0_px + r->vx_px_s * dt + GS_R(0.5) * r->ax_px_s2 * dt * dt;
    gs_real y = r->y0_px + r->vy_px_s * dt + GS_R(0.5) * r->ay_px_s2 * dt * dt;
    return -(x * r->ax_px_s2 + y * r->ay_px_s2) / r->a_px_s2;
}

/* Gravity is one per camera: the fitted direction must agree with the one known (the
 * standing body's axis, earlier flights) within its standard error; true when none is known. */
static bool gravity_agrees(const gs_flight *f, const gs_fit_result *r)
{
    if (!f->up_from_flight && f->up_n == 0) return true;
    gs_real cosang = -(r->ax_px_s2 * f->up_x + r->ay_px_s2 * f->up_y) / r->a_px_s2;
    gs_real lim = GRAV_DIR_SE_K * r->a_se_px_s2 / r->a_px_s2 + GRAV_DIR_MIN_DEG * GS_PI / GS_R(180.0);
    if (!(lim < GS_R(1.5))) return !(lim == lim) ? false : true;  /* SE unknown: no; SE huge: no test */
    return cosang >= (gs_real)GS_COS(lim);
}

/* A few frames' flight the feet did not time, of a body travelling across the image: a
 * running stride, whose limbs swing in depth at speed, so its keypoint COM is no ballistic
 * body's (a jump in place drifts a few cm/s; a stride travels metres a second) */
static bool running_stride(const gs_flight *f, const gs_fit_result *r, uint32_t n, bool feet, gs_real size_px)
{
    if (IS_RIGID(f) || feet || n >= 2u * CFG(f)->min_samples) return false;
    gs_real gx = r->ax_px_s2 / r->a_px_s2, gy = r->ay_px_s2 / r->a_px_s2;
    gs_real v_across = GS_FABSR(r->vx_px_s * gy - r->vy_px_s * gx);  /* perpendicular to gravity */
    return v_across > STRIDE_REL * size_px;
}

/* sample s into the running fit */
static NOINLINE void fit_add(gs_flight *f, const gs_sample_full *s)
{
    gs_fit_add(&f->fit, s->t_us, s->x_px, s->y_px, s->w);
}

/* the oldest sample a flight may reach back to: held, and after the last closed candidate */
static NOINLINE uint32_t history_floor(const gs_flight *f)
{
    uint32_t oldest = oldest_idx(f);
    return f->quiet_from > oldest ? f->quiet_from : oldest;
}

/* A decision (a landing and its close, a seed's core, an alarm's refit) begins: the memo
 * (gs_flight.h) forgets the fits of the one before. */
static void memo_forget(gs_flight *f)
{
#if GS_CLOSE_LAG_FRAMES > 0
    f->memo.valid = false;
#else
    (void)f;
#endif
}

/* gs_fit_robust of ring samples [first, first+count) into f->keep; with a lag, once per
 * decision: the same window fitted again gets its result, and f->keep still holds its
 * flags (every robust fit in between goes through the memo) */
static NOINLINE gs_status robust_fit(gs_flight *f, uint32_t first, uint32_t count, gs_fit_method method,
                            float min_scale, gs_fit_result *r)
{
#if GS_CLOSE_LAG_FRAMES == 0
    /* no lag (the Cortex-M4 build): a close runs whole in one call, and a window it fits
     * twice is fitted twice, the time paid for no memo in RAM or code */
    return gs_fit_robust(f->ring, ring_idx(f, first), count, method, min_scale, f->keep, r);
#else
    gs_fit_memo *m = &f->memo;
    if (m->valid && m->first == first && m->count == count && m->method == method && m->min_scale == min_scale) {
        *r = m->r;
        return m->st;
    }
    m->st = gs_fit_robust(f->ring, ring_idx(f, first), count, method, min_scale, f->keep, r);
    m->first = first;
    m->count = count;
    m->method = method;
    m->min_scale = min_scale;
    m->r = *r;
    m->valid = true;
    return m->st;
#endif
}

/* Rebuild the running fit robustly from the ring samples [lo, hi]; *r: its solution
 * when true (scratch otherwise). */
static bool refit_range(gs_flight *f, uint32_t lo, uint32_t hi, gs_fit_result *r)
{
    /* (every caller's hi is an examined sample, below the head: the ring holding one
     * range [oldest, head), hi > lo is held where lo is) */
    int32_t t_lo = lt_at(f, lo), t_hi = lt_at(f, hi);
    if (t_lo == GS_LT_NONE || hi <= lo) return false;
    uint32_t count = (uint32_t)(hi - lo + 1);
    float min_scale = (float)noise_floor(f);  /* Tukey scale never below the noise: only gross outliers lose weight */
    if (robust_fit(f, lo, count, GS_FIT_IRLS, min_scale, r) != GS_OK)
        return false;
    int32_t tspan = t_hi - t_lo;  /* (two held samples) */
    gs_fit_init(&f->fit, abs_of(f, t_lo + tspan / 2), tspan > 0 ? tspan : frame_dt_us(f));
    for (uint32_t i = lo; i <= hi; i++) {
        gs_sample_full s_b;
        const gs_sample_full *s = usable_at(f, i, &s_b);
        if (s && gs_fit_kept(f->keep, (uint32_t)(i - lo))) fit_add(f, s);
    }
    return gs_fit_solve(&f->fit, r) == GS_OK;
}

/* A CUSUM alarm from a fit of few samples can be the fit's fault. Refit [lo, hi] through
 * the alarm, at its edge on the side (+1: hi, -1: lo): if the samples at the edge then sit
 * on the parabola, it was a false alarm (true contact deviates by far more than a refit can
 * absorb). */
static bool alarm_is_false(gs_flight *f, uint32_t lo, uint32_t hi, int side)
{
    gs_fit_result r;
    if (!refit_range(f, lo, hi, &r)) return false;
    /* a refit that only fits with a residual far above the noise proves nothing */
    if (r.rms_px / GS_SQRT(GS_R(2.0)) > VERIFY_RMS * noise_floor(f)) return false;
    uint32_t checked = 0;
    uint32_t stop = side > 0 ? lo : hi;  /* walking inward from the edge */
    for (uint32_t i = side > 0 ? hi : lo, k = 0; k < 4 && checked < 2; k++) {
        gs_sample_full s_b;
        gs_real z;
        if (tested_at(f, &r, i, &s_b, &z)) {
            if (z > VERIFY_Z) return false;
            checked++;
        }
        if (i == stop) break;
        i = side > 0 ? i - 1 : i + 1;
    }
    return checked == 2;
}

static bool seed_core_width(gs_flight *f, uint32_t apex, uint32_t newest, int64_t half_us)
{
    uint32_t half = frame_steps(f, half_us, 1);
    if (half < 2) half = 2;
    uint32_t floor_idx = history_floor(f);
    uint32_t lo = apex > floor_idx + half ? apex - half : floor_idx;
    uint32_t hi = apex + half < newest ? apex + half : newest;
    /* need at least 5 usable samples: widen when frames are missing */
    for (int widen = 0; widen < 8; widen++) {
        if (count_usable(f, lo, hi) >= 5) break;
        if (lo > floor_idx) lo--;
        if (hi < newest) hi++;
    }
    gs_fit_result r;
    memo_forget(f);
    if (!refit_range(f, lo, hi, &r)) return false;
    uint32_t n_usable = count_usable(f, lo, hi);
    /* a core the robust fit had to cut down to a few samples is not a curve yet */
    bool enough = r.n >= 5 && 4u * r.n >= 3u * n_usable;
    if (!enough || !plausible_fall(f, &r, gate_size(f, apex))) {
        DBG("seed at %llu (half %lld us) rejected: a=%.1f se=%.1f dir=%.1f\n", (unsigned long long)apex, (long long)half_us, r.a_px_s2, r.a_se_px_s2, r.g_dir_deg);
        return false;
    }
    f->fl_first = lo;
    f->fl_last = hi;
    f->seed_idx = apex;
    f->cusum = GS_R(0.0);
    f->pend_ok = 0;
    f->outliers_run = 0;
    return true;
}

/* the seed's core half-widths, tried in turn: wider when noise hides the curve */
static const int32_t seed_half_us[] = {CORE_HALF_US, CORE_HALF_US * 145 / 100, CORE_HALF_US * 19 / 10};
#define SEED_WIDTHS (sizeof seed_half_us / sizeof seed_half_us[0])

/* Seed a flight at an apex: fit a core around it, wider when noise hides the curve. */
static bool seed_core(gs_flight *f, uint32_t apex, uint32_t newest)
{
    for (unsigned k = 0; k < SEED_WIDTHS; k++)
        if (seed_core_width(f, apex, newest, seed_half_us[k])) return true;
    return false;
}

/* ---- boundary refinement with a piecewise model (1D, along up) ------------- */

/* Solve the k x k (k <= 4) symmetric system A c = b by Cholesky; false if not PD. */
static bool solve_spd(gs_real A[4][4], gs_real b[4], int k, gs_real c[4])
{
    /* a pivot below this fraction of its diagonal: not positive definite at this precision */
    const gs_real tiny = sizeof(gs_real) < sizeof(double) ? GS_R(1e-6) : GS_R(1e-12);
    gs_real L[4][4];  /* each entry is written before it is read */
    for (int i = 0; i < k; i++) {
        for (int j = 0; j <= i; j++) {
            gs_real s = A[i][j];
            for (int m = 0; m < j; m++) s -= L[i][m] * L[j][m];
            if (i == j) {
                if (!(s > tiny * (A[i][i] > 0 ? A[i][i] : GS_R(1.0)))) return false;
                L[i][i] = GS_SQRT(s);
            } else {
                L[i][j] = s / L[j][j];
            }
        }
    }
    gs_real y[4];
    for (int i = 0; i < k; i++) {
        gs_real s = b[i];
        for (int m = 0; m < i; m++) s -= L[i][m] * y[m];
        y[i] = s / L[i][i];
    }
    for (int i = k - 1; i >= 0; i--) {
        gs_real s = y[i];
        for (int m = i + 1; m < k; m++) s -= L[m][i] * c[m];
        c[i] = s / L[i][i];
    }
    return true;
}

/* the SSR left after the least-squares solution c of k unknowns: yy - c.b, at least 0 */
static gs_real ssr_left(gs_real yy, const gs_real c[4], const gs_real b[4], int k)
{
    gs_real ssr = yy;
    for (int m = 0; m < k; m++) ssr -= c[m] * b[m];
    return ssr > GS_R(0.0) ? ssr : GS_R(0.0);
}

/* The SSR of the piecewise model from its normal equations A c = b (unknowns: the parabola's
 * three and the contact term's alpha, in tau units), alpha held within [c3_min, c3_max]. */
static gs_real pw_ssr_solve(gs_real A[4][4], gs_real b[4], gs_real yy, gs_real c3_min, gs_real c3_max)
{
    gs_real c[4];
    bool solved = A[3][3] > GS_R(0.0) && solve_spd(A, b, 4, c);
    if (solved && c[3] >= c3_min && c[3] <= c3_max) return ssr_left(yy, c, b, 4);
    /* alpha at a bound: fit the parabola to u - alpha h */
    gs_real al = A[3][3] > GS_R(0.0) ? ((solved && c[3] > c3_max) ? c3_max : c3_min) : GS_R(0.0);
    gs_real b3[4];
    for (int k = 0; k < 3; k++) b3[k] = b[k] - al * A[k][3];
    gs_real yy3 = yy - GS_R(2.0) * al * b[3] + al * al * A[3][3];
    if (!solve_spd(A, b3, 3, c)) return INFINITY;
    return ssr_left(yy3, c, b3, 3);
}

#ifndef __OPTIMIZE_SIZE__
/* Hosts: solve_spd in two steps, so that the leading 3 x 3 rows of the factor, which the
 * boundary's grid points share, are taken once (the same arithmetic in the same order). */
/* Rows [i0, k) of the Cholesky factor L of the k x k (k <= 4) symmetric A; false if not PD. */
static bool chol_rows(gs_real A[4][4], gs_real L[4][4], int i0, int k)
{
    const gs_real tiny = sizeof(gs_real) < sizeof(double) ? GS_R(1e-6) : GS_R(1e-12);  /* as solve_spd */
    for (int i = i0; i < k; i++) {
        for (int j = 0; j <= i; j++) {
            gs_real s = A[i][j];
            for (int m = 0; m < j; m++) s -= L[i][m] * L[j][m];
            if (i == j) {
                if (!(s > tiny * (A[i][i] > 0 ? A[i][i] : GS_R(1.0)))) return false;
                L[i][i] = GS_SQRT(s);
            } else {
                L[i][j] = s / L[j][j];
            }
        }
    }
    return true;
}

/* Solve L L^T c = b for the k x k factor L (solve_spd's substitutions). */
static void chol_solve(gs_real L[4][4], const gs_real b[4], int k, gs_real c[4])
{
    gs_real y[4];
    for (int i = 0; i < k; i++) {
        gs_real s = b[i];
        for (int m = 0; m < i; m++) s -= L[i][m] * y[m];
        y[i] = s / L[i][i];
    }
    for (int i = k - 1; i >= 0; i--) {
        gs_real s = y[i];
        for (int m = i + 1; m < k; m++) s -= L[m][i] * c[m];
        c[i] = s / L[i][i];
    }
}

/* pw_ssr_solve with L's first three rows given (l3: A's leading 3 x 3 is PD) */
static gs_real pw_ssr_solve_l3(gs_real A[4][4], gs_real b[4], gs_real yy, gs_real c3_min, gs_real c3_max,
                               gs_real L[4][4], bool l3)
{
    gs_real c[4];
    bool solved = A[3][3] > GS_R(0.0) && l3 && chol_rows(A, L, 3, 4);
    if (solved) chol_solve(L, b, 4, c);
    if (solved && c[3] >= c3_min && c[3] <= c3_max) return ssr_left(yy, c, b, 4);
    gs_real al = A[3][3] > GS_R(0.0) ? ((solved && c[3] > c3_max) ? c3_max : c3_min) : GS_R(0.0);
    gs_real b3[4];
    for (int k = 0; k < 3; k++) b3[k] = b[k] - al * A[k][3];
    gs_real yy3 = yy - GS_R(2.0) * al * b[3] + al * al * A[3][3];
    if (!l3) return INFINITY;
    chol_solve(L, b3, 3, c);
    return ssr_left(yy3, c, b3, 3);
}
#endif

/* Weighted SSR of u over samples [lo, hi] under parabola + alpha/2 (T - t)^2 for t < T
 * (side < 0, take-off) or alpha/2 (t - T)^2 for t > T (side > 0, landing). Contact is
 * a real force, so alpha >= alpha_min_px (half of g in the image): otherwise a
 * boundary placed inside the flight could absorb flight samples for free. */
static gs_real piecewise_ssr(const gs_flight *f, uint32_t lo, uint32_t hi, int32_t t_lo, int32_t t_hi,
                            int32_t T, int side, gs_real alpha_min_px, gs_real alpha_max_px,
                            const gs_fit_result *r)
{
    /* called per boundary candidate and sample: gs_real. In float, u is taken about
     * the first sample's (the SSR below is yy - c.b, which cancels), in gs_real as is */
    struct { gs_real A[4][4], b[4]; } ne = {0};  /* the normal equations A c = b, zeroed at once */
    gs_real yy = GS_R(0.0);
    gs_real u_c = GS_R(0.0);
    bool have_c = sizeof(gs_real) == sizeof(double);
    /* tau in [-1, 1] over [t_lo, t_hi]: centre tc, half-width ts */
    gs_real ts = GS_R(0.5) * gs_time_span32_s(t_hi - t_lo);
    gs_real ts2 = ts * ts;
    for (uint32_t i = lo; i <= hi; i++) {
        gs_sample_full s_b;
        gs_real z;
        const gs_sample_full *s = tested_at(f, r, i, &s_b, &z);
        if (!s) continue;  /* gross outliers out */
        gs_real w = (gs_real)s->w;
        /* ((t - t_lo) - (t_hi - t)) / (t_hi - t_lo): exact integer spans in (all within [t_lo, t_hi]) */
        int32_t t = lt_of(f, s->t_us);
        gs_real tau = gs_time_span32_s((t - t_lo) - (t_hi - t)) / (ts + ts);
        gs_real d = past_s(t, T, side);
        gs_real h = d > GS_R(0.0) ? GS_R(0.5) * d * d / ts2 : GS_R(0.0);
        gs_real x[4] = {GS_R(1.0), tau, tau * tau, h};
        gs_real u = (gs_real)u_of(f, s);
        if (!have_c) { u_c = u; have_c = true; }
        u -= u_c;
        for (int k = 0; k < 4; k++) {
            ne.b[k] += w * x[k] * u;
            for (int m = 0; m < 4; m++) ne.A[k][m] += w * x[k] * x[m];
        }
        yy += w * u * u;
    }
    return pw_ssr_solve(ne.A, ne.b, yy, alpha_min_px * ts2, alpha_max_px * ts2);  /* alpha in tau units */
}

#ifndef __OPTIMIZE_SIZE__
/* Hosts: the sums of piecewise_ssr that do not depend on T, taken once per boundary. Only
 * the contact column (h) changes with T, and h is zero short of T, so each grid point adds
 * the column over the few samples past it, in sample order: the same sums bit for bit
 * (an added zero leaves a sum as it is). The firmware's code budget is full: it sums anew. */
#define PW_CACHE 64  /* samples past some grid point (contact samples and the search's reach inside) */
typedef struct {
    int32_t t_lus;
    gs_real w, x[3], u;
} pw_sample;
typedef struct {
    gs_real A[3][3], b[3], yy, ts2;
    uint32_t n;
    bool l3;
    gs_real L[4][4];  /* rows 0-2: the Cholesky factor of A, when l3 (row 3: each grid point's) */
    pw_sample s[PW_CACHE];
} pw_sums;

/* pw's T-independent sums over [lo, hi]; false when more than PW_CACHE samples lie past
 * T_reach (the grid point reaching furthest into the flight) */
static bool pw_prepare(const gs_flight *f, uint32_t lo, uint32_t hi, int32_t t_lo, int32_t t_hi,
                       int32_t T_reach, int side, const gs_fit_result *r, pw_sums *P)
{
    memset(P, 0, offsetof(pw_sums, L));
    gs_real u_c = GS_R(0.0);
    bool have_c = sizeof(gs_real) == sizeof(double);
    gs_real ts = GS_R(0.5) * gs_time_span32_s(t_hi - t_lo);
    P->ts2 = ts * ts;
    for (uint32_t i = lo; i <= hi; i++) {
        gs_sample_full s_b;
        gs_real z;
        const gs_sample_full *s = tested_at(f, r, i, &s_b, &z);
        if (!s) continue;
        gs_real w = (gs_real)s->w;
        int32_t t = lt_of(f, s->t_us);
        gs_real tau = gs_time_span32_s((t - t_lo) - (t_hi - t)) / (ts + ts);
        gs_real x[3] = {GS_R(1.0), tau, tau * tau};
        gs_real u = (gs_real)u_of(f, s);
        if (!have_c) { u_c = u; have_c = true; }
        u -= u_c;
        for (int k = 0; k < 3; k++) {
            P->b[k] += w * x[k] * u;
            for (int m = 0; m < 3; m++) P->A[k][m] += w * x[k] * x[m];
        }
        P->yy += w * u * u;
        if (beyond(t, T_reach, side)) {
            if (P->n == PW_CACHE) return false;
            pw_sample *c = &P->s[P->n++];
            c->t_lus = t;
            c->w = w;
            memcpy(c->x, x, sizeof x);
            c->u = u;
        }
    }
    gs_real A4[4][4] = {{0}};
    for (int k = 0; k < 3; k++)
        for (int m = 0; m < 3; m++) A4[k][m] = P->A[k][m];
    P->l3 = chol_rows(A4, P->L, 0, 3);
    return true;
}

/* piecewise_ssr at T from the prepared sums */
static gs_real pw_ssr_at(pw_sums *P, int32_t T, int side, gs_real alpha_min_px, gs_real alpha_max_px)
{
    gs_real A[4][4] = {{0}}, b[4] = {0};
    for (int k = 0; k < 3; k++) {
        b[k] = P->b[k];
        for (int m = 0; m < 3; m++) A[k][m] = P->A[k][m];
    }
    for (uint32_t j = 0; j < P->n; j++) {
        const pw_sample *c = &P->s[j];
        gs_real d = past_s(c->t_lus, T, side);
        if (!(d > GS_R(0.0))) continue;  /* h = 0 */
        gs_real w = c->w, h = GS_R(0.5) * d * d / P->ts2;
        gs_real x[4] = {c->x[0], c->x[1], c->x[2], h};
        b[3] += w * h * c->u;
        for (int k = 0; k < 3; k++) {
            A[k][3] += w * x[k] * h;
            A[3][k] += w * h * x[k];
        }
        A[3][3] += w * h * h;
    }
    return pw_ssr_solve_l3(A, b, P->yy, alpha_min_px * P->ts2, alpha_max_px * P->ts2, P->L, P->l3);
}
#endif

/* Find the boundary time on one side by grid search. [lo, hi]: flight plus contact samples,
 * the outermost contact sample at the side's end (lo: take-off, hi: landing); edge_in: the
 * grown flight's edge. */
static int32_t refine_boundary(const gs_flight *f, uint32_t lo, uint32_t hi, int side,
                               uint32_t edge_in, gs_real penalty, const gs_fit_result *r)
{
    gs_real alpha_min_px = CONTACT_MIN_G * r->a_px_s2;
    gs_real alpha_max_px = (side < 0 ? TAKEOFF_MAX_G : LANDING_MAX_G) * r->a_px_s2;
    /* all held: the contact samples were tested, the flight lies between them and the newest */
    int32_t t_lo = lt_at(f, lo), t_hi = lt_at(f, hi), t_in = lt_at(f, edge_in);
    if (t_hi <= t_lo) return GS_LT_NONE;
    /* search between the outermost contact sample and a little inside the flight: the grid
     * reaches at most a frame interval (2^26 us) beyond the held samples, and spans it less
     * than 2^31 + 2^26 us (unsigned) */
    int32_t dt = frame_dt_us(f);
    int32_t inside = BOUNDARY_IN_US > dt ? BOUNDARY_IN_US : dt;
    int32_t t_edge = t_in + (side < 0 ? inside : -inside);
    int32_t t_from = side < 0 ? t_lo : t_edge, t_to = side < 0 ? t_edge : t_hi;
    uint32_t span_us = (uint32_t)t_to - (uint32_t)t_from;
    uint32_t n_steps = frame_steps(f, span_us, BOUNDARY_STEPS);
    int steps = n_steps < 1 ? 1 : n_steps > 400 ? 400 : (int)n_steps;
    gs_real span_s = gs_time_span_s(span_us, 0);
    gs_real best = INFINITY;
    int32_t best_T = GS_LT_NONE;
#ifndef __OPTIMIZE_SIZE__
    pw_sums P;
    int32_t T_reach = GS_LT_NONE;  /* the grid point furthest toward the flight */
    for (int k = 0; k <= steps; k++) {
        int64_t off_us = gs_time_add_s(0, span_s * (gs_real)k / (gs_real)steps);
        if (off_us == GS_T_NONE) { T_reach = GS_LT_NONE; break; }  /* (no grid: the sums anew) */
        int32_t T = (int32_t)((uint32_t)t_from + (uint32_t)off_us);
        if (k == 0 || beyond(T_reach, T, side)) T_reach = T;
    }
    bool prepared = T_reach != GS_LT_NONE && pw_prepare(f, lo, hi, t_lo, t_hi, T_reach, side, r, &P);
#endif
    for (int k = 0; k <= steps; k++) {
        /* t_from + the offset: its value lies within the local range (see above) */
        int32_t T = (int32_t)((uint32_t)t_from + (uint32_t)gs_time_add_s(0, span_s * (gs_real)k / (gs_real)steps));
#ifndef __OPTIMIZE_SIZE__
        gs_real ssr = prepared ? pw_ssr_at(&P, T, side, alpha_min_px, alpha_max_px)
                               : piecewise_ssr(f, lo, hi, t_lo, t_hi, T, side, alpha_min_px, alpha_max_px, r);
#else
        gs_real ssr = piecewise_ssr(f, lo, hi, t_lo, t_hi, T, side, alpha_min_px, alpha_max_px, r);
#endif
        /* dropping samples the online test took as flight must pay for itself */
        if (beyond(t_in, T, side)) ssr += penalty;
        if (ssr < best - GS_R(1e-12)) { best = ssr; best_T = T; }
    }
    return best_T;
}

/* ---- closing a candidate ---------------------------------------------------- */

/* median of n <= MEDIAN_MAX values and its standard error (from the MAD) */
_Static_assert(GS_STAND_KEEP <= MEDIAN_MAX, "the kept standing sizes fit a median's set");
static gs_real median_se(const float *v, uint32_t n, gs_real *se_out)
{
    float tmp[MEDIAN_MAX], dev[MEDIAN_MAX];
    memcpy(tmp, v, n * sizeof tmp[0]);
    gs_real med = median_f(tmp, n);
    if (n >= 2) {
        for (uint32_t i = 0; i < n; i++) dev[i] = (float)GS_FABSR((gs_real)tmp[i] - med);
        *se_out = GS_R(1.2533) * median_f(dev, n) * GS_R(1.4826) / GS_SQRT((gs_real)n);
    } else {
        *se_out = NAN;
    }
    return med;
}

/* standing size: settled upright frames, else (no stance seen yet) still frames that are
 * roughly upright */
static gs_real stand_size(const gs_flight *f, gs_real *se_out)
{
    if (f->stand_n >= 3) return median_se(f->stand_size, f->stand_n, se_out);
    if (f->loose_n >= 3) return median_se(f->loose_size, f->loose_n, se_out);
    *se_out = NAN;
    return NAN;
}

static gs_real rigid_size(const gs_flight *f, uint32_t lo, uint32_t hi, gs_real *se_out)
{
    float v[MEDIAN_MAX];
    uint32_t n = 0;
    uint32_t step = (hi - lo + MEDIAN_MAX) / MEDIAN_MAX;
    for (uint32_t i = lo; i <= hi && n < MEDIAN_MAX; i += step) {
        gs_sample_full s_b;
        const gs_sample_full *s = at(f, i, &s_b);
        if (s && size_ok(s->size_px)) v[n++] = s->size_px;
    }
    return median_se(v, n, se_out);
}

#define WALK_FREE 16  /* samples a step may walk toward the take-off and still refit at an alarm */
#define CLOSE_LAG_US 60000  /* a close spread over frames ends this soon after its landing's frame */

/* Grow the flight backwards in time from the core with the same CUSUM test.
 * Every sample but gross outliers enters the running fit (so a biased early
 * fit corrects itself); the flight's edge is the last sample after which the
 * CUSUM was back at zero, and the fit is rebuilt over the clean range at the end
 * (GS_CLOSE_GROWN). all: walk to the end; else stop after an alarm's refit, or before
 * one once the walk took WALK_FREE samples. True when it ran a refit or stopped for one. */
static uint8_t grow_left_step(gs_flight *f, gs_close *c, bool all, bool *spent)
{
    uint32_t floor_idx = history_floor(f);
    int32_t t_seed = lt_at(f, f->seed_idx);
    uint32_t walked = 0;
#if GS_CLOSE_LAG_FRAMES > 0
    bool due = c->alarm_due;  /* the walk stopped at an alarm: its refit first */
    c->alarm_due = false;
#else
    bool due = false;
#endif
    for (;;) {
        if (!due) {
            if (c->walk_i <= floor_idx) break;
            uint32_t i = --c->walk_i;
            gs_sample_full s_b;
            const gs_sample_full *s = at(f, i, &s_b);
            if (!s) break;
            if (!usable(s)) continue;
            int32_t t = lt_of(f, s->t_us);
            if (span_over(c->t_prev_lus, t, f->max_gap_us)) break;
            if (span_over(t_seed, t, f->max_flight_us)) break;
            c->t_prev_lus = t;
            walked++;
            gs_real z;
            if (!test_sample(f, &c->r, s, &z)) {
                if (++c->outliers > 2) break;
                continue;
            }
            c->outliers = 0;
            if (!cusum_step(&c->cusum, z)) {
                fit_add(f, s);
                gs_fit_solve(&f->fit, &c->r);
                if (c->cusum == GS_R(0.0)) c->clean = i;
                continue;
            }
#if GS_CLOSE_LAG_FRAMES > 0
            if (!all && walked > WALK_FREE) {  /* its refit in the next step */
                c->alarm_due = true;
                *spent = true;
                return GS_CLOSE_GROW;
            }
#endif
        }
        due = false;
        /* contact at walk_i, or a refit through it shows a false alarm */
        uint32_t i = c->walk_i;
        *spent = true;
        if (!alarm_is_false(f, i, f->fl_last, -1)) {
            c->left_alarm = i;
            return GS_CLOSE_GROWN;
        }
        c->clean = i;
        f->fl_first = i;
        c->cusum = GS_R(0.0);
        gs_fit_solve(&f->fit, &c->r);
        if (!all) return GS_CLOSE_GROW;
    }
    return c->clean != f->fl_first ? GS_CLOSE_GROWN : GS_CLOSE_BOUNDS;
}

/* Contact samples past the flight edge (side -1: before take-off, +1: after
 * landing) for the boundary model: consecutive usable samples while their
 * deviation against gravity keeps growing, as under a constant contact force
 * (after an impact the body soon stops following it). Returns how many;
 * *outer = the outermost, *first = the nearest. */
static uint32_t contact_run(const gs_flight *f, const gs_fit_result *r, uint32_t edge, int side,
                            uint32_t head, uint32_t *outer, uint32_t *first)
{
    uint32_t floor_idx = history_floor(f);
    uint32_t n = 0;
    gs_real z_prev = -INFINITY;
    uint32_t i = edge;
    *outer = edge;
    *first = edge;
    while (n < CONTACT_SAMPLES_MAX) {
        if (side < 0) { if (i <= floor_idx) break; i--; }
        else { if (i + 1 >= head) break; i++; }
        gs_sample_full s_b;
        gs_real z;
        if (!tested_at(f, r, i, &s_b, &z)) continue;  /* a glitch: look past it */
        if (n > 0 && !(z > z_prev)) break;
        if (n == 0) *first = i;
        *outer = i;
        z_prev = z;
        n++;
    }
    return n;
}

/* The boundary time on one side (GS_T_NONE: unknown) from the flight's edge and the contact
 * samples past it (those end where contact was detected, alarm: further out the ground
 * phase is no longer a constant force); *outer = the outermost contact sample. */
static int32_t boundary_time(const gs_flight *f, const gs_close *c, int side, bool refine, uint32_t *outer)
{
    const gs_fit_result *r = &c->r;
    uint32_t edge = side < 0 ? f->fl_first : f->fl_last, other_edge = side < 0 ? f->fl_last : f->fl_first;
    bool alarm = (side < 0 ? c->left_alarm : c->right_alarm) != GS_NO_IDX;
    uint32_t first = edge;  /* the first contact sample */
    *outer = edge;
    if (!refine) return GS_LT_NONE;
    uint32_t n = alarm ? contact_run(f, r, edge, side, c->head, outer, &first) : 0;
    /* two or more contact samples with a growing deviation: a constant-force model
     * past the boundary gives a sub-frame time; one: the midpoint is all we know */
    if (n >= 2) {
        gs_real sig = fit_sigma(f, r);
        return refine_boundary(f, side < 0 ? *outer : other_edge, side < 0 ? other_edge : *outer,
                               side, edge, DROP_PENALTY * sig * sig, r);
    }
    if (n == 1) {
        int32_t t_first = lt_at(f, first), t_edge = lt_at(f, edge);  /* both held: L is */
        return t_edge + (t_first - t_edge) / 2;
    }
    return GS_LT_NONE;
}

/* Is sample i inside the flight on this side: short of the boundary time T or, T unknown,
 * not beyond the grown edge? (false when not held) */
static bool inside_edge(const gs_flight *f, uint32_t i, int32_t T, int side, uint32_t edge)
{
    int32_t t = lt_at(f, i);
    if (t == GS_LT_NONE) return false;
    if (T == GS_LT_NONE) return side < 0 ? i >= edge : i <= edge;
    return beyond(T, t, side);
}

/* The flight's outermost sample on one side: from `from` step toward `to` (inward)
 * until a sample is inside the flight (inside_edge) or `to` is reached. */
static uint32_t trim_edge(const gs_flight *f, uint32_t from, uint32_t to, int32_t T, int side,
                          uint32_t edge)
{
    uint32_t i = from;
    while (i != to && !inside_edge(f, i, T, side, edge)) i = side < 0 ? i + 1 : i - 1;
    return i;
}

/* image up := (ux, uy) normalised; false (unchanged) for a zero or NaN direction */
static NOINLINE bool set_up(gs_flight *f, gs_real ux, gs_real uy)
{
    gs_real nrm = GS_SQRT(ux * ux + uy * uy);
    if (!(nrm > GS_R(0.0))) return false;
    f->up_x = ux / nrm;
    f->up_y = uy / nrm;
    return true;
}

/* Restart the seed's level trackers from ring sample i (from nothing when not held) */
static NOINLINE void restart_levels(gs_flight *f, uint32_t i)
{
    gs_sample_full s_b;
    const gs_sample_full *s = at(f, i, &s_b);
    gs_real u = s ? u_of(f, s) : NAN;
    f->blk_min_cur = finite_r(u) ? u : INFINITY;
    f->blk_min_prev = f->blk_min_cur;
    f->blk_t0_us = s ? s->t_us : GS_T_NONE;
    f->peak_u = -INFINITY;
    f->n_hist = 0;
}

/* The close is over: the next flight may start right after this landing (land_idx: the
 * first sample after the flight, GS_NO_IDX unknown), its take-off side must see the
 * contact samples that follow it */
static NOINLINE void close_done(gs_flight *f, gs_close *c, uint32_t land_idx)
{
    f->quiet_from = land_idx < c->newest ? land_idx : c->newest;  /* (GS_NO_IDX is above every index) */
    restart_levels(f, c->newest);  /* next seeds start after the landing */
}

/* GS_CLOSE_START: the flight's fit as grown so far, and the take-off side's walk from its first sample */
static uint8_t close_start(gs_flight *f, gs_close *c)
{
    if (gs_fit_solve(&f->fit, &c->r) != GS_OK) {
        close_done(f, c, GS_NO_IDX);
        return GS_CLOSE_NONE;
    }
    c->walk_i = c->clean = f->fl_first;
    c->outliers = 0;
    c->cusum = GS_R(0.0);
    c->t_prev_lus = lt_at(f, f->fl_first);
    c->left_alarm = GS_NO_IDX;
#if GS_CLOSE_LAG_FRAMES > 0
    c->alarm_due = false;
#endif
    return GS_CLOSE_GROW;
}

/* GS_CLOSE_BOUNDS: the take-off and landing times (the feet's, else the COM's contact model)
 * and the samples of the final fit */
static uint8_t close_bounds(gs_flight *f, gs_close *c)
{
    const gs_fit_result *r = &c->r;
    /* boundary refinement on the up direction of the flight's own acceleration */
    gs_real save_ux = f->up_x, save_uy = f->up_y;
    bool falls = finite_r(r->a_px_s2) && r->a_px_s2 > GS_R(0.0);
    if (falls) {
        f->up_x = -r->ax_px_s2 / r->a_px_s2;
        f->up_y = -r->ay_px_s2 / r->a_px_s2;
    }
    uint32_t L = f->fl_first, R = f->fl_last;
    int64_t c0 = t_at(f, L);  /* the COM's flight as grown begins (GS_T_NONE: no longer held) */
    /* the feet's times where the layout shows them: the flight is the feet's time off the floor */
    if (GS_WITH_POSE) {  /* (read only where a layout shows feet) */
        c->floor_off_px = c->floor_on_px = c->floor_before_px = NAN;
        c->F0_lus = c->F1_lus = GS_LT_NONE;
        c->feet_contradict = false;  /* the feet, in view, show no flight there */
        c->fell = false;             /* ... or a fall to a lower floor */
    }
    if (GS_WITH_POSE && FEET_ON(f) && falls) {
        gs_feet_flush(&f->feet);  /* the newest frame too: the landing may be in it */
        int64_t apex_us = fit_apex_us(r);
        int64_t c1 = t_at(f, R);  /* ... and ends (held where L is: R lies between L and the newest) */
        bool known = apex_us != GS_T_NONE && c0 != GS_T_NONE;
        int64_t c0_from = known ? c0 - FEET_BEFORE_COM_US : 0;  /* the feet's events count from here */
        if (known) {

            /* (both within the local range: near the flight's held samples) */
            int64_t F0_us = gs_feet_takeoff(&f->feet, c0_from, apex_us, &c->floor_off_px);
            int64_t from = c1 - FEET_BEFORE_COM_US > apex_us ? c1 - FEET_BEFORE_COM_US : apex_us;
            int64_t F1_us = gs_feet_landing(&f->feet, from, c1 + FEET_AFTER_COM_US, &c->floor_on_px, &c->floor_before_px);
            c->F0_lus = F0_us != GS_T_NONE ? lt_of(f, F0_us) : GS_LT_NONE;
            c->F1_lus = F1_us != GS_T_NONE ? lt_of(f, F1_us) : GS_LT_NONE;
        }
        int32_t F0 = c->F0_lus, F1 = c->F1_lus;
        DBG("feet: com %lld..%lld apex %lld -> F0 %lld F1 %lld floors %.1f %.1f before %.1f\n", (long long)c0,
            (long long)c1, (long long)apex_us, (long long)F0, (long long)F1, c->floor_off_px, c->floor_on_px,
            c->floor_before_px);
        if (F1 != GS_LT_NONE && F1 <= F0) c->F0_lus = c->F1_lus = F0 = F1 = GS_LT_NONE;
        /* feet in view that rest on the floor at the apex, or left it and did not come back
         * around the COM's landing, say the body was not in flight there (feet that never
         * rested, as in quick hops, say nothing: the COM times the flight) */
        if (known && gs_feet_seen_since(&f->feet, c0_from))
            c->feet_contradict = gs_feet_resting_at(&f->feet, apex_us) ||
                              (F0 != GS_LT_NONE && F1 == GS_LT_NONE && gs_feet_airborne(&f->feet));
        /* a fall: the feet went well below the floor they left (a box): after a clean take-off
         * below its floor, else below the floor they had rested on */
        float size_px = (float)gate_size(f, L);
        float d_px = f->feet.delta_rel * size_px;
        /* (toes stop where they land: after it a squat's or a moving camera's frames are no
         * floor; an ankle's recrossing is above the floor it then comes down to) */
        float low_px = F1 != GS_LT_NONE && f->feet.stop_touch ? c->floor_on_px : gs_feet_low_px(&f->feet);
        c->fell = F0 != GS_LT_NONE ? low_px < c->floor_off_px - d_px - FALL_FLOOR_REL * size_px
                               : gs_feet_sank_since(&f->feet, c0);
        /* ... or the landing met a floor well below the one that foot had rested on (size_px
         * is the final judgement's gating size: the same standing size) */
        c->fell = c->fell || (F1 != GS_LT_NONE && c->floor_on_px < c->floor_before_px - FALL_FLOOR_REL * size_px);
    }
    /* a flight longer than the ring holds has lost its edges: no refinement. (The ring
     * holds a contiguous range; the contact samples lie between L and the newest and
     * are held, so L tells for all of them.) */
    bool feet = GS_WITH_POSE && c->F0_lus != GS_LT_NONE && c->F1_lus != GS_LT_NONE;
    if (GS_WITH_POSE) c->feet = feet;
    bool refine = c0 != GS_T_NONE && !feet;  /* a body's are its feet's where seen */
    uint32_t lo, hi;  /* the outermost contact samples */
    int32_t T0 = c->T0_lus = boundary_time(f, c, -1, refine, &lo);
    int32_t T1 = c->T1_lus = boundary_time(f, c, +1, refine, &hi);
    DBG("close: L=%llu R=%llu lo=%llu hi=%llu T0=%lld T1=%lld a=%.1f\n",
        (unsigned long long)L, (unsigned long long)R, (unsigned long long)lo, (unsigned long long)hi,
        (long long)T0, (long long)T1, r->a_px_s2);
    /* with the feet's times: the flight and the nearly free frames beside it (the push-off's
     * last tens of ms, when the ground already bears less than the weight; the first of the
     * landing) as far as the parabola explains them */
    int32_t W0 = T0, W1 = T1;
    if (feet) {
        W0 = c->F0_lus - FEET_FREE_EDGE_US;
        W1 = c->F1_lus + FEET_FREE_EDGE_US;
    }
    c->in_lo = trim_edge(f, lo, hi, W0, -1, L);
    c->in_hi = trim_edge(f, hi, c->in_lo, W1, +1, R);
    f->up_x = save_ux;
    f->up_y = save_uy;
    return GS_CLOSE_FINAL;
}

/* GS_CLOSE_FINAL: the final robust fit over the flight's samples, the judgement and the event */
static uint8_t close_final(gs_flight *f, gs_close *c)
{
    uint32_t land_idx = GS_NO_IDX;  /* first sample after the flight */
    int32_t T0 = c->T0_lus, T1 = c->T1_lus;
    uint32_t in_lo = c->in_lo, in_hi = c->in_hi;
    int32_t t_first = lt_at(f, in_lo), t_last = lt_at(f, in_hi);  /* the outermost flight samples */
    if (t_first == GS_LT_NONE || t_last == GS_LT_NONE) goto done;  /* (in_lo <= in_hi: trim_edge keeps them within [lo, hi] in order) */
    land_idx = in_hi + 1;
    uint32_t count = (uint32_t)(in_hi - in_lo + 1);
    gs_fit_result fr;
    float min_scale = (float)noise_floor(f);  /* Tukey scale never below the noise: only gross outliers lose weight */
    gs_status st = robust_fit(f, in_lo, count, CFG(f)->fit_method, min_scale, &fr);
    trace_fit(f, "final", abs_of(f, t_first), abs_of(f, t_last), st == GS_OK ? &fr : NULL);
    if (st != GS_OK) goto done;  /* nothing fits: not a flight worth reporting */

    /* samples actually inside the flight (usable) and rejected as outliers */
    uint32_t n_in = 0, n_out = 0;
    int32_t max_gap_in = 0;
    int32_t t_prev = GS_LT_NONE;
    for (uint32_t i = in_lo; i <= in_hi; i++) {
        gs_sample_full s_b;
        const gs_sample_full *s = at(f, i, &s_b);
        if (!s || !(s->w > 0.0f)) continue;  /* frames missing from the source */
        int32_t t = lt_of(f, s->t_us);
        if (t_prev != GS_LT_NONE && t - t_prev > max_gap_in) max_gap_in = t - t_prev;  /* (held: exact) */
        t_prev = t;
        if (!usable(s)) continue;
        n_in++;
        if (!gs_fit_kept(f->keep, (uint32_t)(i - in_lo))) n_out++;
    }

    /* the flight is the feet's time off the floor where they were seen to leave and to land */
    bool feet = GS_WITH_POSE && c->feet;  /* (no layout with feet: their code folds away) */
    int32_t F1 = GS_WITH_POSE ? c->F1_lus : GS_LT_NONE;
    if (feet) {  /* (one end from the feet and the other from the COM would mix two definitions) */
        T0 = c->F0_lus;
        T1 = F1;
    }
    /* sub-frame times: fall back to half a frame outside the outermost flight sample (the
     * feet's are both known) */
    int32_t half_dt = frame_dt_us(f) / 2;
    if (T0 == GS_LT_NONE) T0 = t_first - half_dt;
    if (T1 == GS_LT_NONE) T1 = t_last + half_dt;
    int64_t T0_us = abs_of(f, T0), T1_us = abs_of(f, T1);

    gs_event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_JUMP;
    gs_ev_jump *j = &ev.u.jump;
    j->index = f->n_flights;
    j->track = f->track;
    j->t_takeoff_us = T0_us;
    j->t_land_us = T1_us;
    j->flight_time_s = gs_time_span_s(T1_us, T0_us);
    j->n_samples = n_in;
    j->n_outliers = n_out;
    j->height_m = j->height_se_m = NAN;  /* the other fields are all set below (memset: not accepted, no reason) */

    /* (a size is a median of finite sizes or NaN: a comparison with an unknown one is false) */
    gs_real size_se = NAN;
    gs_real size = IS_RIGID(f) ? rigid_size(f, in_lo, in_hi, &size_se) : stand_size(f, &size_se);
    const gs_real size_measured = size;  /* (size itself is dropped where the depth changed) */
    uint32_t warn = 0;  /* j->warnings, set once */

    {
        gs_real g = f->g_m_s2;
        j->a_px_s2 = fr.a_px_s2;
        j->a_px_se_s2 = fr.a_se_px_s2;
        j->g_dir_deg = fr.g_dir_deg;
        j->rms_px = fr.rms_px;
        gs_real q = g / fr.a_px_s2, height = NAN;
        j->q_m_per_px = q;
        gs_real apex_s = fit_apex_s(&fr);
        j->t_apex_us = gs_time_add_s(fr.t0_us, apex_s);
        gs_real rise_t = gs_time_span_s(fr.t0_us, T0_us) + apex_s;
        j->jump_height_m = g * j->flight_time_s * j->flight_time_s / GS_R(8.0);
        j->com_rise_m = GS_R(0.5) * g * rise_t * rise_t;
        j->takeoff_velocity_m_s = g * rise_t;
        /* a rebound: the ground contact since the last landing, no stance between */
        j->contact_time_s = j->rsi = NAN;
        /* 0 < T0 - last <= CONTACT_MAX_US unsigned: GS_T_NONE lies 2^62 us or more before any T0 */
        if ((uint64_t)T0_us - (uint64_t)f->last_land_us - 1u < (uint64_t)CONTACT_MAX_US &&
            !(f->stand_last_us > f->last_land_us)) {
            j->contact_time_s = gs_time_span_s(T0_us, f->last_land_us);
            j->rsi = j->jump_height_m / j->contact_time_s;
        }
        if (!IS_RIGID(f) && !feet) warn |= GS_WARN_COM_TIMED;
        /* the stature only where the body stood at the flight's place (its feet on the same floor row) */
        if (feet && f->feet.epoch == f->stand_floor_epoch && finite_r(f->stand_floor_px) &&
            finite_r(c->floor_off_px) && GS_FABSR((gs_real)(c->floor_off_px - f->stand_floor_px)) > DEPTH_TOL_REL * size) {
            warn |= GS_WARN_DEPTH_CHANGED;
            size = size_se = NAN;
        }
        j->size_px = size;
        gs_real ra = fr.a_se_px_s2 / fr.a_px_s2;  /* the acceleration's relative SE */
        if (finite_r(size)) {
            height = size * q;
            j->height_m = height;
            gs_real rs = finite_r(size_se) ? size_se / size : GS_R(0.0);
            j->height_se_m = height * GS_SQRT((finite_r(ra) ? ra * ra : GS_R(0.0)) + rs * rs);
        }

        /* is this a flight at all? (walking bumps, standing, noise) A body's gating size is
         * its standing size, even where the depth left it unused */
        gs_real gsize = !IS_RIGID(f) ? size_measured : finite_r(size) ? size : gate_size(f, in_lo);
        bool flight_like = plausible_fall(f, &fr, gsize);
        if (!flight_like) goto done;
        f->last_land_us = F1 != GS_LT_NONE ? abs_of(f, F1) : T1_us;  /* (a fall's landing is the feet's, for the rebound's contact) */
        /* a body measured without a size: its flight is still a flight (its height unknown) */
        bool sizeless_ok = !IS_RIGID(f) && feet;
        if (!finite_r(size) && sizeless_ok && !(warn & GS_WARN_DEPTH_CHANGED)) warn |= GS_WARN_NO_SIZE;

        if (GS_WITH_POSE && c->fell)
            j->reason = GS_REJ_FALL;
        else if (GS_WITH_POSE && c->feet_contradict)
            j->reason = GS_REJ_NO_FEET_FLIGHT;
        else if (n_in < CFG(f)->min_samples || T1_us - T0_us < f->min_flight_us)
            j->reason = GS_REJ_FEW_SAMPLES;
        else if (max_gap_in > f->max_gap_us)
            j->reason = GS_REJ_GAP;
        else if (!finite_r(size) && !sizeless_ok)
            j->reason = GS_REJ_NO_SIZE;
        else if (fr.rms_px > (gs_real)CFG(f)->max_rms_rel * gsize)
            j->reason = GS_REJ_LARGE_RESIDUAL;
        else if (!(ra <= (gs_real)CFG(f)->max_a_se_rel) || running_stride(f, &fr, n_in, feet, gsize))
            j->reason = GS_REJ_UNCERTAIN_A;
        else if (!gravity_agrees(f, &fr))
            j->reason = GS_REJ_GRAVITY_DIR;
        else if (finite_r(height) && (height < (gs_real)CFG(f)->size_min_m || height > (gs_real)CFG(f)->size_max_m))
            j->reason = GS_REJ_IMPLAUSIBLE_A;
        j->accepted = j->reason == GS_REJ_NONE;
        /* the same posture at both ends puts the COM at the same height (feet times only) */
        if (feet) {
            gs_real du = fit_u_at(&fr, T1_us) - fit_u_at(&fr, T0_us);
            if (GS_FABSR(du) > COM_MISMATCH_REL * gsize) warn |= GS_WARN_COM_MISMATCH;
        }

        if (n_in < 2u * CFG(f)->min_samples) warn |= GS_WARN_FEW_SAMPLES;
        if (n_out * 5u > n_in) warn |= GS_WARN_OUTLIERS;
        if (c->truncated) warn |= GS_WARN_CLIPPED;
        if (GS_FABSR(fr.g_dir_deg - f->last_g_dir_deg) > GS_R(10.0))  /* (NaN before an accepted flight) */
            warn |= GS_WARN_GRAVITY_TILT;
        j->warnings = warn;
    }

    if (j->accepted) {
        f->last_a_px_s2 = fr.a_px_s2;
        f->last_g_dir_deg = finite_r(f->last_g_dir_deg)
            ? GS_R(0.7) * f->last_g_dir_deg + GS_R(0.3) * fr.g_dir_deg : fr.g_dir_deg;
        /* gravity's direction in the image, from the flights themselves */
        gs_real ux = -fr.ax_px_s2 / fr.a_px_s2, uy = -fr.ay_px_s2 / fr.a_px_s2;
        if (f->up_from_flight) {
            ux = GS_R(0.7) * f->up_x + GS_R(0.3) * ux;
            uy = GS_R(0.7) * f->up_y + GS_R(0.3) * uy;
        }
        if (set_up(f, ux, uy)) f->up_from_flight = true;
    }
    f->n_flights++;
    emit(f, &ev);

done:
    close_done(f, c, land_idx);
    return GS_CLOSE_NONE;
}

static void seed_found(gs_flight *f, uint32_t newest);

/* Take the close's steps: all of them (all), else until one has run a robust fit or the
 * boundary search. */
static void close_run(gs_flight *f, gs_close *c, bool all)
{
    bool spent = false;
    uint8_t stage = c->stage;
    while (stage != GS_CLOSE_NONE && (all || !spent)) {
        switch (stage) {
        case GS_CLOSE_REFIT: {  /* the running fit may hold samples past the edge: rebuild it over the flight */
            gs_fit_result r;
            refit_range(f, f->fl_first, f->fl_last, &r);
            stage = GS_CLOSE_START;
            spent = true;
            break;
        }
        case GS_CLOSE_START: stage = close_start(f, c); break;
        case GS_CLOSE_GROW: stage = grow_left_step(f, c, all, &spent); break;
        case GS_CLOSE_GROWN: {
            f->fl_first = c->clean;
            gs_fit_result rr;  /* r changes only when the refit succeeds */
            if (refit_range(f, f->fl_first, f->fl_last, &rr)) gs_fit_solve(&f->fit, &c->r);
            stage = GS_CLOSE_BOUNDS;
            spent = true;
            break;
        }
        case GS_CLOSE_BOUNDS: stage = close_bounds(f, c); spent = true; break;
#if GS_CLOSE_LAG_FRAMES > 0
        case GS_CLOSE_SEED:
            spent = true;
            if (seed_core_width(f, c->apex, c->newest, seed_half_us[c->width])) {
                c->stage = GS_CLOSE_NONE;
                seed_found(f, c->newest);  /* (its landing may begin a close) */
                stage = c->stage;
            } else if (++c->width == SEED_WIDTHS) {
                stage = GS_CLOSE_NONE;
            }
            break;
#endif
        default: stage = close_final(f, c); break;
        }
    }
    c->stage = stage;
}

/* Begin closing the open candidate. right_alarm: the sample at which contact was
 * detected after the flight (GS_NO_IDX when it ended otherwise); refit: rebuild the
 * running fit over the flight first. */
static void close_begin(gs_flight *f, gs_close *c, uint32_t newest, uint32_t right_alarm, bool truncated, bool refit)
{
    c->newest = newest;
    c->right_alarm = right_alarm;
    c->truncated = truncated;
    c->head = head_idx(f);
    c->stage = refit ? GS_CLOSE_REFIT : GS_CLOSE_START;
    memo_forget(f);
}

#if GS_CLOSE_LAG_FRAMES > 0
/* The largest turn (cos, sin) a close can give the image's up: it sets it from an accepted
 * flight, whose gravity lies within plausible_fall's cone (80 degrees at most) and, once an up
 * is known, within gravity_agrees's limit at the largest accepted SE; blended 0.3 once
 * flights set it. (A little wider for rounding.) */
static void up_turn_max(const gs_flight *f, gs_real *cos_out, gs_real *sin_out)
{
    gs_real cap = GS_R(80.0) * GS_PI / GS_R(180.0);
    gs_real lim = GRAV_DIR_SE_K * (gs_real)CFG(f)->max_a_se_rel + GRAV_DIR_MIN_DEG * GS_PI / GS_R(180.0);
    gs_real th = (f->up_from_flight || f->up_n > 0) && lim < cap ? lim : cap;
    gs_real c = (gs_real)GS_COS(th + GS_R(1e-3)), s = (gs_real)GS_SIN(th + GS_R(1e-3));
    if (f->up_from_flight) {
        gs_real bx = GS_R(0.7) + GS_R(0.3) * c, by = GS_R(0.3) * s, n = GS_SQRT(bx * bx + by * by);
        c = bx / n;
        s = by / n;
    }
    *cos_out = c;
    *sin_out = s;
}

/* Could the standing tracker take waiting sample i once it is examined (gs_flight_stand_at
 * answers for the newest frame while it waits)? False only where it provably cannot: not
 * examined, one of the first two after the close (their median of three is not yet
 * formed), not upright, or inside STAND_SETTLE_US of a frame that ended any stillness. The
 * third and fourth (both examined on the ground: no flight is seeded before) end it when
 * they move faster than a standing body along any up the close may set; later ones could
 * follow another close. Checked in order: tracks the frame interval as examine will. */
static bool may_stand(gs_flight *f, gs_close *c, uint32_t i)
{
    gs_sample_full s_b;
    const gs_sample_full *s = at(f, i, &s_b);
    if (!s || !(s->w > 0.0f)) return false;
    int64_t t_prev = c->t_last_us;
    c->t_last_us = s->t_us;
    if (!usable(s)) return false;
    uint32_t dt_q4 = f->dt_med_q4;
    f->dt_med_q4 = c->dt_q4;
    if (t_prev != GS_T_NONE) {
        track_frame_dt(f, s->t_us - t_prev);
        if (s->t_us - t_prev > f->max_gap_us) c->n_ground = 0;  /* the levels restart */
    }
    c->dt_q4 = f->dt_med_q4;
    uint32_t k = frame_steps(f, STAND_LAG_US, 1);
    f->dt_med_q4 = dt_q4;
    if (++c->n_ground < 3 || IS_RIGID(f) || !size_ok(s->size_px)) return false;
    gs_real thr = STAND_SPEED_REL * (gs_real)s->size_px;
    gs_sample_full b_b;
    const gs_sample_full *b = k >= 1 && i >= c->low + k ? usable_at(f, i - k, &b_b) : NULL;
    if (c->n_ground <= 4 && b && s->t_us > b->t_us) {
        gs_real cs, sn;
        up_turn_max(f, &cs, &sn);
        gs_real dx = (gs_real)s->x_px - (gs_real)b->x_px, dy = (gs_real)s->y_px - (gs_real)b->y_px;
        gs_real along = GS_FABSR(dx * f->up_x + dy * f->up_y), across = GS_FABSR(dy * f->up_x - dx * f->up_y);
        if ((along * cs - across * sn) / gs_time_span_s(s->t_us, b->t_us) > thr * GS_R(1.001)) {
            c->still_after_us = s->t_us;
            return false;
        }
    }
    if (!(s->upright >= STAND_UPRIGHT)) return false;
    return c->still_after_us == GS_T_NONE || s->t_us - c->still_after_us >= STAND_SETTLE_US;
}

/* Must the pending close finish in this frame? It adds at most CLOSE_LAG_US to its event's
 * latency (a visit's absence, at least 0.5 s, cannot end meanwhile); the samples it reads
 * must stay in the ring (the next push must not overwrite the oldest), and no frame it
 * holds back may be one the standing tracker takes (may_stand). Trace events come in the
 * stream's order. */
static bool close_due(gs_flight *f)
{
    gs_close *c = &f->close;
    uint32_t head = head_idx(f);
    int64_t t_new_us = f->ring->t_last_us;
    if (f->trace || f->close_whole || head - c->head >= GS_CLOSE_LAG_FRAMES || head + 1u - c->low >= f->ring->capacity ||
        (t_new_us != GS_T_NONE && t_new_us - c->t_end_us >= CLOSE_LAG_US))
        return true;
    while (c->checked < head)
        if (may_stand(f, c, c->checked++)) return true;
    return false;
}

/* The held feet of the frames up to t_us into the feet's tracker (the frame's sample is
 * examined next; no job pends) */
static void feet_release(gs_flight *f, int64_t t_us)
{
    uint32_t n = 0;
    while (n < f->feet_held_n && f->feet_held[n].t_us <= t_us) {
        const gs_feet_frame *h = &f->feet_held[n++];
        gs_flight_feet(f, h->t_us, h->x_px, h->y_px, h->size_px);  /* (no job pends: pushed) */
    }
    if (n == 0) return;
    f->feet_held_n -= n;
    memmove(f->feet_held, f->feet_held + n, f->feet_held_n * sizeof f->feet_held[0]);
}
#endif

/* Close the open candidate at once */
static void close_now(gs_flight *f, uint32_t newest, uint32_t right_alarm, bool truncated, bool refit)
{
#if GS_CLOSE_LAG_FRAMES > 0
    gs_close *c = &f->close;
#else
    gs_close cl, *c = &cl;
#endif
    close_begin(f, c, newest, right_alarm, truncated, refit);
    close_run(f, c, true);
}

/* ---- the per-sample state machine ------------------------------------------ */

static void airborne_sample(gs_flight *f, uint32_t idx, const gs_sample_full *s);

/* The seed holds: airborne from its apex; samples after the core that arrived meanwhile
 * (through newest) are tested in order */
static void seed_found(gs_flight *f, uint32_t newest)
{
    set_state(f, GS_FS_AIRBORNE, t_at(f, f->seed_idx));  /* (the apex: held, as the core around it) */
    for (uint32_t i = f->fl_last + 1; i <= newest && f->state == GS_FS_AIRBORNE; i++) {
        gs_sample_full p_b;
        const gs_sample_full *p = usable_at(f, i, &p_b);
        if (p) airborne_sample(f, i, p);
    }
}

#if GS_CLOSE_LAG_FRAMES > 0
/* A job that waits for the next frames (a close or a seed, its newest sample at t_us): no
 * sample is examined meanwhile, n_ground: usable samples since the levels restarted (see
 * may_stand), low: the oldest sample it may read */
static void job_wait(gs_flight *f, gs_close *c, int64_t t_us, uint32_t n_ground, uint32_t low)
{
    uint32_t oldest = oldest_idx(f);
    c->head = head_idx(f);
    c->t_end_us = t_us;
    c->low = low > oldest ? low : oldest;
    c->checked = f->next;
    c->n_ground = n_ground;
    c->dt_q4 = f->dt_med_q4;
    c->t_last_us = f->last_t_us;
    /* a stillness goes on from when it began, or begins after now */
    c->still_after_us = f->still_since_us != GS_T_NONE ? f->still_since_us : t_us;
}

/* Seed a flight at an apex (ground_sample): the two narrower core widths now, the widest
 * in the next frame (GS_CLOSE_SEED; at once when that frame could be a standing one, as it is
 * when the "apex" was a standing body's noise) */
#define SEED_WIDTHS_NOW 2
static void seed_begin(gs_flight *f, uint32_t apex, uint32_t newest, int64_t t_us)
{
    for (unsigned k = 0; k < SEED_WIDTHS_NOW; k++)
        if (seed_core_width(f, apex, newest, seed_half_us[k])) {
            seed_found(f, newest);
            return;
        }
    gs_close *c = &f->close;
    c->stage = GS_CLOSE_SEED;
    c->apex = apex;
    c->width = SEED_WIDTHS_NOW;
    c->newest = newest;
    /* (the levels run on, and a flight may be seeded next: no sample is spared the test) */
    job_wait(f, c, t_us, 4u, history_floor(f));
    if (close_due(f)) close_run(f, c, true);
}
#endif

/* |du/dt| against the sample about lag_us back (frame jitter is not motion); NaN unknown */
static gs_real speed_px_s(const gs_flight *f, uint32_t idx, const gs_sample_full *s, gs_real u, uint32_t lag_us)
{
    uint32_t k = frame_steps(f, lag_us, 1);
    if (k < 1) k = 1;
    gs_sample_full b_b;  /* (a sample before the oldest held, or before the first, is not held) */
#ifndef __OPTIMIZE_SIZE__
    /* usable_at reading only what the test and the speed need */
    const gs_sample *rs = gs_ring_at(f->ring, ring_idx(f, idx - k));
    if (!rs) return NAN;
    b_b.t_us = gs_ring_sample_t_us(f->ring, rs);
    b_b.x_px = rs->x_px;
    b_b.y_px = rs->y_px;
    b_b.w = gs_sample_w(rs);
    const gs_sample_full *b = usable(&b_b) ? &b_b : NULL;
#else
    const gs_sample_full *b = usable_at(f, idx - k, &b_b);
#endif
    int32_t dt_us = b ? near_us(s->t_us, b->t_us) : 0;  /* (two held samples) */
    if (dt_us <= 0) return NAN;
    return GS_FABSR(u - u_of(f, b)) / gs_time_span32_s(dt_us);
}

/* keep size in a ring of the last GS_STAND_KEEP */
static NOINLINE void keep_size(float *ring, uint32_t *n, uint32_t *next, float size_px)
{
    ring[*next] = size_px;
    *next = (*next + 1u) % GS_STAND_KEEP;
    if (*n < GS_STAND_KEEP) (*n)++;
}

static void update_standing(gs_flight *f, const gs_sample_full *s, gs_real speed)
{
    if (!finite_r(speed)) return;
    if (IS_RIGID(f) || !size_ok(s->size_px)) return;
    /* stillness is broken by motion only; uprightness is judged frame by frame */
    if (!(speed < STAND_SPEED_REL * (gs_real)s->size_px)) { f->still_since_us = GS_T_NONE; return; }
    if (f->still_since_us == GS_T_NONE) f->still_since_us = s->t_us;
    if (s->upright >= LOOSE_UPRIGHT) {
        keep_size(f->loose_size, &f->loose_n, &f->loose_next, s->size_px);
    }
    if (!(s->upright >= STAND_UPRIGHT)) return;
    if (s->t_us - f->still_since_us < STAND_SETTLE_US) return;  /* settled, not rising onto the toes */
    /* sizes are kept for one place: where the feet stand on another floor row, afresh */
    float floor = GS_WITH_POSE && FEET_ON(f) ? gs_feet_floor_px(&f->feet) : NAN;
    if (floor == floor) {
        bool same = f->stand_floor_epoch == f->feet.epoch && f->stand_floor_px == f->stand_floor_px;
        if (!same || GS_FABSR((gs_real)(floor - f->stand_floor_px)) > DEPTH_TOL_REL * (gs_real)s->size_px) {
            if (same) f->stand_n = f->stand_next = f->loose_n = f->loose_next = 0;
            f->stand_floor_px = floor;
            f->stand_floor_epoch = f->feet.epoch;
        }
    }
    keep_size(f->stand_size, &f->stand_n, &f->stand_next, s->size_px);
    f->stand_last_us = s->t_us;
    /* body axis -> image up, until flights measure gravity directly */
    if (!f->up_from_flight && gs_finite2_f(s->up_x, s->up_y)) {
        gs_real ux = (gs_real)s->up_x, uy = (gs_real)s->up_y;  /* the first as it is */
        if (f->up_n > 0) {
            gs_real kw = f->up_n < 20 ? GS_R(1.0) / (gs_real)(f->up_n + 1) : GS_R(0.05);
            ux = (GS_R(1.0) - kw) * f->up_x + kw * ux;
            uy = (GS_R(1.0) - kw) * f->up_y + kw * uy;
        }
        set_up(f, ux, uy);
        f->up_n++;
    }
}

/* the newest standing size (stand_n > 0) */
static float last_stand_size(const gs_flight *f)
{
    return f->stand_size[(f->stand_next + GS_STAND_KEEP - 1u) % GS_STAND_KEEP];
}

gs_real gs_flight_stand_at(const gs_flight *f, int64_t t_us)
{
    /* the ring gives times back exactly: the same frame has the same time */
    if (!f || f->stand_n == 0 || f->stand_last_us != t_us || t_us == GS_T_NONE) return NAN;
    return (gs_real)last_stand_size(f);
}

NOINLINE void gs_flight_forget_body(gs_flight *f)  /* (one copy for init and the pipeline) */
{
    if (!f) return;
#if GS_CLOSE_LAG_FRAMES > 0
    close_finish(f);  /* the close judges with the body it measured */
#endif
    f->stand_n = f->stand_next = 0;
    f->loose_n = f->loose_next = 0;
    f->stand_last_us = GS_T_NONE;
    f->still_since_us = GS_T_NONE;
    f->stand_floor_px = NAN;
    if (!f->up_from_flight) f->up_n = 0;
}

static gs_real size_ref(const gs_flight *f, const gs_sample_full *s)
{
    if (!IS_RIGID(f) && f->stand_n > 0) { /* a rigid object has no standing sizes */
        return last_stand_size(f);
    }
    return size_ok(s->size_px) ? (gs_real)s->size_px : NAN;
}

static void ground_sample(gs_flight *f, uint32_t idx, const gs_sample_full *s)
{
    /* history for the median of three and second differences */
    if (f->n_hist == 3) {
        for (unsigned k = 0; k < 2; k++) {
            f->u_hist[k] = f->u_hist[k + 1];
            f->i_hist[k] = f->i_hist[k + 1];
            f->t_hist_us[k] = f->t_hist_us[k + 1];
        }
        f->n_hist = 2;
    }
    f->u_hist[f->n_hist] = u_of(f, s);
    f->i_hist[f->n_hist] = idx;
    f->t_hist_us[f->n_hist] = s->t_us;
    f->n_hist++;
    if (f->n_hist < 3) return;

    gs_real um = med3(f->u_hist[0], f->u_hist[1], f->u_hist[2]);
    uint32_t im = f->i_hist[1];
    int64_t tm = f->t_hist_us[1];
    gs_real d2 = f->u_hist[2] - GS_R(2.0) * f->u_hist[1] + f->u_hist[0];
    gs_real sz = size_ref(f, s);

    /* keypoint noise, not motion: judged while nearly still (contact phases of a
     * jump series would otherwise pass for noise) */
    gs_real speed = speed_px_s(f, idx, s, f->u_hist[2], SPEED_LAG_US);
    /* size_ref(f, s) again would be sz: nothing between changes what it reads */
    /* sz is positive or NaN (unknown: any finite speed counts) */
    bool still = finite_r(speed) && !(speed >= STAND_SPEED_REL * sz);
    /* noise: a robust running mean of |second difference| on the ground, started from
     * the median of the first few (one early glitch must not set it) */
    if (f->noise_n < NOISE_INIT_N) {
        f->noise_init[f->noise_n++] = (float)GS_FABSR(d2);
        if (f->noise_n == NOISE_INIT_N) {  /* (their order is not needed again: sorted in place) */
            gs_real med = median_f(f->noise_init, NOISE_INIT_N);
            f->noise_px = med / GS_R(1.652);  /* median |N(0, 6 s^2)| = 1.652 s */
            if (f->noise_px < GS_R(0.05)) f->noise_px = GS_R(0.05);
        }
    } else if (still) {
        gs_real a = GS_FABSR(d2) / GS_R(1.954);  /* E|N(0, 6 s^2)| = 1.954 s */
        if (a > GS_R(3.0) * f->noise_px) a = GS_R(3.0) * f->noise_px;
        f->noise_px += GS_R(0.02) * (a - f->noise_px);
    }
    update_standing(f, s, speed_px_s(f, idx, s, f->u_hist[2], STAND_LAG_US));

    /* recent minimum over two half-second blocks */
    if (f->blk_t0_us == GS_T_NONE) f->blk_t0_us = tm;
    if (tm - f->blk_t0_us > LEVEL_BLOCK_US) {
        f->blk_min_prev = f->blk_min_cur;
        f->blk_min_cur = INFINITY;
        f->blk_t0_us = tm;
    }
    if (um < f->blk_min_cur) f->blk_min_cur = um;
    gs_real umin = f->blk_min_cur < f->blk_min_prev ? f->blk_min_cur : f->blk_min_prev;

    gs_real nz = noise_floor(f);
    gs_real thr = SEED_RISE_NOISE * nz;
    if (SEED_RISE_REL * sz > thr) thr = SEED_RISE_REL * sz;  /* false for an unknown (NaN) size */
    DBG("g t=%lld um=%.1f umin=%.1f thr=%.1f noise=%.2f sz=%.1f peak=%.1f\n", (long long)tm, um, umin, thr, nz, sz, f->peak_u);
    /* a peak counts once it rose thr above the recent minimum; the drop that
     * confirms it as an apex seeds a flight, however far it has fallen by then */
    if (!finite_r(f->peak_u)) {
        if (um - umin > thr) { f->peak_u = um; f->peak_idx = im; }
        return;
    }
    if (um > f->peak_u) { f->peak_u = um; f->peak_idx = im; return; }
    gs_real drop = SEED_DROP_NOISE * nz;
    if (GS_R(0.01) * sz > drop) drop = GS_R(0.01) * sz;
    if (f->peak_u - um <= drop) return;
    uint32_t apex = f->peak_idx;
    f->peak_u = -INFINITY;
#if GS_CLOSE_LAG_FRAMES > 0
    if (!f->trace) {
        seed_begin(f, apex, idx, s->t_us);
        return;
    }
#endif
    if (seed_core(f, apex, idx)) seed_found(f, idx);
}

static void land(gs_flight *f, uint32_t idx, uint32_t alarm, const gs_sample_full *s)
{
    /* the COM may turn before the feet meet the floor (its model is not the body): while a
     * foot that left is still in the air, wait for it a little (the event still leaves well
     * within the landing latency) */
    if (GS_WITH_POSE && FEET_ON(f) && f->feet_wait_us == GS_T_NONE && gs_feet_airborne(&f->feet)) {
        f->feet_wait_us = s->t_us + FEET_WAIT_US;
        f->wait_alarm = alarm;
        return;
    }
    f->feet_wait_us = GS_T_NONE;
#if GS_CLOSE_LAG_FRAMES > 0
    if (!f->trace) {
        gs_close *c = &f->close;
        close_begin(f, c, idx, alarm, false, true);
        uint32_t floor_idx = history_floor(f);
        job_wait(f, c, s->t_us, 0u, f->fl_first < floor_idx ? f->fl_first : floor_idx);
        if (!close_due(f)) {  /* its steps in the next frames */
            set_state(f, GS_FS_GROUND, s->t_us);
            return;
        }
        c->stage = GS_CLOSE_NONE;
    }
#endif
    close_now(f, idx, alarm, false, true);
    set_state(f, GS_FS_GROUND, s->t_us);
}

static void airborne_sample(gs_flight *f, uint32_t idx, const gs_sample_full *s)
{
    uint32_t alarm = GS_NO_IDX;  /* the landing's contact alarm (one call of land below) */
    if (f->feet_wait_us != GS_T_NONE) {  /* the COM landed: waiting for the feet */
        if (s->t_us < f->feet_wait_us && gs_feet_airborne(&f->feet)) return;
        alarm = f->wait_alarm;
        goto landed;
    }
    gs_fit_result r;  /* (idx > fl_last: samples come after the seed's core, in order) */
    int32_t t = lt_of(f, s->t_us);
    if (gs_fit_solve(&f->fit, &r) != GS_OK || span_over(t, lt_at(f, f->seed_idx), f->max_flight_us))
        goto landed;
    if (r.n >= 8 && !plausible_fall(f, &r, gate_size(f, idx)))  /* a standing phase, not a flight */
        goto landed;
    uint32_t k = idx - f->fl_last - 1;  /* position among the pending samples */
    if (k >= 32) goto landed;
    gs_real z;
    bool ok = test_sample(f, &r, s, &z);
    DBG("t=%lld ok=%d z=%.2f S=%.2f n=%u a=%.1f noise=%.3f rms=%.3f\n", (long long)s->t_us, ok, z, f->cusum, r.n, r.a_px_s2, f->noise_px, r.rms_px);
    if (!ok) {
        if (++f->outliers_run >= 3) goto landed;
        return;
    }
    f->outliers_run = 0;
    bool contact = cusum_step(&f->cusum, z);
    alarm = idx;
    /* deviations that persist for the configured latency end the flight, alarm or not */
    if (f->cusum > GS_R(0.0) && span_over(t, lt_at(f, f->fl_last), f->landing_latency_us))
        goto landed;
    if (contact) {  /* decelerated by the ground: landed? */
        memo_forget(f);
        if (!alarm_is_false(f, f->fl_first, idx, +1)) goto landed;
        f->fl_last = idx;   /* the refit took every sample through idx */
        f->cusum = GS_R(0.0);
        f->pend_ok = 0;
        return;
    }
    f->pend_ok |= 1u << k;
    if (f->cusum == GS_R(0.0)) {
        /* everything pending was flight after all: take it in */
        for (uint32_t j = f->fl_last + 1; j <= idx; j++) {
            gs_sample_full p_b;
            const gs_sample_full *p = usable_at(f, j, &p_b);
            if (p && (f->pend_ok & (1u << (uint32_t)(j - f->fl_last - 1))))
                fit_add(f, p);
        }
        f->fl_last = idx;
        f->pend_ok = 0;
    }
    return;
landed:
    land(f, idx, alarm, s);
}

/* Keep the offsets small: once the ring's head is 2 x GS_FLIGHT_IDX_KEEP past the base,
 * the base moves to GS_FLIGHT_IDX_KEEP before it (the ring holds fewer samples: no held
 * sample falls before it). A stored index before the new base (never held) becomes 0,
 * equally unheld and before every held one. */
static void rebase(gs_flight *f)
{
    static const uint16_t idx_fields[] = {
        offsetof(gs_flight, next), offsetof(gs_flight, quiet_from), offsetof(gs_flight, last_idx),
        offsetof(gs_flight, i_hist[0]), offsetof(gs_flight, i_hist[1]), offsetof(gs_flight, i_hist[2]),
        offsetof(gs_flight, peak_idx), offsetof(gs_flight, fl_first), offsetof(gs_flight, fl_last),
        offsetof(gs_flight, seed_idx), offsetof(gs_flight, wait_alarm),
#if GS_CLOSE_LAG_FRAMES > 0
        offsetof(gs_flight, close.newest), offsetof(gs_flight, close.head), offsetof(gs_flight, close.low),
        offsetof(gs_flight, close.right_alarm), offsetof(gs_flight, close.left_alarm),
        offsetof(gs_flight, close.walk_i), offsetof(gs_flight, close.clean),
        offsetof(gs_flight, close.in_lo), offsetof(gs_flight, close.in_hi), offsetof(gs_flight, close.apex),
#endif
    };
    uint64_t head = f->ring->head;
    if (head - f->base <= 2u * (uint64_t)GS_FLIGHT_IDX_KEEP) return;
    uint32_t by = idx_of(f, head - GS_FLIGHT_IDX_KEEP);
    f->base += by;
    for (unsigned k = 0; k < sizeof idx_fields / sizeof idx_fields[0]; k++) {
        uint32_t *i = (uint32_t *)(void *)((char *)f + idx_fields[k]);
        if (*i != GS_NO_IDX) *i = *i > by ? *i - by : 0u;
    }
}

/* Examine the samples pushed since (each after its frame's feet) until a close is pending */
static void examine(gs_flight *f)
{
    set_time_base(f);
    uint32_t head = head_idx(f);
    uint32_t oldest = oldest_idx(f);
    if (f->next < oldest) f->next = oldest;  /* fell behind the ring: skip what was lost */
    while (f->next < head) {
        uint32_t idx = f->next++;
        gs_sample_full s_b;
        const gs_sample_full *s = at(f, idx, &s_b);
#if GS_CLOSE_LAG_FRAMES > 0
        if (s && f->feet_held_n > 0) feet_release(f, s->t_us);
#endif
        /* a gap is frames missing from the source; a light frame (the head out of
         * the picture) is present, only not used */
        if (!s || !(s->w > 0.0f)) continue;
        if (!usable(s)) { f->last_t_us = s->t_us; continue; }
        if (f->last_t_us != GS_T_NONE) {
            int64_t dt = s->t_us - f->last_t_us;
            track_frame_dt(f, dt);
            if (dt > f->max_gap_us) {
                if (f->state == GS_FS_AIRBORNE) close_now(f, f->last_idx, GS_NO_IDX, true, false);
                restart_levels(f, GS_NO_IDX);  /* never held: from nothing */
                set_state(f, GS_FS_GROUND, s->t_us);
            }
        }
        f->last_t_us = s->t_us;
        f->last_idx = idx;
        if (f->state == GS_FS_IDLE) set_state(f, GS_FS_GROUND, s->t_us);
        if (f->state == GS_FS_AIRBORNE) airborne_sample(f, idx, s);
        else ground_sample(f, idx, s);
#if GS_CLOSE_LAG_FRAMES > 0
        if (f->close.stage != GS_CLOSE_NONE) return;  /* the rest waits for it */
#endif
    }
#if GS_CLOSE_LAG_FRAMES > 0
    if (f->feet_held_n > 0) feet_release(f, INT64_MAX);
#endif
}

#if GS_CLOSE_LAG_FRAMES > 0
/* Finish a pending close now, and any a later sample begins, examining what waited */
static void close_finish(gs_flight *f)
{
    while (f->close.stage != GS_CLOSE_NONE) {
        close_run(f, &f->close, true);
        examine(f);
    }
}
#endif

void gs_flight_update(gs_flight *f)
{
    rebase(f);
#if GS_CLOSE_LAG_FRAMES > 0
    if (f->close.stage != GS_CLOSE_NONE) {
        close_run(f, &f->close, close_due(f));
        if (f->close.stage != GS_CLOSE_NONE) return;
    }
#endif
    examine(f);
}


/* the stream ends or pauses: close an open candidate (one waiting for its feet with its alarm) */
static void end_flight(gs_flight *f)
{
    if (GS_WITH_POSE && FEET_ON(f)) gs_feet_flush(&f->feet);
    if (f->state != GS_FS_AIRBORNE) return;
    bool waited = f->feet_wait_us != GS_T_NONE;
    f->feet_wait_us = GS_T_NONE;
    close_now(f, f->last_idx, waited ? f->wait_alarm : GS_NO_IDX, !waited, false);
    set_state(f, GS_FS_GROUND, f->last_t_us);
}

void gs_flight_break(gs_flight *f)
{
    gs_flight_update(f);
#if GS_CLOSE_LAG_FRAMES > 0
    close_finish(f);
#endif
    end_flight(f);  /* what the next sample would do on seeing the gap, while the ring still holds the flight */
}

void gs_flight_finish(gs_flight *f)
{
    gs_flight_update(f);
#if GS_CLOSE_LAG_FRAMES > 0
    close_finish(f);
#endif
    end_flight(f);
}
