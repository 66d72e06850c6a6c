/* test_flight_close.c - a flight's close taken in steps over the frames after its landing
 * (GS_CLOSE_LAG_FRAMES) gives the lines of the close done at once. The reference is the
 * same pipeline with trace events on, whose closes run whole in the landing's frame (trace
 * events keep the stream's order); its trace lines are left out of the comparison. A
 * COCO-17 body (the feet wait with the samples) jumps in place; the streams end, pause or
 * wrap a small ring at every frame around a landing, jumps follow each other closely, and
 * seeds leave their widest core fit to the next frame. */
#include "unity.h"
#include "gravscale/gravscale.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define PI 3.14159265358979323846
#define OUT_MAX 200000
#define JUMPS_MAX 64

void setUp(void) {}
void tearDown(void) {}

static uint64_t rng;
static double urand(void)
{
    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}
static double nrand(void)
{
    double a = urand(), b = urand();
    return sqrt(-2.0 * log(a + 1e-300)) * cos(2.0 * PI * b);
}

/* standing COCO-17 skeleton: height fractions above the floor, lateral offsets (fractions of stature) */
static const double kp_h[17] = {0.91, 0.936, 0.936, 0.93, 0.93, 0.818, 0.818, 0.63, 0.63,
                                0.485, 0.485, 0.53, 0.53, 0.285, 0.285, 0.039, 0.039};
static const double kp_x[17] = {0.0, -0.02, 0.02, -0.045, 0.045, -0.11, 0.11, -0.13, 0.13,
                                -0.14, 0.14, -0.06, 0.06, -0.06, 0.06, -0.06, 0.06};

/* a session of jumps: each a countermovement, a flight of flight_s and a landing dip;
 * after the first, the next leaves contact_s after the landing (rebounds when short) */
typedef struct {
    double first_s, flight_s, contact_s;
    int n;
} jumps;

/* the COM's rise (m) at t, *air: in flight (the feet off the floor) */
static double rise_at(const jumps *j, double t, bool *air)
{
    *air = false;
    double start = j->first_s;
    for (int k = 0; k < j->n; k++) {
        double push = k == 0 ? 0.4 : j->contact_s;  /* the ground phase before this take-off */
        double t0 = start + push, t1 = t0 + j->flight_s;
        if (t < start) return 0.0;
        if (t < t0) return -0.10 * sin(PI * (t - start) / push);
        if (t < t1) {
            double x = t - t0, v0 = 4.905 * j->flight_s;
            *air = true;
            return v0 * x - 4.905 * x * x;
        }
        start = t1;
        if (k == j->n - 1 && t < t1 + 0.3) return -0.08 * sin(PI * (t - t1) / 0.3);
    }
    return 0.0;
}

typedef struct {
    int seed_waits;               /* frames that left a seed's widest core to the next */
    char out[OUT_MAX];
    size_t len;
    long frame;                   /* the frame being pushed */
    long jump_frame[JUMPS_MAX];   /* the frame each jump event left in */
    int n_jumps;
} capture;

static void on_event(void *ctx, const gs_event *ev)
{
    capture *c = (capture *)ctx;
    if (ev->type == GS_EV_STATE || ev->type == GS_EV_SAMPLE || ev->type == GS_EV_FIT) return;
    if (ev->type == GS_EV_JUMP && c->n_jumps < JUMPS_MAX) c->jump_frame[c->n_jumps++] = c->frame;
    char line[GS_EMIT_MAX];
    size_t n = gs_emit_json(ev, line, sizeof line);
    TEST_ASSERT_TRUE(n > 0 && c->len + n < OUT_MAX);
    memcpy(c->out + c->len, line, n);
    c->len += n;
    c->out[c->len] = '\0';
}

typedef struct {
    double fps;
    unsigned ring;        /* ring capacity */
    long frames;          /* frames pushed, then the stream ends */
    long pause_after;     /* after this frame a pause beyond the ring's time span (-1: none) */
    bool point;           /* the COM alone (the point layout: no feet, the contact model times the flight) */
    double noise_px;      /* keypoint noise, 1 sigma (0: 1 px) */
    double outliers;      /* the share of frames whose body is displaced by up to 40 px */
} stream;

static bool close_whole; /* run: every close whole in its landing's frame (gs_pipeline_set_close_whole) */

static double storage[(4096 * (sizeof(gs_sample) + sizeof(float))) / sizeof(double) + 8];

static void run(const jumps *j, const stream *st, bool at_once, capture *cap)
{
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.ring_capacity = st->ring;
    static gs_pipeline p;
    memset(cap, 0, sizeof *cap);
    cfg.size_min_m = 0.01f;
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, st->point ? GS_LAYOUT_POINT : GS_LAYOUT_COCO17, storage,
                                              sizeof storage, on_event, cap));
    gs_pipeline_set_trace(&p, at_once);
    gs_pipeline_set_close_whole(&p, close_whole);
    rng = 88172645463325252ull;
    const double stature_px = 600.0, q = 1.75 / stature_px, noise = st->noise_px > 0.0 ? st->noise_px : 1.0;
    int64_t pause_us = 0;
    for (long i = 0; i < st->frames; i++) {
        double t = (double)i / st->fps;
        bool air;
        double rise = rise_at(j, t, &air);
        cap->frame = i;
        if (st->point) {
            double com_h = 0.55 * 1.75 + rise;
            TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_point_us(&p, gs_time_us_of_s(t) + pause_us,
                                                               (float)(960.0 + 0.5 * nrand()),
                                                               (float)(900.0 - com_h / q + 0.5 * nrand()), 1.0f,
                                                               (float)(0.22 / q + 0.3 * nrand())));
            if (i == st->pause_after) pause_us = GS_RING_SPAN_US + 1000000;
            continue;
        }
        gs_kp kp[17];
        double ox = 0.0, oy = 0.0;
        if (urand() < st->outliers) {
            ox = 40.0 * (2.0 * urand() - 1.0);
            oy = 40.0 * (2.0 * urand() - 1.0);
        }
        for (int k = 0; k < 17; k++) {
            /* the ankles stay on the floor through the countermovement */
            double r = k >= 15 ? (air ? rise : 0.0) : rise;
            kp[k].x_px = (float)(960.0 + ox + kp_x[k] * stature_px + noise * nrand());
            kp[k].y_px = (float)(900.0 + oy - (kp_h[k] * 1.75 + r) / q + noise * nrand());
            kp[k].c = 0.9f;
        }
        TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_keypoints_us(&p, gs_time_us_of_s(t) + pause_us, kp));
#if GS_CLOSE_LAG_FRAMES > 0
        cap->seed_waits += p.flight.close.stage == GS_CLOSE_SEED;
#endif
        if (i == st->pause_after) pause_us = GS_RING_SPAN_US + 1000000;
    }
    cap->frame = st->frames;
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_flush(&p));
}

/* the same lines as the close at once; returns the largest delay of a jump event in frames */
static long compare(const jumps *j, const stream *st)
{
    static capture ref, got;
    run(j, st, true, &ref);
    run(j, st, false, &got);
    TEST_ASSERT_EQUAL_STRING(ref.out, got.out);
    TEST_ASSERT_EQUAL_INT(ref.n_jumps, got.n_jumps);
    long delay = 0;
    for (int k = 0; k < got.n_jumps; k++) {
        long d = got.jump_frame[k] - ref.jump_frame[k];
        TEST_ASSERT_TRUE(d >= 0 && d <= GS_CLOSE_LAG_FRAMES);
        if (d > delay) delay = d;
    }
    return delay;
}

/* the frame each jump event of the close at once left in */
static int landings(const jumps *j, const stream *st, long *frame)
{
    static capture ref;
    run(j, st, true, &ref);
    for (int k = 0; k < ref.n_jumps; k++) frame[k] = ref.jump_frame[k];
    return ref.n_jumps;
}

/* Several jumps at 120 fps: the closes spread over frames, the lines unchanged. */
static void test_jumps_120fps(void)
{
    jumps j = {1.0, 0.5, 1.2, 4};
    stream st = {120.0, 512, (long)(8.0 * 120.0), -1, false, 0.0, 0.0};
    long frame[JUMPS_MAX];
    TEST_ASSERT_EQUAL_INT(4, landings(&j, &st, frame));
    TEST_ASSERT_TRUE(compare(&j, &st) > 0);  /* the closes did wait */
}

/* gs_pipeline_set_close_whole: the same lines, each jump event in its landing's frame. */
static void test_close_whole_in_landing_frame(void)
{
    jumps j = {1.0, 0.5, 1.2, 4};
    stream st = {120.0, 512, (long)(8.0 * 120.0), -1, false, 0.0, 0.0};
    static capture ref, got;
    run(&j, &st, true, &ref);
    close_whole = true;
    run(&j, &st, false, &got);
    close_whole = false;
    TEST_ASSERT_EQUAL_STRING(ref.out, got.out);
    TEST_ASSERT_EQUAL_INT(4, got.n_jumps);
    for (int k = 0; k < got.n_jumps; k++) TEST_ASSERT_EQUAL_INT(ref.jump_frame[k], got.jump_frame[k]);
}

/* The stream ends at every frame from the first landing's detection to a few past it
 * (a pending close finishes with the flush, before the summary). */
static void test_stream_ends_while_pending(void)
{
    jumps j = {1.0, 0.5, 1.2, 2};
    stream st = {120.0, 512, (long)(5.0 * 120.0), -1, false, 0.0, 0.0};
    long frame[JUMPS_MAX];
    TEST_ASSERT_EQUAL_INT(2, landings(&j, &st, frame));
    long delayed = 0;
    for (long end = frame[0] - 2; end <= frame[0] + GS_CLOSE_LAG_FRAMES + 2; end++) {
        stream cut = st;
        cut.frames = end + 1;
        delayed += compare(&j, &cut);
    }
    TEST_ASSERT_TRUE(delayed > 0);
}

/* Rebounds: the next take-off soon after each landing, at 30, 60 and 120 fps (the next
 * flight's samples wait while the close is pending, then are examined in order). */
static void test_jumps_close_together(void)
{
    static const double fps[] = {30.0, 60.0, 120.0};
    static const double contact_s[] = {0.15, 0.25, 0.4};
    for (unsigned a = 0; a < sizeof fps / sizeof fps[0]; a++)
        for (unsigned b = 0; b < sizeof contact_s / sizeof contact_s[0]; b++) {
            jumps j = {1.0, 0.45, contact_s[b], 5};
            stream st = {fps[a], 512, (long)(6.0 * fps[a]), -1, false, 0.0, 0.0};
            compare(&j, &st);
        }
}

/* A pause beyond the ring's time span (gs_flight_break) at every frame around a landing. */
static void test_break_after_landing(void)
{
    jumps j = {1.0, 0.5, 1.2, 2};
    stream st = {120.0, 512, (long)(5.0 * 120.0), -1, false, 0.0, 0.0};
    long frame[JUMPS_MAX];
    TEST_ASSERT_EQUAL_INT(2, landings(&j, &st, frame));
    for (long at = frame[0] - 2; at <= frame[0] + GS_CLOSE_LAG_FRAMES + 2; at++) {
        stream cut = st;
        cut.pause_after = at;
        compare(&j, &cut);
    }
}

/* A ring barely longer than a flight: a close that the ring would overtake finishes at once. */
/* The COM alone: its contact samples past the landing are those the ring held at the
 * landing (the close reads no sample pushed after it), the stream ending at every frame around it. */
static void test_point_layout(void)
{
    jumps j = {1.0, 0.5, 0.3, 3};
    stream st = {120.0, 512, (long)(5.0 * 120.0), -1, true, 0.0, 0.0};
    long frame[JUMPS_MAX];
    TEST_ASSERT_EQUAL_INT(3, landings(&j, &st, frame));
    TEST_ASSERT_TRUE(compare(&j, &st) > 0);
    for (long end = frame[0] - 2; end <= frame[0] + GS_CLOSE_LAG_FRAMES + 2; end++) {
        stream cut = st;
        cut.frames = end + 1;
        compare(&j, &cut);
    }
}

/* Frames whose body jumps by up to 40 px (5-30 %): seeds whose narrower cores do not hold try
 * the widest in the next frame (the lines as when all are tried at once). */
static void test_seed_widest_core_next_frame(void)
{
    static capture got;
    static const double outliers[] = {0.05, 0.1, 0.2, 0.3};
    static const double flight_s[] = {0.25, 0.35, 0.45};
    int waits = 0;
    for (unsigned a = 0; a < sizeof outliers / sizeof outliers[0]; a++)
        for (unsigned b = 0; b < sizeof flight_s / sizeof flight_s[0]; b++) {
            jumps j = {1.0, flight_s[b], 1.0, 3};
            stream st = {120.0, 512, (long)(6.0 * 120.0), -1, false, 2.0, outliers[a]};
            compare(&j, &st);
            run(&j, &st, false, &got);
            waits += got.seed_waits;
        }
    TEST_ASSERT_TRUE(waits > 0);  /* the widest cores did wait */
}

static void test_small_ring(void)
{
    static const unsigned ring[] = {64, 128};
    static const double flight_s[] = {0.4, 0.45, 0.5};
    for (unsigned k = 0; k < sizeof ring / sizeof ring[0]; k++)
        for (unsigned m = 0; m < sizeof flight_s / sizeof flight_s[0]; m++)
            for (int point = 0; point < 2; point++) {
                jumps j = {1.0, flight_s[m], 0.3, 3};
                stream st = {120.0, ring[k], (long)(4.0 * 120.0), -1, point != 0, 0.0, 0.0};
                compare(&j, &st);
            }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_jumps_120fps);
    RUN_TEST(test_close_whole_in_landing_frame);
    RUN_TEST(test_stream_ends_while_pending);
    RUN_TEST(test_jumps_close_together);
    RUN_TEST(test_break_after_landing);
    RUN_TEST(test_point_layout);
    RUN_TEST(test_seed_widest_core_next_frame);
    RUN_TEST(test_small_ring);
    return UNITY_END();
}
