/* test_dbits.c - the core's double tests from the IEEE bits (src/core/gs_dbits.h,
 * what the Cortex-M4 firmware uses instead of libgcc's compare and conversion
 * routines) against the native operators: special values (NaN of both signs,
 * +-0, +-inf, subnormals, the largest and smallest doubles, neighbours of
 * integers) in every pair, and a million random bit patterns; and the float to
 * double widening from the bits. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "../src/core/gs_dbits.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static double from_bits(uint64_t b)
{
    double x;
    memcpy(&x, &b, sizeof x);
    return x;
}

static uint64_t g_rng = 0x9E3779B97F4A7C15ull;
static uint64_t next_u64(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return g_rng;
}

static const double k_special[] = {
    0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.0, 1e-300, -1e-300, 5e-324, -5e-324, 2.2250738585072009e-308,
    DBL_MIN, -DBL_MIN, DBL_MAX, -DBL_MAX, INFINITY, -INFINITY, NAN, -NAN, 4503599627370496.5,
    9007199254740993.0, 18446744073709549568.0, 0.9999999999999999, 1.0000000000000002, 123456.789,
};
#define N_SPECIAL (sizeof k_special / sizeof k_special[0])

static int native_cmp(double a, double b)
{
    if (isnan(a) || isnan(b)) return 2;
    return (a > b) - (a < b);
}

static void check_pair(double a, double b)
{
    int c = gs_dcmp(a, b);
    TEST_ASSERT_EQUAL_INT(native_cmp(a, b), c);
    /* the soft-double forms of gs_dle/dge (gs_dbits.h) and of < and >, also on a host */
    TEST_ASSERT_EQUAL_INT(a < b, c < 0);
    TEST_ASSERT_EQUAL_INT(a <= b, c <= 0);
    TEST_ASSERT_EQUAL_INT(a > b, c == 1);
    TEST_ASSERT_EQUAL_INT(a >= b, (unsigned)c <= 1u);
    TEST_ASSERT_EQUAL_INT(a <= b, gs_dle(a, b));
    TEST_ASSERT_EQUAL_INT(a >= b, gs_dge(a, b));
}

static void test_compare_special_pairs(void)
{
    for (size_t i = 0; i < N_SPECIAL; i++)
        for (size_t j = 0; j < N_SPECIAL; j++) check_pair(k_special[i], k_special[j]);
}

static void test_compare_random(void)
{
    for (int i = 0; i < 1000000; i++) {
        double a = from_bits(next_u64());
        /* half the pairs close together, where the order is decided by the low bits */
        double b = (i & 1) ? from_bits(next_u64()) : from_bits(gs_dbits(a) + (next_u64() % 5u) - 2u);
        check_pair(a, b);
    }
}

static void test_predicates(void)
{
    for (size_t i = 0; i < N_SPECIAL; i++) {
        double x = k_special[i];
        TEST_ASSERT_EQUAL_INT(isfinite(x), gs_dfinite(x));
        TEST_ASSERT_EQUAL_INT(isnan(x), gs_disnan(x));
    }
    for (int i = 0; i < 200000; i++) {
        double x = from_bits(next_u64());
        TEST_ASSERT_EQUAL_INT(isfinite(x), gs_dfinite(x));
        TEST_ASSERT_EQUAL_INT(isnan(x), gs_disnan(x));
    }
}

static uint64_t dbits_of(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

/* (double)f from the bits: every subnormal and every exponent, the specials, a
 * million random floats; bit for bit the conversion's result (a signalling NaN's
 * conversion also sets the quiet bit, which gs_dwiden keeps as it was) */
static void check_widen(uint32_t fb)
{
    float f;
    memcpy(&f, &fb, sizeof f);
    uint64_t got = dbits_of(gs_dwiden(f)), want = dbits_of((double)f);
    if (isnan(f)) got |= 1ull << 51;
    if (got != want) {
        char msg[64];
        snprintf(msg, sizeof msg, "float bits 0x%08x", (unsigned)fb);
        TEST_FAIL_MESSAGE(msg);
    }
}

static void test_widen_float(void)
{
    static const uint32_t k_bits[] = {0x00000000u, 0x80000000u, 0x00000001u, 0x80000001u, 0x007FFFFFu,
                                      0x00800000u, 0x3F800000u, 0xBF800000u, 0x7F7FFFFFu, 0xFF7FFFFFu,
                                      0x7F800000u, 0xFF800000u, 0x7FC00000u, 0xFFC00000u, 0x7F800001u,
                                      0x7FFFFFFFu, 0xFFBFFFFFu, 0x3EAAAAABu, 0x4B189680u};
    for (size_t i = 0; i < sizeof k_bits / sizeof k_bits[0]; i++) check_widen(k_bits[i]);
    for (uint32_t m = 0; m < 0x800000u; m++) {  /* every subnormal, both signs */
        check_widen(m);
        check_widen(m | 0x80000000u);
    }
    for (uint32_t e = 0; e < 256u; e++)  /* every exponent with a few mantissas */
        for (uint32_t k = 0; k < 64u; k++) check_widen(e << 23 | ((uint32_t)next_u64() & 0x807FFFFFu));
    for (int i = 0; i < 1000000; i++) check_widen((uint32_t)next_u64());
    TEST_ASSERT_TRUE(isnan(gs_dwiden(NAN)));
    TEST_ASSERT_TRUE(gs_dwiden(-0.0f) == 0.0 && signbit(gs_dwiden(-0.0f)));
    TEST_ASSERT_TRUE(gs_dwiden(FLT_TRUE_MIN) == 0x1p-149);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_compare_special_pairs);
    RUN_TEST(test_compare_random);
    RUN_TEST(test_predicates);
    RUN_TEST(test_widen_float);
    return UNITY_END();
}
