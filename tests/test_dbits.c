/* test_dbits.c - the core's double tests from the IEEE bits (src/core/gs_dbits.h,
 * what the Cortex-M4 firmware uses instead of libgcc's compare and truncation
 * routines) against the native operators: special values (NaN of both signs,
 * +-0, +-inf, subnormals, the largest and smallest doubles, neighbours of
 * integers) in every pair, and a million random bit patterns. */
#include <float.h>
#include <math.h>
#include <stdint.h>
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
    /* the soft-double forms of gs_dlt/dle/dgt/dge (gs_dbits.h), also on a host */
    TEST_ASSERT_EQUAL_INT(a < b, c < 0);
    TEST_ASSERT_EQUAL_INT(a <= b, c <= 0);
    TEST_ASSERT_EQUAL_INT(a > b, c == 1);
    TEST_ASSERT_EQUAL_INT(a >= b, (unsigned)c <= 1u);
    TEST_ASSERT_EQUAL_INT(a < b, gs_dlt(a, b));
    TEST_ASSERT_EQUAL_INT(a <= b, gs_dle(a, b));
    TEST_ASSERT_EQUAL_INT(a > b, gs_dgt(a, b));
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
        TEST_ASSERT_EQUAL_INT(isfinite(x) && x > 0.0, gs_dpositive(x));
    }
    for (int i = 0; i < 200000; i++) {
        double x = from_bits(next_u64());
        TEST_ASSERT_EQUAL_INT(isfinite(x), gs_dfinite(x));
        TEST_ASSERT_EQUAL_INT(isnan(x), gs_disnan(x));
        TEST_ASSERT_EQUAL_INT(isfinite(x) && x > 0.0, gs_dpositive(x));
    }
}

/* trunc(|x|) for |x| < 2^64, as the cast does */
static void test_trunc_abs(void)
{
    static const double k_vals[] = {0.0, -0.0, 0.49999999999999994, 0.5, 0.9999999999999999, 1.0, -1.0, 1.5,
                                    2.5, -2.5, 4503599627370495.5, 4503599627370496.0, 9007199254740993.0,
                                    1e15 + 0.3, 2147483648.0, 4294967295.9, 18446744073709549568.0, 5e-324};
    for (size_t i = 0; i < sizeof k_vals / sizeof k_vals[0]; i++)
        TEST_ASSERT_EQUAL_UINT64((uint64_t)fabs(k_vals[i]), gs_dtrunc_abs(k_vals[i]));
    for (int i = 0; i < 1000000; i++) {
        /* exponents 2^-3 .. 2^63 and both signs */
        uint64_t b = next_u64();
        uint64_t ex = 1020u + (b >> 52) % 67u;
        double x = from_bits((b & 0x800FFFFFFFFFFFFFull) | (ex << 52));
        TEST_ASSERT_EQUAL_UINT64((uint64_t)fabs(x), gs_dtrunc_abs(x));
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_compare_special_pairs);
    RUN_TEST(test_compare_random);
    RUN_TEST(test_predicates);
    RUN_TEST(test_trunc_abs);
    return UNITY_END();
}
