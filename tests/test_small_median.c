/* test_small_median.c - the core's branch-free small medians (src/core/gs_median.h,
 * src/core/gs_select.h) against the compare-and-swap and the sort they replace:
 * medians of three over every triple of special values (NaN of both signs, +-0,
 * +-inf) and random ones, bit for bit; the rank selection of float keys against
 * a sort for random and tied sets of 1..32 values. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "../src/core/gs_median.h"
#include "../src/core/gs_select.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static uint32_t g_rng = 2463534242u;
static uint32_t next_u32(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 17;
    g_rng ^= g_rng << 5;
    return g_rng;
}

static float swap_med3_f(float a, float b, float c)
{
    if (a > b) { float t = a; a = b; b = t; }
    if (b > c) b = c;
    return a > b ? a : b;
}

static double swap_med3_d(double a, double b, double c)
{
    if (a > b) { double t = a; a = b; b = t; }
    if (b > c) b = c;
    return a > b ? a : b;
}

static void check3(float a, float b, float c)
{
    float want = swap_med3_f(a, b, c), got = gs_med3_f(a, b, c);
    double want_d = swap_med3_d(a, b, c), got_d = gs_med3_d(a, b, c);
    TEST_ASSERT_EQUAL_MEMORY(&want, &got, sizeof want);
    TEST_ASSERT_EQUAL_MEMORY(&want_d, &got_d, sizeof want_d);
}

static void test_med3_special_and_random(void)
{
    const float v[] = {0.0f, -0.0f, 1.0f, -1.0f, 2.5f, NAN, -NAN, INFINITY, -INFINITY};
    const int n = (int)(sizeof v / sizeof v[0]);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            for (int k = 0; k < n; k++) check3(v[i], v[j], v[k]);
    for (int r = 0; r < 100000; r++) {
        float a = (float)(next_u32() % 2001u) * 0.01f - 10.0f;
        float b = (float)(next_u32() % 2001u) * 0.01f - 10.0f;
        float c = (float)(next_u32() % 2001u) * 0.01f - 10.0f;
        check3(a, b, c);
    }
}

static int cmp_float(const void *x, const void *y)
{
    float a = *(const float *)x, b = *(const float *)y;
    return (a > b) - (a < b);
}

static void test_rank_select_of_floats(void)
{
#if GS_SELECT_AVX2
    if (!gs_select_avx2()) TEST_IGNORE_MESSAGE("no AVX2 on this CPU");
    for (int r = 0; r < 20000; r++) {
        uint32_t n = 1u + next_u32() % 32u, key[32] = {0}, levels = r & 1 ? 5u : 100000u;
        float v[32], sorted[32];
        for (uint32_t i = 0; i < n; i++) {
            v[i] = ((float)(next_u32() % levels) - (float)(levels / 2u)) * 0.125f;
            sorted[i] = v[i];
            key[i] = gs_select_float_key(v[i]);
        }
        qsort(sorted, n, sizeof sorted[0], cmp_float);
        for (uint32_t k = 0; k < n; k++) {
            uint32_t at = next_u32() % (n + 1u);
            TEST_ASSERT_EQUAL_FLOAT(sorted[k], gs_select_key_float(gs_select_rank_avx2(key, n, k, &at)));
        }
    }
    TEST_ASSERT_EQUAL_HEX32(0x80000000u, gs_select_float_key(-0.0f));
    TEST_ASSERT_TRUE(gs_select_float_key(-1.0f) < gs_select_float_key(0.0f));
    TEST_ASSERT_TRUE(gs_select_float_key(-2.0f) < gs_select_float_key(-1.0f));
#else
    TEST_IGNORE_MESSAGE("no AVX2 rank selection in this build");
#endif
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_med3_special_and_random);
    RUN_TEST(test_rank_select_of_floats);
    return UNITY_END();
}
