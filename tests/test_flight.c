/* test_flight.c - flight detection and measurement against simulated truth.
 * A COM track with a countermovement, constant-force propulsion, an exactly
 * ballistic flight, a hard landing and recovery is sampled at a camera rate
 * and fed through the pipeline (point layout, so sizes come with the samples). */
#include "unity.h"
#include "gravscale/gravscale.h"

#include <math.h>
#include <string.h>

#define MAX_JUMPS 16
#define PI 3.14159265358979323846

/* ---- a deterministic PRNG and Gaussian ------------------------------------- */
static uint64_t rng_state;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}
static double nrand(void)
{
    double u1 = urand(), u2 = urand();
    if (u1 < 1e-300) u1 = 1e-300;
    return sqrt(-2.0 * log(u1)) * cos(2.0 * PI * u2);
}

/* ---- simulated vertical COM track (metres, up positive) -------------------- */
typedef struct {
    double t_start;   /* start of countermovement */
    double v0;        /* take-off velocity */
    double t_takeoff, t_land;
} sim_jump;

typedef struct {
    double g, a_prop, a_land, rise_ext, cm_dur, rec_dur;
    sim_jump jumps[MAX_JUMPS];
    int n;
} sim_track;

/* u(t) of one jump relative to standing, 0 outside its span */
static double jump_u(const sim_track *s, const sim_jump *j, double t, bool *airborne)
{
    double D = j->v0 * j->v0 / (2.0 * s->a_prop) - s->rise_ext;  /* dip depth */
    double tp = j->v0 / s->a_prop;                                 /* propulsion time */
    double t1 = j->t_start + s->cm_dur;                            /* bottom of the dip */
    double tf = 2.0 * j->v0 / s->g;
    double tl = j->v0 / s->a_land;
    double u_to = -D + j->v0 * j->v0 / (2.0 * s->a_prop);
    *airborne = false;
    if (t < j->t_start) return 0.0;
    if (t < t1) return -D * 0.5 * (1.0 - cos(PI * (t - j->t_start) / s->cm_dur));
    if (t < t1 + tp) { double x = t - t1; return -D + 0.5 * s->a_prop * x * x; }
    double x = t - (t1 + tp);
    if (x < tf) { *airborne = true; return u_to + j->v0 * x - 0.5 * s->g * x * x; }
    x -= tf;
    if (x < tl) return u_to - j->v0 * x + 0.5 * s->a_land * x * x;
    double u_bot = u_to - j->v0 * j->v0 / (2.0 * s->a_land);
    x -= tl;
    if (x < s->rec_dur) return u_bot * 0.5 * (1.0 + cos(PI * x / s->rec_dur));
    return 0.0;
}

static double track_u(const sim_track *s, double t, bool *airborne)
{
    *airborne = false;
    for (int k = 0; k < s->n; k++) {
        const sim_jump *j = &s->jumps[k];
        double end = j->t_land + j->v0 / s->a_land + s->rec_dur;
        if (t >= j->t_start && t < end) return jump_u(s, j, t, airborne);
    }
    return 0.0;
}

static void make_track(sim_track *s, int n, double first, double spacing, double v0_lo, double v0_hi)
{
    memset(s, 0, sizeof *s);
    s->g = 9.81;
    s->a_prop = 14.0;
    s->a_land = 30.0;
    s->rise_ext = 0.08;
    s->cm_dur = 0.45;
    s->rec_dur = 0.5;
    s->n = n;
    for (int k = 0; k < n; k++) {
        sim_jump *j = &s->jumps[k];
        j->t_start = first + spacing * k;
        j->v0 = v0_lo + (v0_hi - v0_lo) * (n > 1 ? (double)k / (n - 1) : 0.5);
        j->t_takeoff = j->t_start + s->cm_dur + j->v0 / s->a_prop;
        j->t_land = j->t_takeoff + 2.0 * j->v0 / s->g;
    }
}

/* ---- event capture ------------------------------------------------------------ */
typedef struct {
    gs_ev_jump jumps[MAX_JUMPS * 4];
    double emitted_at[MAX_JUMPS * 4];   /* time of the newest sample pushed when it came */
    int n_jumps;
    gs_ev_height summary;
    int n_height, n_summary;
    double now;
} capture;

static void on_event(void *ctx, const gs_event *ev)
{
    capture *c = (capture *)ctx;
    if (ev->type == GS_EV_JUMP && c->n_jumps < MAX_JUMPS * 4) {
        c->emitted_at[c->n_jumps] = c->now;
        c->jumps[c->n_jumps++] = ev->u.jump;
    } else if (ev->type == GS_EV_HEIGHT) {
        c->n_height++;
    } else if (ev->type == GS_EV_SUMMARY) {
        c->summary = ev->u.height;
        c->n_summary++;
    }
}

typedef struct {
    double fps, q_m_per_px, roll_deg, noise_px, size_m, outlier_rate, phase;
} cam;

static double storage[(4096 * (sizeof(gs_sample) + sizeof(float))) / sizeof(double) + 8];

static gs_jump_judge_fn g_judge; /* the front end's judge for run_from (NULL: none) */
static int64_t g_clock_us;       /* run_from's clock: sample time t is g_clock_us + t, in microseconds */
static uint64_t g_ring_head;     /* run_from: the ring's absolute index of the first sample (0: as initialised) */
static uint32_t g_rebase_after;  /* ... and the flight's index base moves after this many samples */
static void run_from(const sim_track *s, const cam *c, capture *cap, double t_begin, double t_end);
static void run(const sim_track *s, const cam *c, capture *cap, double t_end) { run_from(s, c, cap, 0.0, t_end); }

static void run_from(const sim_track *s, const cam *c, capture *cap, double t_begin, double t_end)
{
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.ring_capacity = 1024;
    cfg.size_min_m = 0.01f;
    static gs_pipeline p;
    memset(cap, 0, sizeof *cap);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_POINT, storage, sizeof storage, on_event, cap));
    gs_pipeline_set_judge(&p, g_judge, cap);
    if (g_ring_head) {  /* as after a stream of g_ring_head samples, the flight's base due to move */
        p.ring.head = p.ring.valid_from = g_ring_head;
        uint32_t off = 2u * GS_FLIGHT_IDX_KEEP - g_rebase_after;
        p.flight.base = g_ring_head - off;
        p.flight.next = p.flight.quiet_from = off;
    }
    double ca = cos(c->roll_deg * PI / 180.0), sa = sin(c->roll_deg * PI / 180.0);
    double size_px = c->size_m / c->q_m_per_px;
    for (long i = (long)ceil(t_begin * c->fps);; i++) {
        double t = (i + c->phase) / c->fps;
        if (t > t_end) break;
        bool air;
        double u = track_u(s, t, &air);
        /* image: y down; the body drifts slowly sideways; camera roll rotates both */
        double X = 0.05 * t, Y = u;
        double xi = 960.0 + (X * ca - Y * sa) / c->q_m_per_px;
        double yi = 700.0 - (X * sa + Y * ca) / c->q_m_per_px;
        xi += c->noise_px * nrand();
        yi += c->noise_px * nrand();
        if (urand() < c->outlier_rate) { xi += 40.0 * (urand() - 0.5) * 2.0; yi += 40.0 * (urand() - 0.5) * 2.0; }
        cap->now = t;
        TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_point_us(&p, g_clock_us + gs_time_us_of_s(t), (float)xi, (float)yi,
                                                           1.0f, (float)(size_px + 0.3 * c->noise_px * nrand())));
    }
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_flush(&p));
    TEST_ASSERT_EQUAL(1, cap->n_summary);
}

/* match each true jump to one accepted event (take-off and landing within tol_s); return count matched */
static int match_tol(const sim_track *s, const capture *cap, int *map, double tol_s)
{
    int found = 0;
    for (int k = 0; k < s->n; k++) {
        map[k] = -1;
        for (int e = 0; e < cap->n_jumps; e++) {
            const gs_ev_jump *j = &cap->jumps[e];
            if (!j->accepted) continue;
            if (fabs(gs_time_s_of_us(j->t_takeoff_us) - s->jumps[k].t_takeoff) < tol_s && fabs(gs_time_s_of_us(j->t_land_us) - s->jumps[k].t_land) < tol_s) {
                map[k] = e;
                found++;
                break;
            }
        }
    }
    return found;
}

static int match(const sim_track *s, const capture *cap, int *map) { return match_tol(s, cap, map, 0.1); }

static double median5(double *v, int n)
{
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && v[j - 1] > v[j]; j--) { double t = v[j]; v[j] = v[j - 1]; v[j - 1] = t; }
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void setUp(void) { rng_state = 0x9E3779B97F4A7C15ull; }
void tearDown(void) {}

/* Noise-free at 30 fps: every flight, a within 0.3 %, boundaries within half a frame. */
static void test_exact_track_30fps(void)
{
    sim_track s;
    make_track(&s, 4, 1.5, 2.5, 1.4, 2.8);
    cam c = {30.0, 0.003, 0.0, 0.0, 0.20, 0.0, 0.37};
    capture cap;
    run(&s, &c, &cap, 12.0);
    int map[MAX_JUMPS];
    TEST_ASSERT_EQUAL_INT(4, match(&s, &cap, map));
    TEST_ASSERT_EQUAL_INT(4, cap.n_jumps);  /* nothing else reported */
    double a_true = 9.81 / 0.003;
    for (int k = 0; k < 4; k++) {
        const gs_ev_jump *j = &cap.jumps[map[k]];
        TEST_ASSERT_DOUBLE_WITHIN(0.003 * a_true, a_true, j->a_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(0.5 / 30.0, s.jumps[k].t_takeoff, gs_time_s_of_us(j->t_takeoff_us));
        TEST_ASSERT_DOUBLE_WITHIN(0.5 / 30.0, s.jumps[k].t_land, gs_time_s_of_us(j->t_land_us));
        TEST_ASSERT_DOUBLE_WITHIN(0.003 * 0.20, 0.20, j->height_m);
        double v0 = s.jumps[k].v0;
        TEST_ASSERT_DOUBLE_WITHIN(0.03 * v0, v0, j->takeoff_velocity_m_s);
        TEST_ASSERT_DOUBLE_WITHIN(0.05 * v0 * v0 / 19.62 + 0.005, v0 * v0 / 19.62, j->jump_height_m);
        /* emitted within 0.2 s of the true landing */
        TEST_ASSERT_TRUE(cap.emitted_at[map[k]] <= s.jumps[k].t_land + 0.2);
    }
    TEST_ASSERT_EQUAL_UINT32(4, cap.summary.n_jumps);
    TEST_ASSERT_DOUBLE_WITHIN(0.001, 0.20, cap.summary.height_m);
}

/* the front end sees something the keypoints do not in the second flight */
static void judge_second(void *ctx, gs_ev_jump *j)
{
    (void)ctx;
    if (j->index != 1) return;
    j->warnings |= GS_WARN_OTHER_MOTION;
    j->accepted = false;
    j->reason = GS_REJ_OTHER_MOTION;
}

/* A judge's rejection is what is reported and what the aggregate counts. */
static void test_front_end_judge(void)
{
    sim_track s;
    make_track(&s, 4, 1.5, 2.5, 1.4, 2.8);
    cam c = {30.0, 0.003, 0.0, 0.0, 0.20, 0.0, 0.37};
    capture cap;
    g_judge = judge_second;
    run(&s, &c, &cap, 12.0);
    g_judge = NULL;
    TEST_ASSERT_EQUAL_INT(4, cap.n_jumps);
    TEST_ASSERT_TRUE(cap.jumps[0].accepted);
    TEST_ASSERT_FALSE(cap.jumps[1].accepted);
    TEST_ASSERT_EQUAL_INT(GS_REJ_OTHER_MOTION, cap.jumps[1].reason);
    TEST_ASSERT_EQUAL_UINT32(GS_WARN_OTHER_MOTION, cap.jumps[1].warnings & GS_WARN_OTHER_MOTION);
    TEST_ASSERT_EQUAL_STRING("other_motion", gs_reject_reason_name(cap.jumps[1].reason));
    TEST_ASSERT_EQUAL_INT(3, cap.n_height);  /* no running height after the rejected one */
    TEST_ASSERT_EQUAL_UINT32(3, cap.summary.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(1, cap.summary.n_rejected);
}

/* Noisy at 30 fps with outliers and 30 deg roll: every flight found, a within
 * 3 SE per flight, boundaries within a frame on the median (a drifting fit of
 * a short noisy core may end one flight early: that costs samples, not bias),
 * gravity's direction found. */
static void test_noisy_rolled(void)
{
    sim_track s;
    make_track(&s, 5, 1.5, 2.5, 1.6, 2.8);
    cam c = {30.0, 0.003, 30.0, 1.0, 0.20, 0.02, 0.11};
    capture cap;
    run(&s, &c, &cap, 15.0);
    int map[MAX_JUMPS];
    TEST_ASSERT_EQUAL_INT(5, match_tol(&s, &cap, map, 0.15));
    double a_true = 9.81 / 0.003, d0[5], d1[5];
    for (int k = 0; k < 5; k++) {
        const gs_ev_jump *j = &cap.jumps[map[k]];
        TEST_ASSERT_DOUBLE_WITHIN(3.0 * j->a_px_se_s2 + 0.005 * a_true, a_true, j->a_px_s2);
        TEST_ASSERT_TRUE(j->a_px_se_s2 < 0.06 * a_true);
        double dir_se_deg = j->a_px_se_s2 / j->a_px_s2 * 57.2958;
        TEST_ASSERT_DOUBLE_WITHIN(3.0 * dir_se_deg + 0.5, 30.0, j->g_dir_deg);
        d0[k] = fabs(gs_time_s_of_us(j->t_takeoff_us) - s.jumps[k].t_takeoff);
        d1[k] = fabs(gs_time_s_of_us(j->t_land_us) - s.jumps[k].t_land);
    }
    TEST_ASSERT_TRUE(median5(d0, 5) < 1.0 / 30.0);
    TEST_ASSERT_TRUE(median5(d1, 5) < 1.0 / 30.0);
    TEST_ASSERT_DOUBLE_WITHIN(0.004, 0.20, cap.summary.height_m);
}

/* 120 fps in light noise: a within 3 SE (SE under 2.5 %), boundaries within two frames (17 ms). */
static void test_120fps(void)
{
    sim_track s;
    make_track(&s, 3, 1.5, 2.5, 1.2, 2.6);
    cam c = {120.0, 0.005, 0.0, 0.3, 0.20, 0.0, 0.5};
    capture cap;
    run(&s, &c, &cap, 10.0);
    int map[MAX_JUMPS];
    TEST_ASSERT_EQUAL_INT(3, match(&s, &cap, map));
    double a_true = 9.81 / 0.005;
    for (int k = 0; k < 3; k++) {
        const gs_ev_jump *j = &cap.jumps[map[k]];
        TEST_ASSERT_DOUBLE_WITHIN(3.0 * j->a_px_se_s2 + 0.002 * a_true, a_true, j->a_px_s2);
        TEST_ASSERT_TRUE(j->a_px_se_s2 < 0.025 * a_true);  /* theory: 1.3 % for the 0.25 s flight */
        TEST_ASSERT_DOUBLE_WITHIN(2.0 / 120.0, s.jumps[k].t_takeoff, gs_time_s_of_us(j->t_takeoff_us));
        TEST_ASSERT_DOUBLE_WITHIN(2.0 / 120.0, s.jumps[k].t_land, gs_time_s_of_us(j->t_land_us));
    }
}

/* Standing still with noise (and slow sway): nothing reported, summary unknown. */
static void test_no_flight(void)
{
    sim_track s;
    make_track(&s, 0, 0.0, 0.0, 0.0, 0.0);
    cam c = {30.0, 0.003, 0.0, 1.5, 0.20, 0.01, 0.0};
    capture cap;
    run(&s, &c, &cap, 30.0);
    TEST_ASSERT_EQUAL_INT(0, cap.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(0, cap.summary.n_jumps);
    TEST_ASSERT_TRUE(isnan(cap.summary.height_m));
    TEST_ASSERT_TRUE(isnan(cap.summary.ci95_lo_m));
}

/* Dropped frames inside flights (10 %) still give every flight. */
static void test_time_gaps(void)
{
    sim_track s;
    make_track(&s, 3, 1.5, 2.5, 2.0, 2.6);
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.size_min_m = 0.01f;
    static gs_pipeline p;
    capture cap;
    memset(&cap, 0, sizeof cap);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_POINT, storage, sizeof storage, on_event, &cap));
    gs_pipeline_set_track(&p, 7);  /* every event must carry its object's number */
    for (long i = 0; i < 300; i++) {
        if (i % 10 == 7) continue;  /* a dropped frame: its timestamp is simply absent */
        double t = i / 30.0;
        bool air;
        double u = track_u(&s, t, &air);
        TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_point(&p, t, 500.0f, (float)(600.0 - u / 0.003), 1.0f, 66.7f));
    }
    gs_pipeline_flush(&p);
    int map[MAX_JUMPS];
    TEST_ASSERT_EQUAL_INT(3, match(&s, &cap, map));
    for (int k = 0; k < 3; k++)
        TEST_ASSERT_DOUBLE_WITHIN(0.005 * 3270.0, 3270.0, cap.jumps[map[k]].a_px_s2);
    for (int e = 0; e < cap.n_jumps; e++) TEST_ASSERT_EQUAL_UINT32(7, cap.jumps[e].track);
    TEST_ASSERT_EQUAL_UINT32(7, cap.summary.track);
}

/* A ring too small for the flights at 120 fps (64 samples = 0.53 s): flights are
 * cut or dropped, never a crash or a read of evicted samples (run under ASan in CI). */
static void test_ring_smaller_than_a_flight(void)
{
    sim_track s;
    make_track(&s, 3, 1.5, 2.5, 2.4, 2.8);  /* 0.49-0.57 s flights */
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.ring_capacity = 64;
    cfg.size_min_m = 0.01f;
    static gs_pipeline p;
    capture cap;
    memset(&cap, 0, sizeof cap);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_POINT, storage, sizeof storage, on_event, &cap));
    for (long i = 0; i < 1200; i++) {
        double t = i / 120.0;
        bool air;
        double u = track_u(&s, t, &air);
        TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_point(&p, t, 500.0f, (float)(600.0 - u / 0.003), 1.0f, 66.7f));
    }
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_flush(&p));
    TEST_ASSERT_EQUAL_INT(1, cap.n_summary);
    /* whatever was accepted is still right */
    for (int e = 0; e < cap.n_jumps; e++)
        if (cap.jumps[e].accepted) TEST_ASSERT_DOUBLE_WITHIN(0.01 * 3270.0, 3270.0, cap.jumps[e].a_px_s2);
}

/* A daemon runs for hours: the ring keeps 32-bit microseconds that wrap every
 * 2^32 us = 71.6 min. Jumps around three wrap points (one flight straddles each)
 * are found and measured exactly as the same jumps near the start. */
static void set_jumps(sim_track *s, const double *take_s, int n)
{
    make_track(s, n, 0.0, 1.0, 2.0, 2.0);
    for (int k = 0; k < n; k++) {
        sim_jump *j = &s->jumps[k];
        j->t_takeoff = take_s[k];
        j->t_start = j->t_takeoff - s->cm_dur - j->v0 / s->a_prop;
        j->t_land = j->t_takeoff + 2.0 * j->v0 / s->g;
    }
}

static void test_hours_across_time_wraps(void)
{
    cam c = {30.0, 0.003, 0.0, 0.0, 0.20, 0.0, 0.37};
    const double base = c.phase / c.fps;     /* the first sample: the ring's time base */
    const double wrap_s = 4294.967296;       /* 2^32 us */
    const double rel[3] = {-2.7, -0.2, 2.3}; /* the middle flight spans the wrap */
    double take[9];
    for (int lap = 0; lap < 3; lap++)
        for (int k = 0; k < 3; k++) take[3 * lap + k] = base + wrap_s * (lap + 1) + rel[k];
    sim_track s;
    set_jumps(&s, take, 9);
    static capture cap_ref, cap;
    /* the same stream from t = 0 (wraps inside the flights) and from 2000 s (its
     * wraps fall 2000 s away from every jump): the same frames, the same events */
    run(&s, &c, &cap, 3.0 * wrap_s + 5.0);
    run_from(&s, &c, &cap_ref, 2000.0, 3.0 * wrap_s + 5.0);
    int map_ref[MAX_JUMPS], map[MAX_JUMPS];
    TEST_ASSERT_EQUAL_INT(9, match(&s, &cap_ref, map_ref));
    TEST_ASSERT_EQUAL_INT(9, match(&s, &cap, map));
    TEST_ASSERT_EQUAL_INT(9, cap.n_jumps);
    for (int k = 0; k < 9; k++) {
        const gs_ev_jump *j = &cap.jumps[map[k]], *r = &cap_ref.jumps[map_ref[k]];
        TEST_ASSERT_DOUBLE_WITHIN(1e-6 * r->a_px_s2, r->a_px_s2, j->a_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, r->height_m, j->height_m);
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, gs_time_s_of_us(r->t_takeoff_us), gs_time_s_of_us(j->t_takeoff_us));
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, gs_time_s_of_us(r->t_land_us), gs_time_s_of_us(j->t_land_us));
        TEST_ASSERT_EQUAL_UINT32(r->n_samples, j->n_samples);
        TEST_ASSERT_DOUBLE_WITHIN(0.003 * 0.20, 0.20, j->height_m);
    }
}

/* The flight's 32-bit sample indices are offsets from a base that moves every 2^30
 * samples: moved at any sample of a noisy stream (inside flights too), with ring indices
 * beyond 32 bits, the events are the same to the bit. */
static void test_index_base_moves(void)
{
    sim_track s;
    make_track(&s, 2, 1.5, 2.0, 2.0, 2.6);
    cam c = {60.0, 0.003, 3.0, 0.6, 0.20, 0.02, 0.37};
    static capture cap_ref, cap;
    rng_state = 0x9E3779B97F4A7C15ull;
    run(&s, &c, &cap_ref, 6.0);
    int map[MAX_JUMPS];
    TEST_ASSERT_EQUAL_INT(2, match(&s, &cap_ref, map));
    for (uint32_t after = 1; after < 360; after += 7) {
        g_ring_head = 0x100000000ull + 12345u;
        g_rebase_after = after;
        rng_state = 0x9E3779B97F4A7C15ull;
        run(&s, &c, &cap, 6.0);
        g_ring_head = 0;
        TEST_ASSERT_EQUAL_INT(cap_ref.n_jumps, cap.n_jumps);
        for (int e = 0; e < cap.n_jumps; e++) {
            const gs_ev_jump *j = &cap.jumps[e], *r = &cap_ref.jumps[e];
            TEST_ASSERT_EQUAL_INT64(r->t_takeoff_us, j->t_takeoff_us);
            TEST_ASSERT_EQUAL_INT64(r->t_land_us, j->t_land_us);
            TEST_ASSERT_EQUAL_MEMORY(&r->a_px_s2, &j->a_px_s2, sizeof j->a_px_s2);
            TEST_ASSERT_EQUAL_MEMORY(&r->height_m, &j->height_m, sizeof j->height_m);
            TEST_ASSERT_EQUAL_UINT32(r->n_samples, j->n_samples);
            TEST_ASSERT_EQUAL_UINT32(r->n_outliers, j->n_outliers);
            TEST_ASSERT_EQUAL(r->accepted, j->accepted);
            TEST_ASSERT_EQUAL_INT(r->reason, j->reason);
        }
    }
}

/* A pause longer than the ring's time span (35.8 min) in the middle of a
 * flight: the flight closes on what was seen, as on a pause within the span
 * (10 s, also a gap that ends the flight), and later jumps are found as then. */
static void run_with_pause(double pause_s, double cut_after_s, capture *cap)
{
    sim_track s;
    make_track(&s, 3, 1.5, 2.5, 2.0, 2.0);
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.size_min_m = 0.01f;
    static gs_pipeline p;
    memset(cap, 0, sizeof *cap);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_POINT, storage, sizeof storage, on_event, cap));
    double cut = s.jumps[1].t_takeoff + cut_after_s;
    bool first_after = true;
    for (long i = 0; i < 30 * 10; i++) {
        double tu = i / 30.0;
        bool air;
        double u = track_u(&s, tu, &air);
        double t = tu > cut ? tu + pause_s : tu;  /* the rest of the stream comes after the pause */
        cap->now = t;
        TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_point(&p, t, 500.0f, (float)(600.0 - u / 0.003), 1.0f, 66.7f));
        if (tu > cut && first_after) {
            first_after = false;
            /* beyond the span only the newest sample is left in the ring */
            TEST_ASSERT_EQUAL_UINT32(pause_s > 2147.5 ? 1u : 31u, gs_ring_count(&p.ring) > 31u ? 31u : gs_ring_count(&p.ring));
        }
    }
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_flush(&p));
}

static void test_pause_beyond_time_span(void)
{
    static const double cuts[] = {0.05, 0.3, 0.45};  /* rising, past the apex, near landing */
    for (size_t k = 0; k < sizeof cuts / sizeof cuts[0]; k++) {
        static capture near, far;
        run_with_pause(10.0, cuts[k], &near);
        run_with_pause(3000.0, cuts[k], &far);
        TEST_ASSERT_TRUE(near.n_jumps >= 2);  /* the first and the last jump at least */
        TEST_ASSERT_EQUAL_INT(near.n_jumps, far.n_jumps);
        for (int e = 0; e < near.n_jumps; e++) {
            const gs_ev_jump *a = &near.jumps[e], *b = &far.jumps[e];
            double sh = gs_time_s_of_us(a->t_takeoff_us) > 5.0 ? 2990.0 : 0.0;
            TEST_ASSERT_EQUAL_INT(a->accepted, b->accepted);
            TEST_ASSERT_EQUAL_UINT32(a->n_samples, b->n_samples);
            TEST_ASSERT_EQUAL_UINT32(a->warnings, b->warnings);
            TEST_ASSERT_DOUBLE_WITHIN(1e-6 * fabs(a->a_px_s2) + 1e-9, a->a_px_s2, b->a_px_s2);
            TEST_ASSERT_DOUBLE_WITHIN(1e-4, gs_time_s_of_us(a->t_takeoff_us) + sh, gs_time_s_of_us(b->t_takeoff_us));
        }
    }
}

/* The noisy stream of seed 99 again on a clock offset_us later: the same flights as ref, to
 * the bit, with every time shifted by exactly the offset. */
static void expect_shifted(const sim_track *s, const cam *c, const capture *ref, int64_t offset_us, double t_end)
{
    static capture cap;
    rng_state = 99;
    g_clock_us = offset_us;
    run(s, c, &cap, t_end);
    g_clock_us = 0;
    TEST_ASSERT_EQUAL_INT(ref->n_jumps, cap.n_jumps);
    for (int e = 0; e < ref->n_jumps; e++) {
        const gs_ev_jump *a = &ref->jumps[e], *b = &cap.jumps[e];
        TEST_ASSERT_TRUE(a->t_takeoff_us + offset_us == b->t_takeoff_us);
        TEST_ASSERT_TRUE(a->t_land_us + offset_us == b->t_land_us);
        TEST_ASSERT_TRUE(a->t_apex_us + offset_us == b->t_apex_us);
        TEST_ASSERT_EQUAL_MEMORY(&a->flight_time_s, &b->flight_time_s, sizeof a->flight_time_s);
        TEST_ASSERT_EQUAL_MEMORY(&a->a_px_s2, &b->a_px_s2, sizeof a->a_px_s2);
        TEST_ASSERT_EQUAL_MEMORY(&a->height_m, &b->height_m, sizeof a->height_m);
        TEST_ASSERT_EQUAL_MEMORY(&a->jump_height_m, &b->jump_height_m, sizeof a->jump_height_m);
        TEST_ASSERT_EQUAL_UINT32(a->n_samples, b->n_samples);
        TEST_ASSERT_EQUAL_UINT32(a->n_outliers, b->n_outliers);
        TEST_ASSERT_EQUAL(a->accepted, b->accepted);
        TEST_ASSERT_EQUAL_INT(a->reason, b->reason);
    }
}

/* Only time differences count: the same noisy stream on a clock 54 years later (Unix
 * time in microseconds) or before zero gives the same flights, to the bit, with every
 * time shifted by exactly the offset. */
static void test_clock_offset_invariance(void)
{
    static const int64_t offsets_us[] = {INT64_C(1700000000000000), -INT64_C(86400000000), GS_T_MAX_US / 2};
    sim_track s;
    make_track(&s, 3, 1.5, 2.5, 1.6, 2.4);
    cam c = {120.0, 0.004, 3.0, 0.4, 0.20, 0.01, 0.21};
    static capture ref;
    rng_state = 99;
    g_clock_us = 0;
    run(&s, &c, &ref, 9.0);
    TEST_ASSERT_EQUAL_INT(3, ref.n_jumps);
    for (size_t k = 0; k < sizeof offsets_us / sizeof offsets_us[0]; k++) expect_shifted(&s, &c, &ref, offsets_us[k], 9.0);
}

/* The flight's times inside its window are 32-bit offsets from a 64-bit base: clocks on
 * which each flight's middle (or its take-off, or its landing) falls where the time's low
 * 32 bits turn negative as an int32 (2^31 modulo 2^32) or wrap (2^32), near zero, beyond
 * 2^32 and below zero, give the same flights to the bit. (Local times taken from the low
 * words alone, or from a wrong base, order such a flight's samples wrongly.) */
static void test_flight_across_word_boundaries(void)
{
    static const int64_t words_us[] = {INT64_C(1) << 31, INT64_C(1) << 32, (INT64_C(1) << 31) + (INT64_C(77) << 32),
                                       -(INT64_C(1) << 31), -(INT64_C(5) << 32)};
    sim_track s;
    make_track(&s, 3, 1.5, 2.5, 1.6, 2.4);
    cam c = {120.0, 0.004, 3.0, 0.4, 0.20, 0.01, 0.21};
    static capture ref;
    rng_state = 99;
    g_clock_us = 0;
    run(&s, &c, &ref, 9.0);
    TEST_ASSERT_EQUAL_INT(3, ref.n_jumps);
    for (int e = 0; e < ref.n_jumps; e++) {
        const gs_ev_jump *j = &ref.jumps[e];
        int64_t at_us[3] = {j->t_takeoff_us + (j->t_land_us - j->t_takeoff_us) / 2, j->t_takeoff_us, j->t_land_us};
        for (size_t w = 0; w < sizeof words_us / sizeof words_us[0]; w++)
            for (int k = 0; k < 3; k++) expect_shifted(&s, &c, &ref, words_us[w] - at_us[k], 9.0);
    }
}

static void test_bad_calls(void)
{
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    static gs_pipeline p;
    capture cap;
    TEST_ASSERT_EQUAL(GS_ENOMEM, gs_pipeline_init(&p, &cfg, GS_LAYOUT_POINT, storage, 16, on_event, &cap));
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_init(&p, &cfg, (gs_layout)99, storage, sizeof storage, on_event, &cap));
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_POINT, storage, sizeof storage, on_event, &cap));
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_point(&p, 1.0, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_EORDER, gs_pipeline_push_point(&p, 0.5, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_push_point(&p, NAN, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_push_point(&p, INFINITY, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_ERANGE, gs_pipeline_push_point(&p, 1e300, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_push_point_us(&p, GS_T_NONE, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_ERANGE, gs_pipeline_push_point_us(&p, GS_T_MAX_US + 1, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_EORDER, gs_pipeline_push_point_us(&p, 999999, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_point_us(&p, 1000000, 1, 1, 1, NAN));  /* the same frame again */
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_flush(&p));
    TEST_ASSERT_EQUAL(GS_ESTATE, gs_pipeline_push_point(&p, 2.0, 1, 1, 1, NAN));
    TEST_ASSERT_EQUAL(GS_ESTATE, gs_pipeline_flush(&p));
    /* a configured span the flight's 32-bit times cannot hold (an unchecked configuration:
     * the checks allow 5 s) is refused; 67 s, the largest held, is taken */
    gs_core_config bad = cfg;
    bad.max_gap_s = NAN;
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_init(&p, &bad, GS_LAYOUT_POINT, storage, sizeof storage, on_event, &cap));
    bad = cfg;
    bad.max_flight_s = 68.0f;
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_init(&p, &bad, GS_LAYOUT_POINT, storage, sizeof storage, on_event, &cap));
    bad.max_flight_s = 67.0f;
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &bad, GS_LAYOUT_POINT, storage, sizeof storage, on_event, &cap));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_exact_track_30fps);
    RUN_TEST(test_front_end_judge);
    RUN_TEST(test_noisy_rolled);
    RUN_TEST(test_120fps);
    RUN_TEST(test_no_flight);
    RUN_TEST(test_time_gaps);
    RUN_TEST(test_ring_smaller_than_a_flight);
    RUN_TEST(test_hours_across_time_wraps);
    RUN_TEST(test_index_base_moves);
    RUN_TEST(test_pause_beyond_time_span);
    RUN_TEST(test_clock_offset_invariance);
    RUN_TEST(test_flight_across_word_boundaries);
    RUN_TEST(test_bad_calls);
    return UNITY_END();
}
