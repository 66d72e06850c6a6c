/* test_agg.c - gs_agg: median and 95 % interval. Monte Carlo coverage against
 * a known truth (1.75 m, heteroscedastic per-flight SE 0.5-3 cm, 10 % outlier
 * flights shifted by +10 cm), the median against the mean, the bounded window
 * (oldest flights drop out), non-finite input, canaries around the struct. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "unity.h"
#include "gravscale/gs_agg.h"

void setUp(void) {}
void tearDown(void) {}

/* splitmix64: fixed-seed, portable */
static uint64_t g_rng = 0x9E3779B97F4A7C15ull;
static uint64_t rng_u64(void)
{
    uint64_t z = (g_rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double rng_unif(void) { return ((double)(rng_u64() >> 11) + 0.5) * (1.0 / 9007199254740992.0); }
static double rng_norm(void)
{
    double u1 = rng_unif(), u2 = rng_unif();
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

static void test_empty_is_unknown(void)
{
    gs_agg a;
    gs_ev_height h;
    gs_agg_init(&a);
    gs_agg_get(&a, &h);
    TEST_ASSERT_TRUE(isnan(h.height_m) && isnan(h.ci95_lo_m) && isnan(h.ci95_hi_m));
    TEST_ASSERT_EQUAL_UINT32(0, h.n_jumps);
    TEST_ASSERT_EQUAL_UINT32(0, h.n_rejected);
    gs_agg_reject(&a);
    gs_agg_reject(&a);
    gs_agg_get(&a, &h);
    TEST_ASSERT_TRUE(isnan(h.height_m));
    TEST_ASSERT_EQUAL_UINT32(2, h.n_rejected);
    /* NULL safety */
    gs_agg_init(NULL);
    gs_agg_add(NULL, 1.0, 0.1);
    gs_agg_reject(NULL);
    gs_agg_get(NULL, &h);
    TEST_ASSERT_TRUE(isnan(h.height_m));
    gs_agg_get(&a, NULL);
}

static void test_single_flight_interval(void)
{
    gs_agg a;
    gs_ev_height h;
    gs_agg_init(&a);
    gs_agg_add(&a, 1.80, 0.02);
    gs_agg_get(&a, &h);
    double half = 1.96 * sqrt(0.02 * 0.02 + (0.03 * 1.80) * (0.03 * 1.80));
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.80, h.height_m);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.80 - half, h.ci95_lo_m);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.80 + half, h.ci95_hi_m);
    TEST_ASSERT_EQUAL_UINT32(1, h.n_jumps);
    /* never narrower than +/- 1.96 se */
    TEST_ASSERT_TRUE(h.ci95_hi_m - h.height_m >= 1.96 * 0.02);
}

static void test_two_equal_flights_use_known_se(void)
{
    gs_agg a;
    gs_ev_height h;
    gs_agg_init(&a);
    gs_agg_add(&a, 1.70, 0.01);
    gs_agg_add(&a, 1.70, 0.01);
    gs_agg_get(&a, &h);
    /* spread 0 < se: sigma = se, normal quantile, median of 2 = mean */
    double half = 1.96 * 0.01 / sqrt(2.0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.70, h.height_m);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, half, h.ci95_hi_m - h.height_m);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, half, h.height_m - h.ci95_lo_m);
}

static void test_median_and_spread_widen(void)
{
    /* Same SEs, one set tight, one scattered: the scattered one must be wider. */
    static const double tight[] = { 1.74, 1.75, 1.76, 1.75, 1.75 };
    static const double loose[] = { 1.60, 1.75, 1.90, 1.70, 1.80 };
    gs_agg a, b;
    gs_ev_height ha, hb;
    gs_agg_init(&a);
    gs_agg_init(&b);
    for (int i = 0; i < 5; i++) {
        gs_agg_add(&a, tight[i], 0.01);
        gs_agg_add(&b, loose[i], 0.01);
    }
    gs_agg_get(&a, &ha);
    gs_agg_get(&b, &hb);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.75, ha.height_m);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.75, hb.height_m);
    TEST_ASSERT_TRUE(hb.ci95_hi_m - hb.ci95_lo_m > 3.0 * (ha.ci95_hi_m - ha.ci95_lo_m));
    /* even count: median of the middle two */
    static const double even[] = { 1.90, 1.60, 1.80, 1.71 };
    gs_agg_init(&a);
    for (int i = 0; i < 4; i++) {
        gs_agg_add(&a, even[i], 0.01);
    }
    gs_agg_get(&a, &ha);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.755, ha.height_m);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* median absolute deviation from the median, by sorting (the reference) */
static double mad_by_sort(const double *v, int n)
{
    double s[GS_AGG_MAX], d[GS_AGG_MAX];
    memcpy(s, v, (size_t)n * sizeof *s);
    qsort(s, (size_t)n, sizeof *s, cmp_double);
    double med = (n & 1) ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
    for (int i = 0; i < n; i++) d[i] = fabs(s[i] - med);
    qsort(d, (size_t)n, sizeof *d, cmp_double);
    return (n & 1) ? d[n / 2] : 0.5 * (d[n / 2 - 1] + d[n / 2]);
}

static void test_spread_follows_mad(void)
{
    /* With zero SEs the half-width is the MAD times a factor of n alone: two sets of one
     * size (heights on a 1 cm grid: ties, both parities) differ in width as in MAD. */
    for (int n = 2; n <= GS_AGG_MAX; n++) {
        double v[2][GS_AGG_MAX], half[2], mad[2];
        for (int k = 0; k < 2; k++) {
            gs_agg a;
            gs_ev_height h;
            gs_agg_init(&a);
            for (int i = 0; i < n; i++) {
                v[k][i] = (double)(float)(1.5 + 0.01 * (double)(rng_u64() % (k ? 40u : 15u)));  /* (held as floats) */
                gs_agg_add(&a, v[k][i], 0.0);
            }
            gs_agg_get(&a, &h);
            half[k] = 0.5 * (h.ci95_hi_m - h.ci95_lo_m);
            mad[k] = mad_by_sort(v[k], n);
        }
        if (mad[0] > 0.0 && mad[1] > 0.0) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-9 * half[1] / mad[1], half[0] / mad[0], half[1] / mad[1]);
        }
    }
}

static void test_non_finite_and_nonpositive_count_as_rejected(void)
{
    static const struct { double v, se; bool accepted; } rows[] = {
        { 1.75, 0.01, true },
        { NAN, 0.01, false },
        { INFINITY, 0.01, false },
        { -INFINITY, 0.01, false },
        { 0.0, 0.01, false },
        { -1.75, 0.01, false },
        { 1.76, NAN, true },   /* unknown SE: kept, spread still counts */
        { 1.74, -0.5, true },  /* negative SE: treated as unknown */
    };
    gs_agg a;
    gs_ev_height h;
    gs_agg_init(&a);
    uint32_t acc = 0, rej = 0;
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        gs_agg_add(&a, rows[r].v, rows[r].se);
        rows[r].accepted ? acc++ : rej++;
        gs_agg_get(&a, &h);
        TEST_ASSERT_EQUAL_UINT32(acc, h.n_jumps);
        TEST_ASSERT_EQUAL_UINT32(rej, h.n_rejected);
        TEST_ASSERT_TRUE(isfinite(h.height_m) && isfinite(h.ci95_lo_m) && isfinite(h.ci95_hi_m));
    }
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 1.75, h.height_m);
    TEST_ASSERT_TRUE(h.ci95_lo_m < 1.75 && h.ci95_hi_m > 1.75);
}

static void test_window_keeps_newest(void)
{
    struct {
        unsigned char pre[32];
        gs_agg a;
        unsigned char post[32];
    } box;
    memset(&box, 0xA5, sizeof box);
    gs_agg_init(&box.a);
    gs_ev_height h;
    /* 10 early flights at 3 m, then GS_AGG_MAX at 1.5..: the early ones must drop out */
    for (int i = 0; i < 10; i++) {
        gs_agg_add(&box.a, 3.0, 0.01);
    }
    for (int i = 0; i < GS_AGG_MAX; i++) {
        gs_agg_add(&box.a, 1.5 + 0.001 * i, 0.01);
    }
    gs_agg_get(&box.a, &h);
    TEST_ASSERT_EQUAL_UINT32(10 + GS_AGG_MAX, h.n_jumps);
    TEST_ASSERT_DOUBLE_WITHIN(1e-5, 1.5 + 0.001 * (GS_AGG_MAX - 1) / 2.0, h.height_m);
    TEST_ASSERT_TRUE(h.ci95_hi_m < 2.0);
    /* wrap several more times: values 1..300, newest 64 are 237..300 */
    gs_agg_init(&box.a);
    for (int i = 1; i <= 300; i++) {
        gs_agg_add(&box.a, (double)i, 0.5);
        gs_agg_get(&box.a, &h);
        int lo = i > GS_AGG_MAX ? i - GS_AGG_MAX + 1 : 1;
        TEST_ASSERT_DOUBLE_WITHIN(1e-3, 0.5 * (lo + i), h.height_m);
    }
    for (size_t k = 0; k < sizeof box.pre; k++) {
        TEST_ASSERT_EQUAL_HEX8(0xA5, box.pre[k]);
        TEST_ASSERT_EQUAL_HEX8(0xA5, box.post[k]);
    }
}

static int cmp_d(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* The interval covers the truth in 90-99 % of runs for every n, and the median
 * beats the mean once there are at least three flights. */
static void test_monte_carlo_coverage(void)
{
    static const int ns[] = { 1, 2, 3, 5, 10 };
    const int runs = 2000;
    const double truth = 1.75;
    g_rng = 12345;
    for (size_t k = 0; k < sizeof ns / sizeof ns[0]; k++) {
        int n = ns[k], covered = 0;
        double err_med = 0, err_mean = 0;
        for (int r = 0; r < runs; r++) {
            gs_agg a;
            gs_agg_init(&a);
            double sum = 0, v[16];
            for (int i = 0; i < n; i++) {
                double se = 0.005 + 0.025 * rng_unif();
                double x = truth + se * rng_norm();
                if (rng_unif() < 0.10) {
                    x += 0.10;
                }
                v[i] = x;
                sum += x;
                gs_agg_add(&a, x, se);
            }
            gs_ev_height h;
            gs_agg_get(&a, &h);
            covered += (h.ci95_lo_m <= truth && truth <= h.ci95_hi_m);
            err_med += fabs(h.height_m - truth);
            err_mean += fabs(sum / n - truth);
            /* the reported median is the sample median */
            qsort(v, (size_t)n, sizeof v[0], cmp_d);
            double med = (n & 1) ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
            TEST_ASSERT_DOUBLE_WITHIN(1e-6, med, h.height_m);
        }
        double cov = (double)covered / runs;
        printf("n=%2d coverage %.4f  MAE median %.2f cm  MAE mean %.2f cm\n", n, cov, 100 * err_med / runs,
               100 * err_mean / runs);
        TEST_ASSERT_TRUE_MESSAGE(cov >= 0.90 && cov <= 0.99, "95 % interval coverage out of 90-99 %");
        if (n >= 3) {
            TEST_ASSERT_TRUE_MESSAGE(err_med < err_mean, "median must beat the mean under outliers");
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_empty_is_unknown);
    RUN_TEST(test_single_flight_interval);
    RUN_TEST(test_two_equal_flights_use_known_se);
    RUN_TEST(test_median_and_spread_widen);
    RUN_TEST(test_spread_follows_mad);
    RUN_TEST(test_non_finite_and_nonpositive_count_as_rejected);
    RUN_TEST(test_window_keeps_newest);
    RUN_TEST(test_monte_carlo_coverage);
    return UNITY_END();
}
