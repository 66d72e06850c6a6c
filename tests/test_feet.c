/* test_feet.c - the feet's take-off and landing (include/gravscale/gs_feet.h) against
 * synthetic truth: foot points that rest, roll up, leave the floor at a known instant with
 * a known speed and come back, sampled at 30, 60 and 120 fps with every phase of the
 * frames against the instant, clean and with jitter and lone outliers; a step down to a
 * lower floor; a turn of the up direction; bad calls. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gravscale/gs_feet.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

#define SIZE_PX 600.0           /* the body's stature in the image */
#define TOE_DELTA 0.009f        /* the toe stands this x stature above its rest when it leaves */
#define ANKLE_DELTA 0.064f
#define FLOOR_Y 900.0           /* image row of the resting point (y down) */

/* a deterministic normal variate (Box-Muller on a small LCG) */
static uint32_t g_seed = 12345u;
static double urand(void)
{
    g_seed = g_seed * 1664525u + 1013904223u;
    return ((double)(g_seed >> 8) + 0.5) / 16777216.0;
}
static double nrand(void) { return sqrt(-2.0 * log(urand())) * cos(6.283185307179586 * urand()); }

/* Height above the rest (px, up positive) of a point that leaves at t0 and lands at t1:
 * before t0 it rolls up smoothly to `delta_px` (the lift at the instant it leaves), then
 * flies ballistically (a = g in px) to land at t1 with the same lift, then comes down the
 * rest of the way at settle_px_s (a toe at once, as fast as it fell; an ankle with the heel,
 * slower) and rests; `drop_px` lowers the floor after the landing. */
typedef struct {
    double t0, t1, delta_px, v0_px_s, a_px_s2, drop_px, settle_px_s;
} foot_path;

static double height_px(const foot_path *p, double t)
{
    /* the roll-up before leaving: a quadratic from rest that reaches the flight's speed
     * as the foot leaves (the feet of people's jumps move smoothly through toe-off) */
    const double roll = 2.0 * p->delta_px / (0.5 * p->a_px_s2 * (p->t1 - p->t0));
    if (t < p->t0 - roll) return 0.0;
    if (t < p->t0) {
        double s = (t - (p->t0 - roll)) / roll;  /* 0..1 */
        return p->delta_px * s * s;
    }
    if (t < p->t1) {
        double tau = t - p->t0, T = p->t1 - p->t0;
        double v = 0.5 * p->a_px_s2 * T;  /* symmetric flight: back at the lift height at t1 */
        return p->delta_px + v * tau - 0.5 * p->a_px_s2 * tau * tau;
    }
    double h = p->delta_px - p->settle_px_s * (t - p->t1);
    return h > -p->drop_px ? h : -p->drop_px;
}

/* run one flight through the tracker; both points follow the same path (plus noise) */
#define NO_OUTLIER (-1000)

static void run_path(gs_feet *ft, const foot_path *p, double fps, double phase, double sigma_px,
                     int outlier_frame)
{
    int k0 = (int)ceil(p->t0 * fps - phase);  /* the first frame after the take-off */
    if ((k0 + phase) / fps <= p->t0) k0++;
    for (int k = 0; k < (int)(3.0 * fps); k++) {
        double t = (k + phase) / fps;
        float x[GS_FEET_POINTS], y[GS_FEET_POINTS];
        for (int i = 0; i < GS_FEET_POINTS; i++) {
            x[i] = (float)(800.0 + 60.0 * i);
            y[i] = (float)(FLOOR_Y - height_px(p, t) + sigma_px * nrand());
        }
        if (outlier_frame != NO_OUTLIER && k == k0 + outlier_frame)
            for (int i = 0; i < GS_FEET_POINTS; i++) y[i] -= 0.2f * (float)SIZE_PX;  /* both feet: the detector's slip */
        gs_feet_push(ft, (int64_t)llround(t * 1e6), x, y, 0.0, -1.0, SIZE_PX);
    }
    gs_feet_flush(ft);
}

static void toe_path(foot_path *p)
{
    p->t0 = 1.2371;
    p->t1 = 1.6522;
    p->delta_px = TOE_DELTA * SIZE_PX;
    p->a_px_s2 = 9.81 / (1.70 / SIZE_PX);  /* a 1.70 m body */
    p->v0_px_s = 0.5 * p->a_px_s2 * (p->t1 - p->t0);
    p->drop_px = 0.0;
    p->settle_px_s = p->v0_px_s;
}

/* every fps and phase: the take-off and the landing found, clean within 2 ms */
static void test_toes_clean_every_phase(void)
{
    const double fpss[] = {30.0, 60.0, 120.0};
    double worst = 0.0;
    for (int fi = 0; fi < 3; fi++) {
        for (int ph = 0; ph < 8; ph++) {
            gs_feet ft;
            gs_feet_init(&ft, TOE_DELTA, true);
            foot_path p;
            toe_path(&p);
            run_path(&ft, &p, fpss[fi], ph / 8.0, 0.0, NO_OUTLIER);
            float lv = NAN, on = NAN, before = NAN;
            int64_t t0 = gs_feet_takeoff(&ft, 1000000, 1450000, &lv);
            int64_t t1 = gs_feet_landing(&ft, 1450000, 2000000, &on, &before);
            char msg[96];
            snprintf(msg, sizeof msg, "%.0f fps phase %d: %lld %lld", fpss[fi], ph, (long long)t0, (long long)t1);
            TEST_ASSERT_TRUE_MESSAGE(t0 != GS_T_NONE && t1 != GS_T_NONE, msg);
            double e0 = t0 * 1e-6 - p.t0, e1 = t1 * 1e-6 - p.t1;
            if (fabs(e0) > worst) worst = fabs(e0);
            if (fabs(e1) > worst) worst = fabs(e1);
            if (ph == 0) printf("  %.0f fps: take-off %+.2f ms, landing %+.2f ms (phase 0)\n", fpss[fi], e0 * 1e3, e1 * 1e3);
            /* the toe accelerates up through its crossing: the chord between the frames
             * around it crosses early, by up to 0.3 of a frame interval */
            TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.15 / fpss[fi] + 0.0005, p.t0 - 0.15 / fpss[fi], t0 * 1e-6, msg);
            /* the touch follows the toe down from its last frame clear of the floor at its
             * speed there: late by up to a third of a frame interval */
            TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.17 / fpss[fi] + 0.001, p.t1 + 0.16 / fpss[fi], t1 * 1e-6, msg);
            TEST_ASSERT_FLOAT_WITHIN_MESSAGE(0.5f, (float)-FLOOR_Y, lv, msg);
            TEST_ASSERT_FLOAT_WITHIN_MESSAGE(0.5f, (float)-FLOOR_Y, on, msg);
            TEST_ASSERT_FALSE(gs_feet_airborne(&ft));
            TEST_ASSERT_FALSE(gs_feet_sank_since(&ft, 1000000));
        }
    }
    printf("toes, clean: worst boundary error %.2f ms\n", worst * 1e3);
}

/* jitter of 1.5 px (0.25 % of the body) at 30 fps: within 8 ms on average, no flight lost */
static void test_toes_jitter(void)
{
    double sum = 0.0;
    int n = 0;
    g_seed = 7u;
    for (int ph = 0; ph < 16; ph++) {
        gs_feet ft;
        gs_feet_init(&ft, TOE_DELTA, true);
        foot_path p;
        toe_path(&p);
        run_path(&ft, &p, 30.0, ph / 16.0, 1.5, NO_OUTLIER);
        int64_t t0 = gs_feet_takeoff(&ft, 1000000, 1450000, NULL);
        int64_t t1 = gs_feet_landing(&ft, 1450000, 2000000, NULL, NULL);
        TEST_ASSERT_TRUE(t0 != GS_T_NONE && t1 != GS_T_NONE);
        sum += fabs((t1 - t0) * 1e-6 - (p.t1 - p.t0));
        n++;
    }
    printf("toes, 1.5 px jitter at 30 fps: flight time MAE %.2f ms over %d phases\n", 1e3 * sum / n, n);
    TEST_ASSERT_TRUE(sum / n < 0.008);
}

/* a lone outlier in the frames around the take-off (120 px up, both feet) does not start the flight */
static void test_lone_outlier_is_ignored(void)
{
    int64_t clean = GS_T_NONE;
    for (int k = -3; k <= 2; k++) {  /* (-3: none, the reference; -1, 0: the frames either side of the crossing) */
        gs_feet ft;
        gs_feet_init(&ft, TOE_DELTA, true);
        foot_path p;
        toe_path(&p);
        run_path(&ft, &p, 30.0, 0.37, 0.0, k == -3 ? NO_OUTLIER : k);
        int64_t t0 = gs_feet_takeoff(&ft, 1000000, 1450000, NULL);
        printf("outlier %+d frames from the take-off: take-off %+.2f ms\n", k, (t0 * 1e-6 - p.t0) * 1e3);
        TEST_ASSERT_TRUE(t0 != GS_T_NONE);
        if (k == -3) clean = t0;
        if (k == -1 || k == 0) {
            /* a frame beside the crossing lost: the chord bridges two intervals of the
             * accelerating toe and crosses early, within one frame interval */
            TEST_ASSERT_DOUBLE_WITHIN(0.5 / 30.0, p.t0 - 0.5 / 30.0, t0 * 1e-6);
        } else {
            /* the same crossing as without it */
            TEST_ASSERT_INT64_WITHIN(1000, clean, t0);
            TEST_ASSERT_DOUBLE_WITHIN(0.15 / 30.0 + 0.0005, p.t0 - 0.15 / 30.0, t0 * 1e-6);
        }
    }
}

/* ankles (COCO-17): the landing is where the falling ankle passes its take-off level again */
/* a short stand (a clip that begins 0.4 s before the take-off, at 30 fps, every phase) with a
 * detector's jitter of 0.8 % of the stature on the toes (a phone clip's BlazePose toes): the
 * rest is learnt and the take-off found nearly every time, within a few ms on average */
static void test_short_stand_with_jitter(void)
{
    const int trials = 200;
    const double fps = 30.0, sigma = 0.008 * SIZE_PX;
    int found = 0;
    double sum_abs = 0.0;
    g_seed = 777u;
    for (int tr = 0; tr < trials; tr++) {
        gs_feet ft;
        gs_feet_init(&ft, TOE_DELTA, true);
        foot_path p;
        toe_path(&p);
        const double t_start = p.t0 - 0.4 + (tr % 8) / (8.0 * fps);
        for (int k = 0; k < (int)(1.2 * fps); k++) {
            double t = t_start + k / fps;
            float x[GS_FEET_POINTS], y[GS_FEET_POINTS];
            for (int i = 0; i < GS_FEET_POINTS; i++) {
                x[i] = (float)(800.0 + 60.0 * i);
                y[i] = (float)(FLOOR_Y - height_px(&p, t) + sigma * nrand());
            }
            gs_feet_push(&ft, (int64_t)llround(t * 1e6), x, y, 0.0, -1.0, SIZE_PX);
        }
        gs_feet_flush(&ft);
        float lv = NAN;
        int64_t t0 = gs_feet_takeoff(&ft, 0, 1450000, &lv);
        if (t0 == GS_T_NONE) continue;
        found++;
        sum_abs += fabs(t0 * 1e-6 - p.t0);
    }
    double mae_ms = found ? 1e3 * sum_abs / found : NAN;
    printf("  short stand, %.1f px jitter: take-off found %d/%d, MAE %.1f ms\n", sigma, found, trials, mae_ms);
    TEST_ASSERT_TRUE(found >= trials * 97 / 100);
    TEST_ASSERT_TRUE(mae_ms < 8.0);
}

static void test_ankles_recrossing(void)
{
    gs_feet ft;
    gs_feet_init(&ft, ANKLE_DELTA, false);
    foot_path p;
    toe_path(&p);
    p.delta_px = ANKLE_DELTA * SIZE_PX;
    p.settle_px_s = p.delta_px / 0.06;  /* the heel comes down in 60 ms */
    run_path(&ft, &p, 60.0, 0.5, 0.0, NO_OUTLIER);
    int64_t t0 = gs_feet_takeoff(&ft, 1000000, 1450000, NULL);
    int64_t t1 = gs_feet_landing(&ft, 1450000, 2000000, NULL, NULL);
    TEST_ASSERT_TRUE(t0 != GS_T_NONE && t1 != GS_T_NONE);
    TEST_ASSERT_DOUBLE_WITHIN(0.003, p.t0, t0 * 1e-6);
    TEST_ASSERT_DOUBLE_WITHIN(0.003, p.t1, t1 * 1e-6);
}

/* a step down to a floor 0.2 x stature lower: the landing's floor is below the one left,
 * and the point sank below its floor */
static void test_lower_floor(void)
{
    gs_feet ft;
    gs_feet_init(&ft, TOE_DELTA, true);
    foot_path p;
    toe_path(&p);
    p.drop_px = 0.2 * SIZE_PX;
    p.t1 = 1.75;  /* the ballistic path: it crosses the old floor before t1 and falls on */
    /* fall on in the air past t1 to the lower floor, where it stops */
    float x[GS_FEET_POINTS] = {800.0f, 860.0f}, y[GS_FEET_POINTS];
    double fps = 60.0;
    for (int k = 0; k < (int)(3.0 * fps); k++) {
        double t = k / fps, h;
        if (t < p.t1) h = height_px(&p, t);
        else {
            double tau = t - p.t0, v = 0.5 * p.a_px_s2 * (p.t1 - p.t0);
            h = p.delta_px + v * tau - 0.5 * p.a_px_s2 * tau * tau;
            if (h < -p.drop_px) h = -p.drop_px;
        }
        y[0] = y[1] = (float)(FLOOR_Y - h);
        gs_feet_push(&ft, (int64_t)llround(t * 1e6), x, y, 0.0, -1.0, SIZE_PX);
    }
    gs_feet_flush(&ft);
    float lv = NAN, on = NAN, before = NAN;
    TEST_ASSERT_TRUE(gs_feet_takeoff(&ft, 1000000, 1450000, &lv) != GS_T_NONE);
    TEST_ASSERT_TRUE(gs_feet_landing(&ft, 1450000, 2600000, &on, &before) != GS_T_NONE);
    TEST_ASSERT_TRUE(on < lv - 0.15f * (float)SIZE_PX);
    TEST_ASSERT_FLOAT_WITHIN(0.5f, lv, before);
    TEST_ASSERT_TRUE(gs_feet_low_px(&ft) < lv - 0.15f * (float)SIZE_PX);
}

/* one foot stays down (a step, not a flight): no take-off */
static void test_one_foot_down_is_no_flight(void)
{
    gs_feet ft;
    gs_feet_init(&ft, TOE_DELTA, true);
    foot_path p;
    toe_path(&p);
    double fps = 60.0;
    for (int k = 0; k < (int)(3.0 * fps); k++) {
        double t = k / fps;
        float x[GS_FEET_POINTS] = {800.0f, 860.0f};
        float y[GS_FEET_POINTS] = {(float)(FLOOR_Y - height_px(&p, t)), (float)FLOOR_Y};
        gs_feet_push(&ft, (int64_t)llround(t * 1e6), x, y, 0.0, -1.0, SIZE_PX);
    }
    gs_feet_flush(&ft);
    TEST_ASSERT_EQUAL_INT64(GS_T_NONE, gs_feet_takeoff(&ft, 1000000, 1450000, NULL));
    TEST_ASSERT_TRUE(gs_feet_resting_at(&ft, 1450000));  /* the other foot rests through the "flight" */
}

/* heights are measured along up: a turn of more than a degree forgets the levels (a new
 * epoch), a smaller one keeps them; unknown sizes, unknown and repeated times are ignored */
static void test_up_turn_and_bad_calls(void)
{
    gs_feet ft;
    gs_feet_init(&ft, TOE_DELTA, true);
    float x[GS_FEET_POINTS] = {800.0f, 860.0f}, y[GS_FEET_POINTS] = {900.0f, 900.0f};
    for (int k = 0; k < 30; k++) gs_feet_push(&ft, k * 33333, x, y, 0.0, -1.0, SIZE_PX);
    gs_feet_flush(&ft);
    TEST_ASSERT_FLOAT_WITHIN(0.01f, -900.0f, gs_feet_floor_px(&ft));
    uint16_t e = ft.epoch;
    double a = 0.5 * 3.14159265 / 180.0;  /* half a degree: kept */
    gs_feet_push(&ft, 30 * 33333, x, y, sin(a), -cos(a), SIZE_PX);
    TEST_ASSERT_EQUAL_UINT16(e, ft.epoch);
    a = 2.0 * 3.14159265 / 180.0;  /* two degrees: forgotten */
    gs_feet_push(&ft, 31 * 33333, x, y, sin(a), -cos(a), SIZE_PX);
    TEST_ASSERT_EQUAL_UINT16((uint16_t)(e + 1u), ft.epoch);
    gs_feet_flush(&ft);
    TEST_ASSERT_TRUE(isnan(gs_feet_floor_px(&ft)));
    uint32_t n = ft.n;
    gs_feet_push(&ft, 40 * 33333, x, y, sin(a), -cos(a), NAN);        /* no size */
    gs_feet_push(&ft, 41 * 33333, x, y, sin(a), -cos(a), 0.0);        /* no size */
    gs_feet_push(&ft, GS_T_NONE, x, y, sin(a), -cos(a), SIZE_PX);     /* no time */
    gs_feet_push(&ft, 20 * 33333, x, y, sin(a), -cos(a), SIZE_PX);    /* time went back */
    gs_feet_flush(&ft);
    TEST_ASSERT_EQUAL_UINT32(n, ft.n);
    float xn[GS_FEET_POINTS] = {NAN, 860.0f};
    gs_feet_push(&ft, 50 * 33333, xn, y, sin(a), -cos(a), SIZE_PX);   /* a missing point */
    gs_feet_flush(&ft);
    TEST_ASSERT_FALSE(gs_feet_seen_since(&ft, 49 * 33333));
    TEST_ASSERT_TRUE(gs_feet_seen_since(&ft, 51 * 33333));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_toes_clean_every_phase);
    RUN_TEST(test_toes_jitter);
    RUN_TEST(test_lone_outlier_is_ignored);
    RUN_TEST(test_short_stand_with_jitter);
    RUN_TEST(test_ankles_recrossing);
    RUN_TEST(test_lower_floor);
    RUN_TEST(test_one_foot_down_is_no_flight);
    RUN_TEST(test_up_turn_and_bad_calls);
    return UNITY_END();
}
