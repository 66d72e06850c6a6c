/* test_fit.c - the streaming quadratic fit against a batch long-double
 * reference, exact data, SE calibration by Monte Carlo, robust fits with gross
 * outliers, degenerate input and ring windows across the wrap point. */
#include "unity.h"

#include "gravscale/gs_fit.h"
#include "gravscale/gs_ring.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* seconds to the fit's microseconds (GS_T_NONE for NaN), and a span snapped to them */
#define US(t_s) gs_time_us_of_s(t_s)
#define SNAP(t_s) ((double)US(t_s) / 1e6)

void setUp(void) {}
void tearDown(void) {}

/* ---- test PRNG (splitmix64) and Gaussian noise ----------------------------- */

static uint64_t rng_state;

static void rng_seed(uint64_t s) { rng_state = s; }

static uint64_t rng_u64(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1). */
static double rng_unif(void) { return (double)(rng_u64() >> 11) * (1.0 / 9007199254740992.0); }

static double rng_range(double lo, double hi) { return lo + (hi - lo) * rng_unif(); }

static double rng_gauss(void)
{
    double u1 = rng_unif(), u2 = rng_unif();
    if (u1 < 1e-300) {
        u1 = 1e-300;
    }
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* ---- batch reference: weighted normal equations in long double -------------- */

typedef struct {
    double x0, vx, ax, y0, vy, ay; /* at the requested t0 */
    double a, ssr_x, ssr_y, se_a, sum_w;
    uint32_t n;
    int ok;
} ref_result;

/* Solve the 3x3 system A x = b by Gaussian elimination with partial pivoting. */
static int solve3(long double a_in[3][3], const long double b_in[3], long double x[3])
{
    long double a[3][3], b[3];
    int i, j, k;
    memcpy(a, a_in, sizeof a);
    memcpy(b, b_in, sizeof b);
    for (k = 0; k < 3; k++) {
        int p = k;
        for (i = k + 1; i < 3; i++) {
            if (fabsl(a[i][k]) > fabsl(a[p][k])) {
                p = i;
            }
        }
        if (a[p][k] == 0.0L) {
            return 0;
        }
        if (p != k) {
            for (j = 0; j < 3; j++) {
                long double t = a[k][j];
                a[k][j] = a[p][j];
                a[p][j] = t;
            }
            {
                long double t = b[k];
                b[k] = b[p];
                b[p] = t;
            }
        }
        for (i = k + 1; i < 3; i++) {
            long double f = a[i][k] / a[k][k];
            for (j = k; j < 3; j++) {
                a[i][j] -= f * a[k][j];
            }
            b[i] -= f * b[k];
        }
    }
    for (i = 2; i >= 0; i--) {
        long double s = b[i];
        for (j = i + 1; j < 3; j++) {
            s -= a[i][j] * x[j];
        }
        x[i] = s / a[i][i];
    }
    return 1;
}

/* Weighted LS of x(t), y(t) on its own centred basis u = (t - tm)/s, reported at t0. */
static ref_result ref_fit(uint32_t n, const double *t, const double *x, const double *y, const double *w, double t0)
{
    ref_result r;
    long double tmin = INFINITY, tmax = -INFINITY, tm, s, A[3][3] = {{0}}, bx[3] = {0}, by[3] = {0};
    long double dx[3], dy[3], e2[3], inv22[3], u0, ssx = 0, ssy = 0, sw = 0;
    const long double e[3] = {0, 0, 1};
    uint32_t i, m = 0;
    int j, k;
    memset(&r, 0, sizeof r);
    for (i = 0; i < n; i++) {
        if (w[i] > 0 && isfinite(t[i]) && isfinite(x[i]) && isfinite(y[i])) {
            if (t[i] < tmin) tmin = t[i];
            if (t[i] > tmax) tmax = t[i];
        }
    }
    tm = 0.5L * (tmin + tmax);
    s = 0.5L * (tmax - tmin);
    for (i = 0; i < n; i++) {
        long double u, phi[3];
        if (!(w[i] > 0 && isfinite(t[i]) && isfinite(x[i]) && isfinite(y[i]))) {
            continue;
        }
        u = ((long double)t[i] - tm) / s;
        phi[0] = 1;
        phi[1] = u;
        phi[2] = u * u;
        for (j = 0; j < 3; j++) {
            for (k = 0; k < 3; k++) {
                A[j][k] += w[i] * phi[j] * phi[k];
            }
            bx[j] += w[i] * phi[j] * x[i];
            by[j] += w[i] * phi[j] * y[i];
        }
        sw += w[i];
        m++;
    }
    r.n = m;
    if (m < 3 || !solve3(A, bx, dx) || !solve3(A, by, dy) || !solve3(A, e, e2)) {
        return r;
    }
    inv22[2] = e2[2];
    for (i = 0; i < n; i++) {
        long double u, ex, ey;
        if (!(w[i] > 0 && isfinite(t[i]) && isfinite(x[i]) && isfinite(y[i]))) {
            continue;
        }
        u = ((long double)t[i] - tm) / s;
        ex = x[i] - (dx[0] + u * (dx[1] + u * dx[2]));
        ey = y[i] - (dy[0] + u * (dy[1] + u * dy[2]));
        ssx += w[i] * ex * ex;
        ssy += w[i] * ey * ey;
    }
    u0 = ((long double)t0 - tm) / s;
    r.x0 = (double)(dx[0] + u0 * (dx[1] + u0 * dx[2]));
    r.vx = (double)((dx[1] + 2 * dx[2] * u0) / s);
    r.ax = (double)(2 * dx[2] / (s * s));
    r.y0 = (double)(dy[0] + u0 * (dy[1] + u0 * dy[2]));
    r.vy = (double)((dy[1] + 2 * dy[2] * u0) / s);
    r.ay = (double)(2 * dy[2] / (s * s));
    r.a = sqrt(r.ax * r.ax + r.ay * r.ay);
    r.ssr_x = (double)ssx;
    r.ssr_y = (double)ssy;
    r.sum_w = (double)sw;
    if (m > 3) {
        long double sigma2 = (ssx + ssy) / (2.0L * (m - 3));
        r.se_a = (double)sqrtl(4.0L * sigma2 * inv22[2] / (s * s * s * s));
    } else {
        r.se_a = NAN;
    }
    r.ok = 1;
    return r;
}

static double rel_err(double got, double want, double scale)
{
    return fabs(got - want) / scale;
}

/* ---- streaming fit vs the batch reference ----------------------------------- */

#define MAXN 500

static double g_max_rel_dev; /* reported at the end */

static void test_stream_matches_batch_reference(void)
{
    static double t[MAXN], x[MAXN], y[MAXN], w[MAXN];
    static int64_t t_us[MAXN];
    int trial;
    double worst = 0.0;
    rng_seed(12345);
    for (trial = 0; trial < 400; trial++) {
        uint32_t n = 4 + (uint32_t)(rng_unif() * (MAXN - 3)), i;
        double tstart = 1e5 + rng_range(0.0, 1e4);
        double dur = rng_range(0.1, 2.0);
        double ax = rng_range(-200, 200), ay = rng_range(300, 3000);
        double vx = rng_range(-300, 300), vy = rng_range(-1500, 1500);
        double x0 = rng_range(100, 1800), y0 = rng_range(100, 1000);
        double sigma = rng_range(0.05, 3.0);
        double tscale = dur * pow(10.0, rng_range(-1.0, 1.0));
        gs_fit f;
        gs_fit_result res;
        ref_result ref;
        double pos_scale, vel_scale, acc_scale, d;
        if (trial < 4) {
            n = 4 + (uint32_t)trial; /* the smallest windows always appear */
        }
        for (i = 0; i < n; i++) {
            double tt = rng_range(0.0, dur);
            t_us[i] = US(tstart + tt);
            x[i] = x0 + vx * tt + 0.5 * ax * tt * tt + sigma * rng_gauss();
            y[i] = y0 + vy * tt + 0.5 * ay * tt * tt + sigma * rng_gauss();
            w[i] = rng_unif() < 0.05 ? 0.0 : rng_range(0.05, 1.0);
        }
        if (n < 8) {
            for (i = 0; i < n; i++) {
                w[i] = rng_range(0.05, 1.0); /* keep at least 4 weighted samples */
            }
        }
        gs_fit_init(&f, t_us[0], US(tscale));
        for (i = 0; i < n; i++) {
            gs_fit_add(&f, t_us[i], x[i], y[i], w[i]);
            t[i] = (double)(t_us[i] - t_us[0]) / 1e6; /* the reference on the same times, exactly */
        }
        ref = ref_fit(n, t, x, y, w, 0.0);
        TEST_ASSERT_TRUE(ref.ok);
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&f, &res));
        TEST_ASSERT_EQUAL_UINT32(ref.n, res.n);
        TEST_ASSERT_TRUE(res.t0_us == t_us[0]);
        /* Natural magnitudes of each quantity over the window (x is offset by t - t[0] up to dur). */
        acc_scale = ref.a;
        vel_scale = fabs(ref.vx) + fabs(ref.vy) + acc_scale * dur;
        pos_scale = fabs(ref.x0) + fabs(ref.y0) + vel_scale * dur;
        d = rel_err(res.x0_px, ref.x0, pos_scale);
        d = fmax(d, rel_err(res.y0_px, ref.y0, pos_scale));
        d = fmax(d, rel_err(res.vx_px_s, ref.vx, vel_scale));
        d = fmax(d, rel_err(res.vy_px_s, ref.vy, vel_scale));
        d = fmax(d, rel_err(res.ax_px_s2, ref.ax, acc_scale));
        d = fmax(d, rel_err(res.ay_px_s2, ref.ay, acc_scale));
        d = fmax(d, rel_err(res.a_px_s2, ref.a, ref.a));
        d = fmax(d, rel_err(f.ssr_x, ref.ssr_x, ref.ssr_x));
        d = fmax(d, rel_err(f.ssr_y, ref.ssr_y, ref.ssr_y));
        d = fmax(d, rel_err(res.a_se_px_s2, ref.se_a, ref.se_a));
        d = fmax(d, rel_err(res.rms_px, sqrt((ref.ssr_x + ref.ssr_y) / ref.sum_w),
                            sqrt((ref.ssr_x + ref.ssr_y) / ref.sum_w)));
        d = fmax(d, rel_err(f.sum_w, ref.sum_w, ref.sum_w));
        if (d > 1e-9) {
            char msg[200];
            snprintf(msg, sizeof msg, "trial %d n=%u tscale/dur=%.3g rel dev %.3g", trial, (unsigned)n, tscale / dur, d);
            TEST_FAIL_MESSAGE(msg);
        }
        if (d > worst) {
            worst = d;
        }
    }
    g_max_rel_dev = worst;
    printf("stream vs batch: max relative deviation %.3g over 400 random windows\n", worst);
}

/* The per-coefficient relative check alone, at the worst conditioning the brief asks for. */
static void test_stream_extreme_tscale_exact(void)
{
    static const double ratios[] = {0.1, 0.3, 1.0, 3.0, 10.0};
    size_t k;
    for (k = 0; k < sizeof ratios / sizeof ratios[0]; k++) {
        gs_fit f;
        gs_fit_result res;
        uint32_t i, n = 120;
        double dur = 1.0, tstart = 86400.0 * 1.3;
        gs_fit_init(&f, US(tstart), US(ratios[k] * dur));
        for (i = 0; i < n; i++) {
            double tt = SNAP(dur * i / (n - 1));
            gs_fit_add(&f, US(tstart + tt), 640.0 + 40.0 * tt - 5.0 * tt * tt, 200.0 - 900.0 * tt + 490.5 * tt * tt, 1.0);
        }
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&f, &res));
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 981.0, -10.0, res.ax_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 981.0, 981.0, res.ay_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 981.0, sqrt(981.0 * 981.0 + 100.0), res.a_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 1000.0, 40.0, res.vx_px_s);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 1000.0, -900.0, res.vy_px_s);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 640.0, 640.0, res.x0_px);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 640.0, 200.0, res.y0_px);
        TEST_ASSERT_TRUE(res.rms_px < 1e-7);
        TEST_ASSERT_TRUE(res.a_se_px_s2 < 1e-6);
    }
}

/* ---- exact data and gravity direction ------------------------------------------ */

static void fit_rolled(double roll_deg, gs_fit_result *res)
{
    /* Vertical throw in a level camera (y down, g = 980 px/s^2), then the image rotated. */
    double th = roll_deg * 3.141592653589793 / 180.0;
    double c = cos(th), s = sin(th);
    gs_fit f;
    int i;
    gs_fit_init(&f, US(1e5), US(0.8));
    for (i = 0; i < 97; i++) {
        double tt = SNAP(i / 120.0);
        double lx = 3.0 * tt, ly = -450.0 * tt + 490.0 * tt * tt; /* level-camera motion */
        /* Rotating the level frame by th maps image-down (0,1) to (sin th, cos th). */
        double xi = 500.0 + c * lx + s * ly;
        double yi = 300.0 - s * lx + c * ly;
        gs_fit_add(&f, US(1e5 + tt), xi, yi, 1.0);
    }
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&f, res));
}

static void test_exact_parabola_and_g_direction(void)
{
    static const struct {
        double roll_deg, want_dir_deg;
    } cases[] = {{0.0, 0.0}, {30.0, 30.0}, {-30.0, -30.0}, {90.0, 90.0}, {179.0, 179.0}, {-120.0, -120.0}};
    size_t k;
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        gs_fit_result res;
        double th = cases[k].roll_deg * 3.141592653589793 / 180.0;
        fit_rolled(cases[k].roll_deg, &res);
        TEST_ASSERT_DOUBLE_WITHIN(980.0 * 1e-9, 980.0, res.a_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(980.0 * 1e-9, 980.0 * sin(th), res.ax_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(980.0 * 1e-9, 980.0 * cos(th), res.ay_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(1e-7, cases[k].want_dir_deg, res.g_dir_deg);
        TEST_ASSERT_EQUAL_UINT32(97, res.n);
    }
    /* Header convention: +30 deg means the acceleration points down and toward +x. */
    {
        gs_fit_result res;
        fit_rolled(30.0, &res);
        TEST_ASSERT_TRUE(res.ax_px_s2 > 0.0 && res.ay_px_s2 > 0.0 && res.g_dir_deg > 0.0);
    }
}

static void test_three_samples_exact_without_se(void)
{
    gs_fit f;
    gs_fit_result res;
    int i;
    gs_fit_init(&f, US(10.0), US(0.1));
    for (i = 0; i < 3; i++) {
        double tt = 0.05 * i;
        gs_fit_add(&f, US(10.0 + tt), 1.0 + 2.0 * tt, 5.0 + 3.0 * tt + 0.5 * 700.0 * tt * tt, 0.5 + 0.2 * i);
    }
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&f, &res));
    TEST_ASSERT_EQUAL_UINT32(3, res.n);
    TEST_ASSERT_DOUBLE_WITHIN(700.0 * 1e-9, 700.0, res.a_px_s2);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 3.0, res.vy_px_s);
    TEST_ASSERT_TRUE(isnan(res.a_se_px_s2));
    TEST_ASSERT_TRUE(res.rms_px < 1e-9);
}

/* ---- SE calibration by Monte Carlo --------------------------------------------------- */

static void se_monte_carlo(int weighted, double *ratio_out, double *cover_out)
{
    const int trials = 2000;
    const uint32_t n = 60;
    const double sigma = 1.0, ax = 100.0, ay = 900.0, a_true = sqrt(ax * ax + ay * ay);
    double sum = 0, sum2 = 0, sum_se = 0;
    int covered = 0, k;
    for (k = 0; k < trials; k++) {
        gs_fit f;
        gs_fit_result res;
        uint32_t i;
        gs_fit_init(&f, US(5000.0), US(1.0));
        for (i = 0; i < n; i++) {
            double tt = SNAP(i / 60.0);
            /* Noise SD sigma/sqrt(w): the weights are correct relative inverse variances. */
            double w = weighted ? rng_range(0.2, 1.0) : 1.0;
            double sd = sigma / sqrt(w);
            double x = 300.0 + 20.0 * tt + 0.5 * ax * tt * tt + sd * rng_gauss();
            double y = 700.0 - 450.0 * tt + 0.5 * ay * tt * tt + sd * rng_gauss();
            gs_fit_add(&f, US(5000.0 + tt), x, y, w);
        }
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&f, &res));
        sum += res.a_px_s2;
        sum2 += res.a_px_s2 * res.a_px_s2;
        sum_se += res.a_se_px_s2;
        if (fabs(res.a_px_s2 - a_true) <= 1.959964 * res.a_se_px_s2) {
            covered++;
        }
    }
    {
        double mean = sum / trials;
        double sd = sqrt((sum2 - trials * mean * mean) / (trials - 1));
        *ratio_out = (sum_se / trials) / sd;
        *cover_out = (double)covered / trials;
        /* The estimator is unbiased: the mean is within 4 standard errors of truth. */
        TEST_ASSERT_DOUBLE_WITHIN(4.0 * sd / sqrt((double)trials), a_true, mean);
    }
}

static void test_se_calibration(void)
{
    double ratio, cover;
    rng_seed(777);
    se_monte_carlo(0, &ratio, &cover);
    printf("SE calibration (unit weights): mean SE / empirical SD = %.4f, 95%% coverage = %.4f\n", ratio, cover);
    TEST_ASSERT_DOUBLE_WITHIN(0.10, 1.0, ratio);
    TEST_ASSERT_TRUE(cover >= 0.93 && cover <= 0.97);
    se_monte_carlo(1, &ratio, &cover);
    printf("SE calibration (random weights): mean SE / empirical SD = %.4f, 95%% coverage = %.4f\n", ratio, cover);
    TEST_ASSERT_DOUBLE_WITHIN(0.10, 1.0, ratio);
    TEST_ASSERT_TRUE(cover >= 0.93 && cover <= 0.97);
}

/* ---- ring windows ------------------------------------------------------------------------- */

#define RING_CAP 256

static gs_sample ring_store[RING_CAP];

static gs_sample_full mk_sample(double t, double x, double y, double w)
{
    gs_sample_full s;
    s.t_us = US(t);
    s.x_px = (float)x;
    s.y_px = (float)y;
    s.w = (float)w;
    s.size_px = NAN;
    s.up_x = NAN;
    s.up_y = NAN;
    s.upright = NAN;
    return s;
}

/* Plain gs_fit over ring samples with their own weights, reported at t0. */
static gs_status direct_fit(const gs_ring *r, uint64_t first, uint32_t count, int64_t t0_us, const float *wts,
                            gs_fit_result *res)
{
    gs_fit f;
    uint32_t i;
    gs_fit_init(&f, t0_us, 370000);
    for (i = 0; i < count; i++) {
        gs_sample_full s;
        TEST_ASSERT_TRUE(gs_ring_get(r, first + i, &s));
        gs_fit_add(&f, s.t_us, s.x_px, s.y_px, wts ? wts[i] : s.w);
    }
    return gs_fit_solve(&f, res);
}

/* A throw sampled at fps with Gaussian noise; truth acceleration (ax, ay). */
typedef struct {
    double ax, ay, sigma, fps, t_start;
} throw_cfg;

static void push_throw(gs_ring *r, const throw_cfg *c, uint32_t n, uint32_t index0)
{
    uint32_t i;
    for (i = 0; i < n; i++) {
        double tt = (index0 + i) / c->fps;
        double x = 400.0 + 60.0 * tt + 0.5 * c->ax * tt * tt + c->sigma * rng_gauss();
        double y = 900.0 - 1100.0 * tt + 0.5 * c->ay * tt * tt + c->sigma * rng_gauss();
        gs_sample_full s = mk_sample(c->t_start + tt, x, y, rng_range(0.5, 1.0));
        gs_ring_push(r, &s);
    }
}

static void test_ring_window_across_wrap(void)
{
    gs_ring r;
    gs_fit_result res, direct;
    uint32_t w[3];
    throw_cfg c = {30.0, 1500.0, 0.5, 120.0, 3600.0};
    uint32_t i;
    static gs_sample small[64];
    rng_seed(99);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, small, 64));
    push_throw(&r, &c, 100, 0);
    /* [40, 100) holds slots 40..63 then 0..35: straddles the wrap at absolute 64. */
    TEST_ASSERT_EQUAL_UINT64(36, gs_ring_oldest(&r));
    w[0] = w[1] = w[2] = 0xA5A5A5A5u; /* canary bits past the 60 of the window */
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 40, 60, GS_FIT_PLAIN, 0.5f, w, &res));
    TEST_ASSERT_EQUAL_HEX32(0xA5A5A5A5u, w[2]);
    TEST_ASSERT_EQUAL_HEX32(0xA0000000u, w[1] & 0xF0000000u);
    for (i = 0; i < 60; i++) {
        TEST_ASSERT_TRUE(gs_fit_kept(w, i)); /* plain LS keeps every weighted sample */
    }
    TEST_ASSERT_EQUAL_UINT32(60, res.n);
    TEST_ASSERT_EQUAL_INT(GS_OK, direct_fit(&r, 40, 60, res.t0_us, NULL, &direct));
    /* t0 is the window's middle, floored to the microsecond */
    TEST_ASSERT_TRUE(res.t0_us == (US(3600.0 + 40.0 / 120.0) + US(3600.0 + 99.0 / 120.0)) / 2);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 1500.0, direct.a_px_s2, res.a_px_s2);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 1000.0, direct.y0_px, res.y0_px);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 1000.0, direct.vy_px_s, res.vy_px_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 1500.0, direct.a_se_px_s2, res.a_se_px_s2);
    /* and the estimate is near truth (SE ~ 10 px/s^2 here). */
    TEST_ASSERT_DOUBLE_WITHIN(5.0 * res.a_se_px_s2, sqrt(30.0 * 30.0 + 1500.0 * 1500.0), res.a_px_s2);
    /* IRLS across the wrap too. */
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 40, 60, GS_FIT_IRLS, 0.5f, w, &res));
    TEST_ASSERT_DOUBLE_WITHIN(5.0 * res.a_se_px_s2, sqrt(30.0 * 30.0 + 1500.0 * 1500.0), res.a_px_s2);
    TEST_ASSERT_EQUAL_HEX32(0xA5A5A5A5u, w[2]);
    TEST_ASSERT_EQUAL_HEX32(0xA0000000u, w[1] & 0xF0000000u);
    /* Windows at the edges of what is held. */
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 36, 64, GS_FIT_PLAIN, 0.5f, w, &res));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 35, 64, GS_FIT_PLAIN, 0.5f, w, &res));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 37, 64, GS_FIT_PLAIN, 0.5f, w, &res));
}

static void test_window_partly_overwritten_is_einval(void)
{
    gs_ring r;
    gs_fit_result res;
    uint32_t w[2];
    throw_cfg c = {0.0, 981.0, 0.3, 60.0, 0.0};
    static gs_sample small[16];
    static const gs_fit_method methods[] = {GS_FIT_PLAIN, GS_FIT_IRLS, GS_FIT_RANSAC};
    size_t k;
    rng_seed(5);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, small, 16));
    push_throw(&r, &c, 40, 0); /* holds [24, 40) */
    for (k = 0; k < 3; k++) {
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 24, 16, methods[k], 0.5f, w, &res));
        TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 20, 10, methods[k], 0.5f, w, &res));
        TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 30, 20, methods[k], 0.5f, w, &res));
        TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 0, 40, methods[k], 0.5f, w, &res));
        TEST_ASSERT_TRUE(isnan(res.a_px_s2));
    }
}

/* ---- robust fits with gross outliers ---------------------------------------------------- */

typedef struct {
    const char *name;
    int where;       /* 0 scattered (random direction), 1 burst in the middle, 2 at both ends (shifted up) */
    double shift_px; /* outlier displacement */
    int plain_fails; /* the layout biases the curvature, so plain LS must be off by > 5 % */
} outlier_case;

static double g_rob_irls_err, g_rob_plain_err, g_rob_ransac_err;

static void run_outlier_case(const outlier_case *oc)
{
    gs_ring r;
    gs_fit_result plain, irls, ransac;
    static uint32_t w[RING_CAP / 32];
    const uint32_t n = 90, n_out = 18; /* 20 % */
    const double fps = 90.0, ax = 40.0, ay = 1200.0, a_true = sqrt(ax * ax + ay * ay), sigma = 0.7;
    static bool is_out[RING_CAP];
    uint32_t i, k, n_rejected_inliers = 0;
    double e_plain, e_irls, e_ransac;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, ring_store, RING_CAP));
    /* Pre-fill so the window does not start at absolute index 0. */
    for (i = 0; i < 30; i++) {
        gs_sample_full s = mk_sample(-1.0 + i * 0.01, 0, 0, 1.0);
        gs_ring_push(&r, &s);
    }
    memset(is_out, 0, sizeof is_out);
    for (k = 0; k < n_out; k++) {
        uint32_t idx;
        if (oc->where == 1) {
            idx = 34 + k;
        } else if (oc->where == 2) {
            idx = k < n_out / 2 ? k : n - 1 - (k - n_out / 2);
        } else {
            do {
                idx = (uint32_t)(rng_unif() * n);
            } while (is_out[idx]);
        }
        is_out[idx] = true;
    }
    for (i = 0; i < n; i++) {
        double tt = i / fps;
        double x = 700.0 - 80.0 * tt + 0.5 * ax * tt * tt + sigma * rng_gauss();
        double y = 800.0 - 600.0 * tt + 0.5 * ay * tt * tt + sigma * rng_gauss();
        double wt = rng_range(0.3, 1.0);
        if (is_out[i]) {
            double ang = oc->where ? -1.5707963 : rng_range(0.0, 6.283185307179586);
            double mag = oc->shift_px * rng_range(0.7, 1.3);
            x += mag * cos(ang);
            y += mag * sin(ang);
            wt = (i % 2) ? 1.0 : rng_range(0.3, 1.0); /* half the outliers are fully trusted */
        }
        {
            gs_sample_full s = mk_sample(20000.0 + tt, x, y, wt);
            gs_ring_push(&r, &s);
        }
    }
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 30, n, GS_FIT_PLAIN, 1.0f, w, &plain));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 30, n, GS_FIT_RANSAC, 1.0f, w, &ransac));
    for (i = 0; i < n; i++) {
        if (is_out[i]) {
            TEST_ASSERT_FALSE(gs_fit_kept(w, i));
        }
    }
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 30, n, GS_FIT_IRLS, 1.0f, w, &irls));
    for (i = 0; i < n; i++) {
        if (is_out[i]) {
            TEST_ASSERT_FALSE(gs_fit_kept(w, i));
        } else if (!gs_fit_kept(w, i)) {
            n_rejected_inliers++;
        }
    }
    TEST_ASSERT_EQUAL_UINT32(0, n_rejected_inliers);
    TEST_ASSERT_EQUAL_UINT32(n - n_out, irls.n);
    e_plain = fabs(plain.a_px_s2 - a_true) / a_true;
    e_irls = fabs(irls.a_px_s2 - a_true) / a_true;
    e_ransac = fabs(ransac.a_px_s2 - a_true) / a_true;
    printf("outliers %-9s: |a| rel error plain %.4f  irls %.5f  ransac %.5f (irls n=%u, ransac n=%u)\n", oc->name,
           e_plain, e_irls, e_ransac, (unsigned)irls.n, (unsigned)ransac.n);
    TEST_ASSERT_TRUE(e_irls < 0.01);
    TEST_ASSERT_TRUE(e_ransac < 0.01);
    if (oc->plain_fails) {
        TEST_ASSERT_TRUE(e_plain > 0.05);
        if (g_rob_plain_err == 0.0 || e_plain < g_rob_plain_err) g_rob_plain_err = e_plain;
    }
    if (e_irls > g_rob_irls_err) g_rob_irls_err = e_irls;
    if (e_ransac > g_rob_ransac_err) g_rob_ransac_err = e_ransac;
    /* The RANSAC result is the plain fit over its inliers with their prior weights. */
    {
        static float wts[RING_CAP];
        gs_fit_result again;
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 30, n, GS_FIT_RANSAC, 1.0f, w, &ransac));
        for (i = 0; i < n; i++) {
            gs_sample_full s;
            TEST_ASSERT_TRUE(gs_ring_get(&r, 30 + i, &s));
            wts[i] = gs_fit_kept(w, i) ? s.w : 0.0f;
        }
        TEST_ASSERT_EQUAL_INT(GS_OK, direct_fit(&r, 30, n, ransac.t0_us, wts, &again));
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * a_true, again.a_px_s2, ransac.a_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, again.y0_px, ransac.y0_px);
    }
}

static void test_robust_gross_outliers(void)
{
    static const outlier_case cases[] = {
        {"burst", 1, 60.0, 1},
        {"ends", 2, 40.0, 1},
        {"scattered", 0, 120.0, 0},
        {"scatter2", 0, 250.0, 0},
    };
    size_t k;
    int rep;
    rng_seed(4242);
    for (rep = 0; rep < 5; rep++) {
        for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
            run_outlier_case(&cases[k]);
        }
    }
}

static void test_robust_without_outliers_matches_plain(void)
{
    gs_ring r;
    gs_fit_result plain, irls;
    static uint32_t w[RING_CAP / 32];
    throw_cfg c = {-25.0, 1800.0, 1.2, 120.0, 1e5};
    int rep;
    rng_seed(31337);
    for (rep = 0; rep < 20; rep++) {
        uint32_t i;
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, ring_store, RING_CAP));
        push_throw(&r, &c, 100, 0);
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, 100, GS_FIT_PLAIN, 1.0f, w, &plain));
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, 100, GS_FIT_IRLS, 1.0f, w, &irls));
        TEST_ASSERT_EQUAL_UINT32(100, irls.n);
        /* No Gaussian sample is rejected (cut-off ~8 sigma). */
        for (i = 0; i < 100; i++) {
            TEST_ASSERT_TRUE(gs_fit_kept(w, i));
        }
        /* Biweights near 1 for Gaussian noise: the estimate moves by a small part of its SE. */
        printf("no outliers: (irls - plain) / se = %+.3f\n", (irls.a_px_s2 - plain.a_px_s2) / plain.a_se_px_s2);
        /* Efficiency ~0.98 makes the difference's SD ~0.15 SE: 0.75 SE is a 5-sigma bound. */
        TEST_ASSERT_DOUBLE_WITHIN(0.75 * plain.a_se_px_s2, plain.a_px_s2, irls.a_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(0.10 * plain.a_se_px_s2, plain.a_se_px_s2, irls.a_se_px_s2);
    }
}

static void test_robust_exact_data_keeps_everything(void)
{
    gs_ring r;
    gs_fit_result res;
    static uint32_t w[RING_CAP / 32];
    static const gs_fit_method methods[] = {GS_FIT_PLAIN, GS_FIT_IRLS, GS_FIT_RANSAC};
    size_t k;
    uint32_t i;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, ring_store, RING_CAP));
    for (i = 0; i < 50; i++) {
        double tt = i / 50.0;
        /* Small coordinates so float storage is exact enough. */
        gs_sample_full s = mk_sample(tt, 10.0 + 4.0 * tt, 20.0 - 40.0 * tt + 0.5 * 100.0 * tt * tt, 1.0);
        gs_ring_push(&r, &s);
    }
    for (k = 0; k < 3; k++) {
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, 50, methods[k], 0.01f, w, &res));
        TEST_ASSERT_EQUAL_UINT32(50, res.n);
        TEST_ASSERT_DOUBLE_WITHIN(1e-3, 100.0, res.a_px_s2);
        TEST_ASSERT_DOUBLE_WITHIN(1e-4, 0.0, res.g_dir_deg);
        for (i = 0; i < 50; i++) {
            TEST_ASSERT_TRUE(gs_fit_kept(w, i));
        }
    }
    /* A zero or NaN floor must not divide by zero. */
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, 50, GS_FIT_IRLS, 0.0f, w, &res));
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, 100.0, res.a_px_s2);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, 50, GS_FIT_IRLS, NAN, w, &res));
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, 100.0, res.a_px_s2);
}

/* IRLS over windows of every length from 5 to 70 samples, gross outliers at the first
 * sample, around the 32-sample word boundary and at the last: exactly they are rejected,
 * and keep's bits past the window (the rest of its last word, the next words) are left
 * as they were. */
static void test_robust_keep_bits_every_length(void)
{
    gs_ring r;
    gs_fit_result res;
    static uint32_t keep[RING_CAP / 32];
    const uint32_t pattern = 0xA5C3965Au;
    uint32_t count, i;
    rng_seed(777);
    for (count = 5; count <= 70; count++) {
        bool out[70] = {false};
        uint32_t n_out = 0, words = (count + 31u) / 32u;
        out[0] = count >= 9;
        out[count - 1] = true;
        if (count > 33) {
            out[31] = out[32] = true;
        }
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, ring_store, RING_CAP));
        for (i = 0; i < count; i++) {
            double tt = i / 60.0;
            double x = 300.0 + 50.0 * tt + 0.3 * rng_gauss() + (out[i] ? 80.0 : 0.0);
            double y = 700.0 - 500.0 * tt + 0.5 * 1500.0 * tt * tt + 0.3 * rng_gauss() - (out[i] ? 60.0 : 0.0);
            gs_sample_full s = mk_sample(50.0 + tt, x, y, rng_range(0.5, 1.0));
            gs_ring_push(&r, &s);
            n_out += out[i] ? 1u : 0u;
        }
        for (i = 0; i < RING_CAP / 32; i++) {
            keep[i] = pattern;
        }
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, count, GS_FIT_IRLS, 0.5f, keep, &res));
        TEST_ASSERT_EQUAL_UINT32(count - n_out, res.n);
        for (i = 0; i < count; i++) {
            TEST_ASSERT_EQUAL_INT(!out[i], gs_fit_kept(keep, i));
        }
        for (i = count; i < 32u * words; i++) {
            TEST_ASSERT_EQUAL_INT((pattern >> (i & 31u)) & 1u, gs_fit_kept(keep, i));
        }
        for (i = words; i < RING_CAP / 32; i++) {
            TEST_ASSERT_EQUAL_HEX32(pattern, keep[i]);
        }
    }
}

/* ---- degenerate input ------------------------------------------------------------------------ */

typedef struct {
    const char *name;
    uint32_t n;
    double t[6], x[6], y[6], w[6];
    gs_status want;
} degen_case;

static void test_degenerate_table(void)
{
    static const degen_case cases[] = {
        {"empty", 0, {0}, {0}, {0}, {0}, GS_EINVAL},
        {"one", 1, {0}, {1}, {1}, {1}, GS_EINVAL},
        {"two", 2, {0, 1}, {1, 2}, {1, 4}, {1, 1}, GS_EINVAL},
        {"all weights zero", 5, {0, 1, 2, 3, 4}, {1, 2, 3, 4, 5}, {1, 2, 3, 4, 5}, {0, 0, 0, 0, 0}, GS_EINVAL},
        {"negative weights", 5, {0, 1, 2, 3, 4}, {1, 2, 3, 4, 5}, {1, 2, 3, 4, 5}, {-1, -1, -1, -1, -1}, GS_EINVAL},
        {"same time", 5, {7, 7, 7, 7, 7}, {1, 2, 3, 4, 5}, {1, 2, 3, 4, 5}, {1, 1, 1, 1, 1}, GS_EINVAL},
        {"two times", 6, {7, 8, 7, 8, 7, 8}, {1, 2, 3, 4, 5, 6}, {1, 2, 3, 4, 5, 6}, {1, 1, 1, 1, 1, 1}, GS_EINVAL},
        {"two weighted of 4", 4, {0, 1, 2, 3}, {1, 2, 3, 4}, {1, 4, 9, 16}, {1, 0, 0, 1}, GS_EINVAL},
        {"NaN leaves 2", 4, {0, 1, NAN, 3}, {1, NAN, 3, 4}, {1, 4, 9, 16}, {1, 1, 1, 1}, GS_EINVAL},
        {"three distinct", 3, {0, 1, 2}, {0, 1, 2}, {0, 1, 4}, {1, 1, 1}, GS_OK},
        {"four, two times dup", 4, {0, 1, 1, 2}, {0, 1, 1, 2}, {0, 1, 1, 4}, {1, 1, 1, 1}, GS_OK},
    };
    size_t k;
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const degen_case *c = &cases[k];
        gs_fit f;
        gs_fit_result res;
        gs_status st;
        gs_ring r;
        static uint32_t wbuf[1];
        uint32_t i;
        gs_fit_init(&f, US(0.0), US(1.0));
        for (i = 0; i < c->n; i++) {
            gs_fit_add(&f, US(c->t[i]), c->x[i], c->y[i], c->w[i]);
        }
        st = gs_fit_solve(&f, &res);
        TEST_ASSERT_EQUAL_INT_MESSAGE(c->want, st, c->name);
        if (st != GS_OK) {
            TEST_ASSERT_TRUE_MESSAGE(isnan(res.a_px_s2) && isnan(res.a_se_px_s2) && isnan(res.x0_px), c->name);
        } else {
            TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(1e-9, 2.0, res.ay_px_s2, c->name);
        }
        /* The same through the ring and every robust method. */
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, ring_store, RING_CAP));
        for (i = 0; i < c->n; i++) {
            gs_sample_full s = mk_sample(c->t[i], c->x[i], c->y[i], c->w[i]);
            gs_ring_push(&r, &s);
        }
        {
            static const gs_fit_method methods[] = {GS_FIT_PLAIN, GS_FIT_IRLS, GS_FIT_RANSAC};
            size_t m;
            for (m = 0; m < 3; m++) {
                wbuf[0] = 0xFFFFFFFFu;  /* canary bits past the window */
                st = gs_fit_robust(&r, 0, c->n, methods[m], 0.1f, wbuf, &res);
                TEST_ASSERT_EQUAL_INT_MESSAGE(c->want, st, c->name);
                for (i = c->n; i < 32; i++) {
                    TEST_ASSERT_TRUE_MESSAGE(gs_fit_kept(wbuf, i), c->name);
                }
                if (st != GS_OK) {
                    for (i = 0; i < c->n; i++) {
                        TEST_ASSERT_FALSE_MESSAGE(gs_fit_kept(wbuf, i), c->name);
                    }
                } else {
                    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(1e-4, 2.0, res.ay_px_s2, c->name);
                }
            }
        }
    }
}

static void test_nan_inputs_are_ignored(void)
{
    gs_fit a, b;
    gs_fit_result ra, rb;
    int i;
    gs_fit_init(&a, US(50.0), US(0.5));
    gs_fit_init(&b, US(50.0), US(0.5));
    rng_seed(8);
    for (i = 0; i < 40; i++) {
        double tt = 50.0 + i / 30.0;
        double x = 100.0 + 3.0 * i + rng_gauss(), y = 200.0 + 0.4 * i * i + rng_gauss();
        gs_fit_add(&a, US(tt), x, y, 1.0);
        gs_fit_add(&b, US(tt), x, y, 1.0);
        /* Interleave junk into b only. */
        gs_fit_add(&b, US(NAN), x, y, 1.0);
        gs_fit_add(&b, US(tt), NAN, y, 1.0);
        gs_fit_add(&b, US(tt), x, INFINITY, 1.0);
        gs_fit_add(&b, US(tt), x + 500.0, y, NAN);
        gs_fit_add(&b, US(tt), x + 500.0, y, 0.0);
        gs_fit_add(&b, US(tt), x + 500.0, y, -1.0);
        gs_fit_add(&b, US(tt), x + 500.0, y, INFINITY);
    }
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&a, &ra));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&b, &rb));
    TEST_ASSERT_EQUAL_UINT32(40, rb.n);
    /* Field by field (the struct has padding): identical, not merely close. */
    TEST_ASSERT_EQUAL_MEMORY(&ra.x0_px, &rb.x0_px, sizeof ra.x0_px);
    TEST_ASSERT_EQUAL_MEMORY(&ra.vy_px_s, &rb.vy_px_s, sizeof ra.vy_px_s);
    TEST_ASSERT_EQUAL_MEMORY(&ra.a_px_s2, &rb.a_px_s2, sizeof ra.a_px_s2);
    TEST_ASSERT_EQUAL_MEMORY(&ra.a_se_px_s2, &rb.a_se_px_s2, sizeof ra.a_se_px_s2);
    TEST_ASSERT_EQUAL_MEMORY(&ra.g_dir_deg, &rb.g_dir_deg, sizeof ra.g_dir_deg);
    TEST_ASSERT_EQUAL_MEMORY(&ra.rms_px, &rb.rms_px, sizeof ra.rms_px);
    /* NULL arguments never crash. */
    gs_fit_init(NULL, 0, 1000000);
    gs_fit_add(NULL, 0, 1.0, 1.0, 1.0);
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_solve(NULL, &ra));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_solve(&a, NULL));
}

/* A bad centre becomes 0, a bad scale 1 s; an unknown time is ignored; times at the
 * limits of the range neither overflow nor change the fit of the others. */
static void test_init_and_add_limits(void)
{
    static const struct { int64_t t0_us, tscale_us, want_t0_us; double want_tscale_s; } rows[] = {
        {5000000, 250000, 5000000, 0.25},
        {-7, 1, -7, 1e-6},
        {GS_T_MAX_US, 2147483647, GS_T_MAX_US, 2147.483647},
        {-GS_T_MAX_US, 1000000, -GS_T_MAX_US, 1.0},
        {GS_T_NONE, 1000000, 0, 1.0},
        {GS_T_MAX_US + 1, 1000000, 0, 1.0},
        {INT64_MAX, 0, 0, 1.0},
        {3, 0, 3, 1.0},
        {3, -5, 3, 1.0},
        {3, GS_T_NONE, 3, 1.0},
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        gs_fit f;
        gs_fit_init(&f, rows[k].t0_us, rows[k].tscale_us);
        TEST_ASSERT_TRUE_MESSAGE(f.t0_us == rows[k].want_t0_us, "t0 row");
        TEST_ASSERT_DOUBLE_WITHIN(1e-12 * rows[k].want_tscale_s, rows[k].want_tscale_s, f.tscale_s);
        TEST_ASSERT_EQUAL_UINT32(0, f.n);
    }
    /* a parabola sampled every 10 ms, centred far from zero; junk times interleaved */
    gs_fit a, b;
    gs_fit_result ra, rb;
    const int64_t t0 = GS_T_MAX_US - 1000000;
    gs_fit_init(&a, t0, 500000);
    gs_fit_init(&b, t0, 500000);
    for (int i = 0; i < 50; i++) {
        double tt = 0.01 * (i - 25);
        int64_t t = t0 + (int64_t)(i - 25) * 10000;
        gs_fit_add(&a, t, 3.0 * tt, 100.0 - 200.0 * tt + 490.0 * tt * tt, 1.0);
        gs_fit_add(&b, t, 3.0 * tt, 100.0 - 200.0 * tt + 490.0 * tt * tt, 1.0);
        gs_fit_add(&b, GS_T_NONE, 1e6, 1e6, 1.0);
    }
    gs_fit_add(&a, -GS_T_MAX_US, 0.0, 0.0, 1e-300);  /* 2^63 us from the centre: no overflow, no effect */
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&a, &ra));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_solve(&b, &rb));
    TEST_ASSERT_EQUAL_UINT32(51, ra.n);
    TEST_ASSERT_EQUAL_UINT32(50, rb.n);
    TEST_ASSERT_TRUE(rb.t0_us == t0);
    TEST_ASSERT_DOUBLE_WITHIN(980.0 * 1e-9, 980.0, rb.ay_px_s2);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, -200.0, rb.vy_px_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 3.0, rb.vx_px_s);
    TEST_ASSERT_DOUBLE_WITHIN(980.0 * 1e-6, 980.0, ra.ay_px_s2);
}

static void test_robust_nan_samples_and_bad_args(void)
{
    gs_ring r;
    gs_fit_result res, ref;
    static uint32_t w[RING_CAP / 32];
    throw_cfg c = {0.0, 981.0, 0.5, 100.0, 10.0};
    gs_sample_full bad;
    uint32_t i;
    rng_seed(17);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, ring_store, RING_CAP));
    push_throw(&r, &c, 30, 0);
    bad = mk_sample(10.295, NAN, 3.0, 1.0);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&r, &bad));
    bad = mk_sample(NAN, 3.0, 3.0, 1.0);  /* a time the ring cannot hold */
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_push(&r, &bad));
    bad = mk_sample(10.297, 3.0, 3.0, 0.0);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&r, &bad));
    bad = mk_sample(10.1, 3.0, 3.0, 1.0);  /* older than the newest */
    TEST_ASSERT_EQUAL_INT(GS_EORDER, gs_ring_push(&r, &bad));
    push_throw(&r, &c, 30, 30);
    TEST_ASSERT_EQUAL_UINT64(62, gs_ring_head(&r));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, 62, GS_FIT_PLAIN, 0.5f, w, &res));
    TEST_ASSERT_EQUAL_UINT32(60, res.n);
    TEST_ASSERT_FALSE(gs_fit_kept(w, 30));
    TEST_ASSERT_FALSE(gs_fit_kept(w, 31));
    TEST_ASSERT_TRUE(gs_fit_kept(w, 32));
    TEST_ASSERT_EQUAL_INT(GS_OK, direct_fit(&r, 0, 62, res.t0_us, NULL, &ref));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 981.0, ref.a_px_s2, res.a_px_s2);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, 62, GS_FIT_IRLS, 0.5f, w, &res));
    TEST_ASSERT_EQUAL_UINT32(60, res.n);
    TEST_ASSERT_DOUBLE_WITHIN(5.0 * res.a_se_px_s2, 981.0, res.a_px_s2);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_fit_robust(&r, 0, 62, GS_FIT_RANSAC, 0.5f, w, &res));
    TEST_ASSERT_DOUBLE_WITHIN(5.0 * res.a_se_px_s2, 981.0, res.a_px_s2);
    for (i = 30; i < 32; i++) {
        TEST_ASSERT_FALSE(gs_fit_kept(w, i));
    }
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(NULL, 0, 63, GS_FIT_IRLS, 0.5f, w, &res));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 0, 62, GS_FIT_IRLS, 0.5f, NULL, &res));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 0, 62, GS_FIT_IRLS, 0.5f, w, NULL));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 0, 0, GS_FIT_IRLS, 0.5f, w, &res));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_fit_robust(&r, 0, 62, (gs_fit_method)7, 0.5f, w, &res));
}

/* ---- method names ---------------------------------------------------------------------------- */

static void test_method_names(void)
{
    static const struct {
        const char *s;
        size_t len;
        bool ok;
        gs_fit_method m;
    } cases[] = {
        {"irls", 4, true, GS_FIT_IRLS},
        {"ransac", 6, true, GS_FIT_RANSAC},
        {"plain", 5, true, GS_FIT_PLAIN},
        {"plainly", 5, true, GS_FIT_PLAIN}, /* only len characters count */
        {"plainly", 7, false, GS_FIT_IRLS},
        {"irl", 3, false, GS_FIT_IRLS},
        {"irls", 3, false, GS_FIT_IRLS},
        {"IRLS", 4, false, GS_FIT_IRLS},
        {"", 0, false, GS_FIT_IRLS},
        {"ransac\0x", 8, false, GS_FIT_IRLS},
    };
    size_t k;
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        gs_fit_method m = (gs_fit_method)99;
        bool ok = gs_fit_method_from_name(cases[k].s, cases[k].len, &m);
        TEST_ASSERT_EQUAL_MESSAGE(cases[k].ok, ok, cases[k].s);
        if (ok) {
            TEST_ASSERT_EQUAL_INT_MESSAGE(cases[k].m, m, cases[k].s);
        } else {
            TEST_ASSERT_EQUAL_INT_MESSAGE(99, m, cases[k].s);
        }
    }
    TEST_ASSERT_EQUAL_STRING("irls", gs_fit_method_name(GS_FIT_IRLS));
    TEST_ASSERT_EQUAL_STRING("ransac", gs_fit_method_name(GS_FIT_RANSAC));
    TEST_ASSERT_EQUAL_STRING("plain", gs_fit_method_name(GS_FIT_PLAIN));
    TEST_ASSERT_FALSE(gs_fit_method_from_name(NULL, 4, &(gs_fit_method){GS_FIT_IRLS}));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_stream_matches_batch_reference);
    RUN_TEST(test_stream_extreme_tscale_exact);
    RUN_TEST(test_exact_parabola_and_g_direction);
    RUN_TEST(test_three_samples_exact_without_se);
    RUN_TEST(test_init_and_add_limits);
    RUN_TEST(test_se_calibration);
    RUN_TEST(test_ring_window_across_wrap);
    RUN_TEST(test_window_partly_overwritten_is_einval);
    RUN_TEST(test_robust_gross_outliers);
    RUN_TEST(test_robust_without_outliers_matches_plain);
    RUN_TEST(test_robust_exact_data_keeps_everything);
    RUN_TEST(test_robust_keep_bits_every_length);
    RUN_TEST(test_degenerate_table);
    RUN_TEST(test_nan_inputs_are_ignored);
    RUN_TEST(test_robust_nan_samples_and_bad_args);
    RUN_TEST(test_method_names);
    printf("summary: max rel dev vs batch %.3g; robust worst |a| rel err irls %.5f ransac %.5f, plain best %.4f\n",
           g_max_rel_dev, g_rob_irls_err, g_rob_ransac_err, g_rob_plain_err);
    return UNITY_END();
}
