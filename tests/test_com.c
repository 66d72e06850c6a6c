/* test_com.c - gs_com against synthetic skeletons built here from published
 * landmark heights (Drillis & Contini 1966, Winter's segment lengths): stature
 * in px at several rolls, scales and views; body axis; uprightness standing and
 * squatting; COM on the mid-line at 0.55-0.58 of stature; behaviour when each
 * keypoint goes missing; mass tables; invalid arguments; names. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "unity.h"
#include "gravscale/gs_com.h"

void setUp(void) {}
void tearDown(void) {}

#define DEG (3.14159265358979323846 / 180.0)

/* Test-side keypoint names (person's left/right), mapped to each layout below. */
enum {
    NOSE, LEYE, REYE, LEAR, REAR, LSHO, RSHO, LELB, RELB, LWRI, RWRI,
    LHIP, RHIP, LKNE, RKNE, LANK, RANK, LHEEL, RHEEL, LTOE, RTOE,
    LPINKY, RPINKY, LINDEX, RINDEX, NPTS
};
static const int coco_of[NPTS] = { 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16,
                                   -1, -1, -1, -1, -1, -1, -1, -1 };
static const int blaze_of[NPTS] = { 0, 2, 5, 7, 8, 11, 12, 13, 14, 15, 16, 23, 24, 25, 26, 27, 28,
                                    29, 30, 31, 32, 17, 18, 19, 20 };

/* Body frame in units of stature: X to the person's left, Y up from the floor, Z forward. */
typedef struct { double x, y, z; } p3;

/* Standing adult, arms hanging; heights from Drillis & Contini / Winter Fig. 4.1. */
static void standing(p3 b[NPTS])
{
    b[NOSE] = (p3){ 0.0, 0.910, 0.10 };
    b[LEYE] = (p3){ 0.032, 0.936, 0.08 };  b[REYE] = (p3){ -0.032, 0.936, 0.08 };
    b[LEAR] = (p3){ 0.075, 0.927, 0.0 };   b[REAR] = (p3){ -0.075, 0.927, 0.0 };
    b[LSHO] = (p3){ 0.10, 0.818, 0.0 };    b[RSHO] = (p3){ -0.10, 0.818, 0.0 };
    b[LELB] = (p3){ 0.11, 0.630, 0.0 };    b[RELB] = (p3){ -0.11, 0.630, 0.0 };
    b[LWRI] = (p3){ 0.11, 0.485, 0.0 };    b[RWRI] = (p3){ -0.11, 0.485, 0.0 };
    b[LPINKY] = (p3){ 0.11, 0.438, -0.02 }; b[RPINKY] = (p3){ -0.11, 0.438, -0.02 };
    b[LINDEX] = (p3){ 0.11, 0.438, 0.02 };  b[RINDEX] = (p3){ -0.11, 0.438, 0.02 };
    b[LHIP] = (p3){ 0.06, 0.530, 0.0 };    b[RHIP] = (p3){ -0.06, 0.530, 0.0 };
    b[LKNE] = (p3){ 0.055, 0.285, 0.0 };   b[RKNE] = (p3){ -0.055, 0.285, 0.0 };
    b[LANK] = (p3){ 0.05, 0.039, 0.0 };    b[RANK] = (p3){ -0.05, 0.039, 0.0 };
    b[LHEEL] = (p3){ 0.05, 0.015, -0.04 }; b[RHEEL] = (p3){ -0.05, 0.015, -0.04 };
    b[LTOE] = (p3){ 0.06, 0.012, 0.15 };   b[RTOE] = (p3){ -0.06, 0.012, 0.15 };
}

/* Deep squat seen from any side: knees forward, hips back and down, trunk leaning. */
static void squat(p3 b[NPTS])
{
    standing(b);
    for (int s = 0; s < 2; s++) {
        double x = s ? -1.0 : 1.0;
        b[s ? RKNE : LKNE] = (p3){ x * 0.09, 0.234, 0.15 };
        b[s ? RHIP : LHIP] = (p3){ x * 0.06, 0.284, -0.09 };
    }
    double dz = 0.288 * sin(30 * DEG), dy = 0.288 * cos(30 * DEG);
    double lift = 0.284 + dy - 0.818;  /* shift of everything above the hips */
    const int upper[] = { NOSE, LEYE, REYE, LEAR, REAR, LSHO, RSHO, LELB, RELB, LWRI, RWRI,
                          LPINKY, RPINKY, LINDEX, RINDEX };
    for (size_t k = 0; k < sizeof upper / sizeof upper[0]; k++) {
        b[upper[k]].y += lift;
        b[upper[k]].z += -0.09 + dz;
    }
}

typedef struct {
    double yaw_deg;   /* 0 frontal, 90 lateral */
    double roll_deg;  /* camera roll */
    double scale;     /* px per stature */
    double cx, cy;    /* image position of the floor point below the body */
} view;

/* Orthographic projection into image pixels (y down). */
static void project(const p3 b[NPTS], view v, gs_layout layout, gs_kp *kp)
{
    size_t n = gs_layout_kp_count(layout);
    for (size_t i = 0; i < n; i++) {
        kp[i] = (gs_kp){ 0.0f, 0.0f, 0.0f };
    }
    double cy = cos(v.yaw_deg * DEG), sy = sin(v.yaw_deg * DEG);
    double cr = cos(v.roll_deg * DEG), sr = sin(v.roll_deg * DEG);
    for (int k = 0; k < NPTS; k++) {
        int i = layout == GS_LAYOUT_COCO17 ? coco_of[k] : blaze_of[k];
        if (i < 0) {
            continue;
        }
        double u = b[k].x * cy + b[k].z * sy, h = b[k].y;
        kp[i].x_px = (float)(v.cx + v.scale * (u * cr - h * sr));
        kp[i].y_px = (float)(v.cy - v.scale * (u * sr + h * cr));
        kp[i].c = 0.9f;
    }
}

/* Unit "up" of the body in the image for a view. */
static void view_up(view v, double *ux, double *uy)
{
    *ux = -sin(v.roll_deg * DEG);
    *uy = -cos(v.roll_deg * DEG);
}

/* COM height above the floor and lateral offset from the mid-line, in statures. */
static void com_in_body(const gs_com_out *o, view v, double *height, double *lateral)
{
    double ux, uy;
    view_up(v, &ux, &uy);
    double dx = o->x_px - v.cx, dy = o->y_px - v.cy;
    *height = (dx * ux + dy * uy) / v.scale;
    *lateral = (dx * -uy + dy * ux) / v.scale;
}

static gs_com_out run(gs_layout layout, gs_mass_table t, gs_stature_method m, const gs_kp *kp)
{
    gs_com_out o;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_com_compute(layout, t, m, 0.3f, kp, &o));
    return o;
}

static const view k_views[] = {
    { 0, 0, 400, 640, 900 },
    { 0, 12, 250, 300, 700 },
    { 0, -25, 900, 1000, 1800 },
    { 0, 90, 500, 100, 400 },
    { 0, 180, 333, 500, 100 },
    { 30, 5, 600, 700, 1000 },
    { 90, -8, 450, 600, 950 },
    { 90, 45, 120, 200, 300 },
};
#define N_VIEWS (sizeof k_views / sizeof k_views[0])

static void test_stature_axis_upright_standing(void)
{
    p3 b[NPTS];
    standing(b);
    gs_kp kp[33];
    const gs_layout layouts[] = { GS_LAYOUT_COCO17, GS_LAYOUT_BLAZEPOSE33 };
    for (size_t l = 0; l < 2; l++) {
        for (size_t i = 0; i < N_VIEWS; i++) {
            project(b, k_views[i], layouts[l], kp);
            gs_com_out o = run(layouts[l], GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
            double ux, uy;
            view_up(k_views[i], &ux, &uy);
            /* stature within 0.5 % of the truth */
            TEST_ASSERT_DOUBLE_WITHIN(0.005 * k_views[i].scale, k_views[i].scale, o.stature_px);
            /* axis within 3 degrees (profile landmarks are not stacked exactly) */
            TEST_ASSERT_TRUE(o.up_x * ux + o.up_y * uy > cos(3 * DEG));
            TEST_ASSERT_DOUBLE_WITHIN(1e-5, 1.0, hypot(o.up_x, o.up_y));
            TEST_ASSERT_TRUE(o.upright >= 0.95f);
            TEST_ASSERT_TRUE(o.w > 0.5f);
        }
    }
}

static void test_nose_ankle_117_is_the_paper_rule(void)
{
    p3 b[NPTS];
    standing(b);
    gs_kp kp[17];
    view v = { 0, 10, 500, 400, 800 };
    project(b, v, GS_LAYOUT_COCO17, kp);
    gs_com_out o = run(GS_LAYOUT_COCO17, GS_MASS_CLAUSER, GS_STATURE_NOSE_ANKLE_117, kp);
    double ax = 0.5 * (kp[15].x_px + kp[16].x_px), ay = 0.5 * (kp[15].y_px + kp[16].y_px);
    double expect = 1.17 * hypot(kp[0].x_px - ax, kp[0].y_px - ay);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * expect, expect, o.stature_px);
    /* On this skeleton (nose at 0.910, ankles at 0.039) 1.17 over-reads by 1.9 %. */
    TEST_ASSERT_DOUBLE_WITHIN(0.005, 1.17 * (0.910 - 0.039), o.stature_px / v.scale);
    /* Nose missing -> unknown; the anthro method still works without the nose. */
    kp[0].c = 0.0f;
    o = run(GS_LAYOUT_COCO17, GS_MASS_CLAUSER, GS_STATURE_NOSE_ANKLE_117, kp);
    TEST_ASSERT_TRUE(isnan(o.stature_px));
    o = run(GS_LAYOUT_COCO17, GS_MASS_CLAUSER, GS_STATURE_ANTHRO, kp);
    TEST_ASSERT_DOUBLE_WITHIN(0.005 * v.scale, v.scale, o.stature_px);
}

static void test_stature_unknown_without_head_or_feet(void)
{
    p3 b[NPTS];
    standing(b);
    gs_kp kp[17];
    view v = { 0, 0, 500, 400, 800 };
    project(b, v, GS_LAYOUT_COCO17, kp);
    for (int k = 0; k < 5; k++) kp[k].c = 0.0f;
    gs_com_out o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    TEST_ASSERT_TRUE(isnan(o.stature_px));
    /* axis falls back to hip centre -> shoulder centre */
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, 0.0, o.up_x);
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, -1.0, o.up_y);
    TEST_ASSERT_FALSE(isnan(o.x_px));  /* the COM survives without the head */
    project(b, v, GS_LAYOUT_COCO17, kp);
    kp[15].c = kp[16].c = 0.0f;
    o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    TEST_ASSERT_TRUE(isnan(o.stature_px));
    TEST_ASSERT_TRUE(isnan(o.upright));  /* no complete leg */
}

static void test_upright_squat_is_zero(void)
{
    p3 b[NPTS];
    squat(b);
    gs_kp kp[33];
    const double yaws[] = { 0, 45, 90 };
    for (size_t i = 0; i < 3; i++) {
        view v = { yaws[i], 3, 500, 400, 800 };
        project(b, v, GS_LAYOUT_COCO17, kp);
        gs_com_out o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
        TEST_ASSERT_TRUE_MESSAGE(o.upright <= 0.05f, "squat must not look upright");
        project(b, v, GS_LAYOUT_BLAZEPOSE33, kp);
        o = run(GS_LAYOUT_BLAZEPOSE33, GS_MASS_DEMPSTER, GS_STATURE_ANTHRO, kp);
        TEST_ASSERT_TRUE(o.upright <= 0.05f);
    }
    /* a slight knee bend (knee angle ~160 deg) is in between */
    standing(b);
    b[LKNE].z = b[RKNE].z = 0.043;
    view v = { 90, 0, 500, 400, 800 };
    project(b, v, GS_LAYOUT_COCO17, kp);
    gs_com_out o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    TEST_ASSERT_TRUE(o.upright > 0.2f && o.upright < 0.8f);
}

/* Standing COM: 0.55-0.57 of stature in the literature; we allow 0.545-0.585
 * since the tables differ (Dempster's heavy trunk puts it highest). */
static void test_com_standing_height_and_midline(void)
{
    p3 b[NPTS];
    standing(b);
    gs_kp kp[33];
    const gs_mass_table tables[] = { GS_MASS_DELEVA, GS_MASS_CLAUSER, GS_MASS_DEMPSTER };
    const gs_layout layouts[] = { GS_LAYOUT_COCO17, GS_LAYOUT_BLAZEPOSE33 };
    for (size_t t = 0; t < 3; t++) {
        for (size_t l = 0; l < 2; l++) {
            for (size_t i = 0; i < N_VIEWS; i++) {
                project(b, k_views[i], layouts[l], kp);
                gs_com_out o = run(layouts[l], tables[t], GS_STATURE_ANTHRO, kp);
                double h, lat;
                com_in_body(&o, k_views[i], &h, &lat);
                TEST_ASSERT_TRUE_MESSAGE(h > 0.545 && h < 0.585, gs_mass_table_name(tables[t]));
                if (k_views[i].yaw_deg == 0) {
                    TEST_ASSERT_DOUBLE_WITHIN(1e-4, 0.0, lat);
                }
            }
        }
    }
}

/* Raising both arms overhead moves the COM up by about
 * 2 x (upper arm + forearm + hand) mass x their COM rise: ~0.035 stature. */
static void test_com_follows_arms(void)
{
    p3 b[NPTS];
    standing(b);
    gs_kp kp[17];
    view v = { 0, 0, 1000, 500, 1100 };
    project(b, v, GS_LAYOUT_COCO17, kp);
    gs_com_out down = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    for (int s = 0; s < 2; s++) {
        double x = s ? -0.10 : 0.10;
        b[s ? RELB : LELB] = (p3){ x, 0.818 + 0.188, 0 };
        b[s ? RWRI : LWRI] = (p3){ x, 0.818 + 0.188 + 0.145, 0 };
    }
    project(b, v, GS_LAYOUT_COCO17, kp);
    gs_com_out up = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    double hd, hu, lat;
    com_in_body(&down, v, &hd, &lat);
    com_in_body(&up, v, &hu, &lat);
    /* expected rise from the table: upper arm, forearm and hand segment COM rises */
    double mu = gs_mass_fraction(GS_MASS_DELEVA, GS_SEG_UPPER_ARM);
    double mf = gs_mass_fraction(GS_MASS_DELEVA, GS_SEG_FOREARM);
    double mh = gs_mass_fraction(GS_MASS_DELEVA, GS_SEG_HAND);
    double cu = 0.5763, cf = 0.4567, eh = 0.24;
    double rise_u = 2 * cu * 0.188;                   /* 0.818 -/+ cu x 0.188 */
    double rise_f = (1.006 - 0.630) + 2 * cf * 0.145; /* elbow rise + flip about it */
    double rise_h = (1.151 - 0.485) + 2 * eh * 0.145; /* wrist rise + flip beyond it */
    double expect = 2 * (mu * rise_u + mf * rise_f + mh * rise_h);
    TEST_ASSERT_DOUBLE_WITHIN(0.0005, expect, hu - hd);
}

/* Drop each keypoint in turn: COM moves little, w never rises. */
static void drop_each(gs_layout layout, const p3 b[NPTS], view v, double bound, double *worst)
{
    gs_kp kp[33];
    size_t n = gs_layout_kp_count(layout);
    project(b, v, layout, kp);
    gs_com_out full = run(layout, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    *worst = 0;
    for (size_t k = 0; k < n; k++) {
        project(b, v, layout, kp);
        kp[k].c = 0.1f;  /* below min_conf 0.3 */
        gs_com_out o = run(layout, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
        TEST_ASSERT_FALSE(isnan(o.x_px));
        double d = hypot(o.x_px - full.x_px, o.y_px - full.y_px) / v.scale;
        if (d > *worst) *worst = d;
        if (getenv("GS_DEBUG")) printf("layout %d yaw %.0f drop %zu: shift %.5f w %.3f/%.3f\n", (int)layout, v.yaw_deg, k, d, o.w, full.w);
        TEST_ASSERT_TRUE_MESSAGE(d < bound, "COM shift when one keypoint is missing");
        TEST_ASSERT_TRUE(o.w <= full.w + 1e-6f);
    }
}

static void test_missing_each_keypoint_bounded(void)
{
    p3 b[NPTS];
    double worst;
    standing(b);
    /* Symmetric frontal pose: mirroring makes a lost limb joint almost free. */
    drop_each(GS_LAYOUT_COCO17, b, (view){ 0, 7, 500, 400, 800 }, 0.004, &worst);
    drop_each(GS_LAYOUT_BLAZEPOSE33, b, (view){ 0, -7, 500, 400, 800 }, 0.004, &worst);
    /* Lateral view: the other side's limb is copied. */
    drop_each(GS_LAYOUT_COCO17, b, (view){ 90, 0, 500, 400, 800 }, 0.02, &worst);
    /* Asymmetric pose (one arm up, one knee raised) seen from the front. */
    b[LELB] = (p3){ 0.10, 1.006, 0 };
    b[LWRI] = (p3){ 0.10, 1.151, 0 };
    b[RKNE] = (p3){ -0.06, 0.45, 0.2 };
    b[RANK] = (p3){ -0.06, 0.25, 0.1 };
    drop_each(GS_LAYOUT_COCO17, b, (view){ 0, 0, 500, 400, 800 }, 0.03, &worst);
    drop_each(GS_LAYOUT_COCO17, b, (view){ 90, 0, 500, 400, 800 }, 0.03, &worst);
    drop_each(GS_LAYOUT_BLAZEPOSE33, b, (view){ 66, 0, 500, 400, 800 }, 0.03, &worst);
}

static void test_missing_trunk_gives_zero_weight(void)
{
    p3 b[NPTS];
    standing(b);
    gs_kp kp[17];
    view v = { 0, 0, 500, 400, 800 };
    static const struct { int a, b; bool usable; } rows[] = {
        { 5, 6, false },   /* both shoulders */
        { 11, 12, false }, /* both hips */
        { 5, 12, true },   /* one of each: centres from the lone points */
        { 5, 5, true },    /* one shoulder: rebuilt from the hip pair */
        { 12, 12, true },  /* one hip: rebuilt from the shoulder pair */
    };
    project(b, v, GS_LAYOUT_COCO17, kp);
    gs_com_out full = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        project(b, v, GS_LAYOUT_COCO17, kp);
        kp[rows[r].a].c = 0.0f;
        kp[rows[r].b].c = 0.0f;
        gs_com_out o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
        if (rows[r].usable) {
            TEST_ASSERT_TRUE(o.w > 0.0f && o.w < full.w);
            TEST_ASSERT_TRUE(hypot(o.x_px - full.x_px, o.y_px - full.y_px) < 0.03 * v.scale);
        } else {
            TEST_ASSERT_EQUAL_FLOAT(0.0f, o.w);
            TEST_ASSERT_TRUE(isnan(o.x_px) && isnan(o.y_px));
            TEST_ASSERT_FALSE(isnan(o.stature_px));  /* head and feet still give the size */
        }
    }
    /* nothing visible at all */
    memset(kp, 0, sizeof kp);
    gs_com_out o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, o.w);
    TEST_ASSERT_TRUE(isnan(o.x_px) && isnan(o.stature_px) && isnan(o.up_x) && isnan(o.upright));
}

static void test_weight_tracks_confidence(void)
{
    p3 b[NPTS];
    standing(b);
    gs_kp kp[17];
    view v = { 0, 0, 500, 400, 800 };
    project(b, v, GS_LAYOUT_COCO17, kp);
    gs_com_out o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    /* everything seen at c = 0.9: w = 1^2 x 0.9 */
    TEST_ASSERT_DOUBLE_WITHIN(1e-5, 0.9, o.w);
    for (int k = 0; k < 17; k++) kp[k].c = 0.5f;
    o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    TEST_ASSERT_DOUBLE_WITHIN(1e-5, 0.5, o.w);
    /* Lateral view, left knee lost: copied from the right leg, the three
     * segments that use it count half: w = (1 - (thigh + shank + foot)/2)^2 x c. */
    double mt = gs_mass_fraction(GS_MASS_DELEVA, GS_SEG_THIGH);
    double ms = gs_mass_fraction(GS_MASS_DELEVA, GS_SEG_SHANK);
    double mf = gs_mass_fraction(GS_MASS_DELEVA, GS_SEG_FOOT);
    view lat = { 90, 0, 500, 400, 800 };
    project(b, lat, GS_LAYOUT_COCO17, kp);
    kp[13].c = 0.0f;
    o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    double kept = 1 - 0.5 * (mt + ms + mf);
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, kept * kept * 0.9, o.w);
    /* Both knees lost: nothing to mirror from, so both thighs and shanks are
     * dropped and the rest renormalised; the feet sit at the ankles, counted half.
     * A COM that lacks whole segments is biased, so the frame nearly drops out (x 0.02). */
    project(b, lat, GS_LAYOUT_COCO17, kp);
    kp[13].c = kp[14].c = 0.0f;
    o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    kept = 1 - 2 * (mt + ms + 0.5 * mf);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, kept * kept * 0.9 * 0.02, o.w);
}

static void test_mass_tables(void)
{
    /* published values, % of body mass, one side (de Leva: mean of M and F) */
    static const struct { gs_mass_table t; double pct[GS_SEG_COUNT]; } rows[] = {
        { GS_MASS_DELEVA, { 6.81, 43.02, 2.63, 1.50, 0.585, 14.47, 4.57, 1.33 } },
        { GS_MASS_CLAUSER, { 7.3, 50.7, 2.6, 1.6, 0.7, 10.3, 4.3, 1.5 } },
        { GS_MASS_DEMPSTER, { 8.1, 49.7, 2.8, 1.6, 0.6, 10.0, 4.65, 1.45 } },
    };
    for (size_t r = 0; r < 3; r++) {
        double sum = 0;
        for (int s = 0; s < GS_SEG_COUNT; s++) {
            double m = gs_mass_fraction(rows[r].t, (gs_segment)s);
            sum += (s >= GS_SEG_UPPER_ARM ? 2.0 : 1.0) * m;
            TEST_ASSERT_DOUBLE_WITHIN(0.0005, rows[r].pct[s] / 100.0, m);
        }
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.0, sum);
    }
    TEST_ASSERT_TRUE(isnan(gs_mass_fraction((gs_mass_table)3, GS_SEG_HEAD)));
    TEST_ASSERT_TRUE(isnan(gs_mass_fraction(GS_MASS_DELEVA, GS_SEG_COUNT)));
}

static void test_point_layout(void)
{
    gs_kp kp = { 12.5f, -3.0f, 0.8f };
    gs_com_out o;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_com_compute(GS_LAYOUT_POINT, GS_MASS_DELEVA, GS_STATURE_ANTHRO, 0.5f, &kp, &o));
    TEST_ASSERT_EQUAL_FLOAT(12.5f, o.x_px);
    TEST_ASSERT_EQUAL_FLOAT(-3.0f, o.y_px);
    TEST_ASSERT_EQUAL_FLOAT(0.8f, o.w);
    TEST_ASSERT_EQUAL_FLOAT(1.0f, o.upright);
    TEST_ASSERT_TRUE(isnan(o.stature_px) && isnan(o.up_x) && isnan(o.up_y));
    kp.c = 0.4f;  /* below min_conf */
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_com_compute(GS_LAYOUT_POINT, GS_MASS_DELEVA, GS_STATURE_ANTHRO, 0.5f, &kp, &o));
    TEST_ASSERT_TRUE(isnan(o.x_px));
    TEST_ASSERT_EQUAL_FLOAT(0.0f, o.w);
    kp = (gs_kp){ NAN, 1.0f, 1.0f };
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_com_compute(GS_LAYOUT_POINT, GS_MASS_DELEVA, GS_STATURE_ANTHRO, 0.0f, &kp, &o));
    TEST_ASSERT_TRUE(isnan(o.x_px));
    kp = (gs_kp){ 1.0f, 1.0f, 0.0f };  /* c == 0 is missing even with min_conf 0 */
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_com_compute(GS_LAYOUT_POINT, GS_MASS_DELEVA, GS_STATURE_ANTHRO, 0.0f, &kp, &o));
    TEST_ASSERT_TRUE(isnan(o.x_px));
}

static void test_invalid_args(void)
{
    gs_kp kp[33] = { { 0 } };
    gs_com_out o;
    static const struct { int layout, table, stature; float min_conf; bool null_kp, null_out; } rows[] = {
        { 3, 0, 0, 0.3f, false, false },
        { -1, 0, 0, 0.3f, false, false },
        { 1, 3, 0, 0.3f, false, false },
        { 1, -1, 0, 0.3f, false, false },
        { 1, 0, 2, 0.3f, false, false },
        { 1, 0, 0, -0.1f, false, false },
        { 1, 0, 0, 1.5f, false, false },
        { 1, 0, 0, NAN, false, false },
        { 1, 0, 0, 0.3f, true, false },
        { 1, 0, 0, 0.3f, false, true },
    };
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        o.x_px = o.w = 5.0f;
        gs_status st = gs_com_compute((gs_layout)rows[r].layout, (gs_mass_table)rows[r].table,
                                      (gs_stature_method)rows[r].stature, rows[r].min_conf,
                                      rows[r].null_kp ? NULL : kp, rows[r].null_out ? NULL : &o);
        TEST_ASSERT_EQUAL_INT(GS_EINVAL, st);
        if (!rows[r].null_out) {
            TEST_ASSERT_TRUE(isnan(o.x_px));
            TEST_ASSERT_EQUAL_FLOAT(0.0f, o.w);
        }
    }
    TEST_ASSERT_EQUAL_UINT(1, gs_layout_kp_count(GS_LAYOUT_POINT));
    TEST_ASSERT_EQUAL_UINT(17, gs_layout_kp_count(GS_LAYOUT_COCO17));
    TEST_ASSERT_EQUAL_UINT(33, gs_layout_kp_count(GS_LAYOUT_BLAZEPOSE33));
    TEST_ASSERT_EQUAL_UINT(0, gs_layout_kp_count((gs_layout)7));
}

static void test_garbage_keypoints_do_not_poison(void)
{
    p3 b[NPTS];
    standing(b);
    gs_kp kp[17];
    view v = { 0, 0, 500, 400, 800 };
    project(b, v, GS_LAYOUT_COCO17, kp);
    gs_com_out ref = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    kp[9].x_px = NAN;  /* left wrist with a NaN coordinate counts as missing */
    kp[3].c = INFINITY;
    gs_com_out o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    TEST_ASSERT_TRUE(isfinite(o.x_px) && isfinite(o.y_px) && isfinite(o.w) && isfinite(o.stature_px));
    TEST_ASSERT_TRUE(hypot(o.x_px - ref.x_px, o.y_px - ref.y_px) < 0.01 * v.scale);
    /* coordinates so large that float arithmetic overflows: unknown, never inf */
    project(b, v, GS_LAYOUT_COCO17, kp);
    kp[15].y_px = 3e38f;
    kp[0].y_px = -3e38f;
    o = run(GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, kp);
    TEST_ASSERT_FALSE(isinf(o.x_px) || isinf(o.y_px) || isinf(o.stature_px) || isinf(o.up_x) || isinf(o.up_y));
    TEST_ASSERT_TRUE(o.w >= 0.0f && o.w <= 1.0f);
}

static void test_names(void)
{
    static const struct { const char *s; int kind; int want; } rows[] = {
        { "deleva", 0, GS_MASS_DELEVA }, { "clauser", 0, GS_MASS_CLAUSER }, { "dempster", 0, GS_MASS_DEMPSTER },
        { "DeLeva", 0, GS_MASS_DELEVA }, { "delev", 0, -1 }, { "delevax", 0, -1 }, { "", 0, -1 },
        { "anthro", 1, GS_STATURE_ANTHRO }, { "nose_ankle_1.17", 1, GS_STATURE_NOSE_ANKLE_117 },
        { "nose_ankle", 1, -1 }, { "nose_ankle_1.170", 1, -1 },
        { "point", 2, GS_LAYOUT_POINT }, { "coco17", 2, GS_LAYOUT_COCO17 },
        { "blazepose33", 2, GS_LAYOUT_BLAZEPOSE33 }, { "BLAZEPOSE33", 2, GS_LAYOUT_BLAZEPOSE33 },
        { "coco", 2, -1 }, { "blazepose", 2, -1 },
    };
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        size_t len = strlen(rows[r].s);
        bool ok;
        int got = -1;
        if (rows[r].kind == 0) {
            gs_mass_table t = (gs_mass_table)99;
            ok = gs_mass_table_from_name(rows[r].s, len, &t);
            if (ok) got = (int)t;
        } else if (rows[r].kind == 1) {
            gs_stature_method m = (gs_stature_method)99;
            ok = gs_stature_method_from_name(rows[r].s, len, &m);
            if (ok) got = (int)m;
        } else {
            gs_layout l = (gs_layout)99;
            ok = gs_layout_from_name(rows[r].s, len, &l);
            if (ok) got = (int)l;
        }
        TEST_ASSERT_EQUAL_INT_MESSAGE(rows[r].want, got, rows[r].s);
        TEST_ASSERT_EQUAL(rows[r].want >= 0, ok);
    }
    /* length-delimited: a prefix of a longer buffer */
    gs_layout l;
    TEST_ASSERT_TRUE(gs_layout_from_name("coco17,rest", 6, &l));
    TEST_ASSERT_EQUAL_INT(GS_LAYOUT_COCO17, l);
    TEST_ASSERT_FALSE(gs_layout_from_name(NULL, 0, &l));
    TEST_ASSERT_FALSE(gs_layout_from_name("coco17", 6, NULL));
    /* round trips */
    for (int t = 0; t < 3; t++) {
        gs_mass_table back;
        const char *n = gs_mass_table_name((gs_mass_table)t);
        TEST_ASSERT_TRUE(gs_mass_table_from_name(n, strlen(n), &back));
        TEST_ASSERT_EQUAL_INT(t, back);
        gs_layout lb;
        n = gs_layout_name((gs_layout)t);
        TEST_ASSERT_TRUE(gs_layout_from_name(n, strlen(n), &lb));
        TEST_ASSERT_EQUAL_INT(t, lb);
    }
    for (int m = 0; m < 2; m++) {
        gs_stature_method back;
        const char *n = gs_stature_method_name((gs_stature_method)m);
        TEST_ASSERT_TRUE(gs_stature_method_from_name(n, strlen(n), &back));
        TEST_ASSERT_EQUAL_INT(m, back);
    }
    TEST_ASSERT_EQUAL_STRING("unknown", gs_mass_table_name((gs_mass_table)9));
    TEST_ASSERT_EQUAL_STRING("unknown", gs_stature_method_name((gs_stature_method)9));
    TEST_ASSERT_EQUAL_STRING("unknown", gs_layout_name((gs_layout)9));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_stature_axis_upright_standing);
    RUN_TEST(test_nose_ankle_117_is_the_paper_rule);
    RUN_TEST(test_stature_unknown_without_head_or_feet);
    RUN_TEST(test_upright_squat_is_zero);
    RUN_TEST(test_com_standing_height_and_midline);
    RUN_TEST(test_com_follows_arms);
    RUN_TEST(test_missing_each_keypoint_bounded);
    RUN_TEST(test_missing_trunk_gives_zero_weight);
    RUN_TEST(test_weight_tracks_confidence);
    RUN_TEST(test_mass_tables);
    RUN_TEST(test_point_layout);
    RUN_TEST(test_invalid_args);
    RUN_TEST(test_garbage_keypoints_do_not_poison);
    RUN_TEST(test_names);
    return UNITY_END();
}
