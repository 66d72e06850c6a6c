/* test_time.c - microsecond times (include/gravscale/gs_time.h): spans to seconds,
 * seconds added to a time, configured spans, and the double-seconds edge of the
 * hosts, table-driven with values at and past every limit, and round trips. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gravscale/gs_time.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

#define S_US INT64_C(1000000)
#define T31_US (INT64_C(1) << 31)

static void test_span_s(void)
{
    static const struct { int64_t t1, t0; double want; } rows[] = {
        {0, 0, 0.0},
        {1, 0, 1e-6},
        {0, 1, -1e-6},
        {1500000, 0, 1.5},
        {1000000000 * S_US + 250000, 1000000000 * S_US, 0.25}, /* far from zero: the span is exact */
        {-3 * S_US, 2 * S_US, -5.0},
        {T31_US - 1, 0, 2147.483647},                        /* the largest span of a float build */
        {T31_US, 0, 2147.483648},                            /* double: no saturation */
        {GS_T_NONE, 0, NAN},
        {0, GS_T_NONE, NAN},
        {GS_T_NONE, GS_T_NONE, NAN},
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        gs_real got = gs_time_span_s(rows[k].t1, rows[k].t0);
        char msg[48];
        snprintf(msg, sizeof msg, "span row %u", (unsigned)k);
        if (isnan(rows[k].want)) {
            TEST_ASSERT_TRUE_MESSAGE(isnan(got), msg);
        } else {
            TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(1e-15 * fabs(rows[k].want), rows[k].want, got, msg);
        }
    }
    /* the largest spans inside the range */
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, 4611686018427.387904, gs_time_span_s(GS_T_MAX_US, 0));
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, -4611686018427.387904, gs_time_span_s(0, GS_T_MAX_US));
}

static void test_add_s(void)
{
    static const struct { int64_t t; double ds; int64_t want; } rows[] = {
        {0, 0.0, 0},
        {0, -0.0, 0},
        {-5, 0.0, -5},
        {0, 1e-6, 1},
        {0, -1e-6, -1},
        {0, 4e-7, 0},
        {0, 6e-7, 1},
        {0, -4e-7, 0},
        {0, -6e-7, -1},                                 /* rounded half away from zero, both signs */
        {0, 1.4999e-6, 1},
        {0, 1.5001e-6, 2},
        {0, -1.5001e-6, -2},
        {1000000000 * S_US, 0.0166667, 1000000000 * S_US + 16667},
        {1000000000 * S_US, -0.0166667, 1000000000 * S_US - 16667},
        {7, 2.25, 7 + 2250000},
        {7, -2.25, 7 - 2250000},
        {0, 2147483647.0, 2147483647 * S_US},            /* just below 2^31 s */
        {0, -2147483647.0, -2147483647 * S_US},
        {0, 2147483647.9999995, 2147483648 * S_US},      /* the whole seconds and the rounded rest */
        {0, 2147483648.0, GS_T_NONE},                    /* |ds| >= 2^31 s: refused */
        {0, -2147483648.0, GS_T_NONE},
        {0, 1e300, GS_T_NONE},
        {0, NAN, GS_T_NONE},
        {0, INFINITY, GS_T_NONE},
        {0, -INFINITY, GS_T_NONE},
        {GS_T_NONE, 1.0, GS_T_NONE},
        {GS_T_NONE, 0.0, GS_T_NONE},
        {GS_T_MAX_US, 1.0, GS_T_MAX_US + S_US},          /* at the limit: still no overflow */
        {-GS_T_MAX_US, -1.0, -GS_T_MAX_US - S_US},
        {GS_T_MAX_US + 1, 0.0, GS_T_NONE},               /* no time is beyond it */
        {INT64_MAX, 2147483647.0, GS_T_NONE},
        {INT64_MIN + 1, -2147483647.0, GS_T_NONE},
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        char msg[48];
        snprintf(msg, sizeof msg, "add row %u", (unsigned)k);
        TEST_ASSERT_TRUE_MESSAGE(gs_time_add_s(rows[k].t, (gs_real)rows[k].ds) == rows[k].want, msg);
    }
}

static void test_us_of_cfg_s(void)
{
    static const struct { float s; int64_t want; } rows[] = {
        {0.0f, 0},
        {-0.0f, 0},
        {1e-6f, 1},
        {4e-7f, 0},
        {6e-7f, 1},
        {0.12f, 120000},
        {0.2f, 200000},
        {0.5f, 500000},
        {1.5f, 1500000},
        {2.5f, 2500000},
        {600.0f, 600 * S_US},
        {2147483520.0f, 2147483520 * S_US},  /* the largest float below 2^31 */
        {2147483648.0f, GS_T_NONE},
        {-1e-6f, GS_T_NONE},
        {-1.0f, GS_T_NONE},
        {NAN, GS_T_NONE},
        {INFINITY, GS_T_NONE},
        {-INFINITY, GS_T_NONE},
        {FLT_MAX, GS_T_NONE},
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        char msg[48];
        snprintf(msg, sizeof msg, "cfg row %u", (unsigned)k);
        TEST_ASSERT_TRUE_MESSAGE(gs_time_us_of_cfg_s(rows[k].s) == rows[k].want, msg);
    }
    /* every 61st float in [0, 2^31): the nearest microsecond (the double product is exact) */
    for (uint32_t b = 0; b < 0x4F000000u; b += 61u) {
        float s;
        memcpy(&s, &b, sizeof s);
        if (gs_time_us_of_cfg_s(s) != (int64_t)llround((double)s * 1e6)) {
            char msg[48];
            snprintf(msg, sizeof msg, "cfg float bits 0x%08x", (unsigned)b);
            TEST_FAIL_MESSAGE(msg);
        }
    }
    /* every configured span of 1 ms steps up to 10 s: the nearest microsecond of the float */
    for (int ms = 0; ms <= 10000; ms++) {
        float s = (float)ms / 1000.0f;
        int64_t want = (int64_t)llround((double)s * 1e6);
        TEST_ASSERT_TRUE(gs_time_us_of_cfg_s(s) == want);
    }
}

static void test_us_of_s_and_back(void)
{
    const double lim_s = (double)GS_T_MAX_US / 1e6; /* rounds to the double whose product is 2^62 */
    static const struct { double s; int64_t want; } rows[] = {
        {0.0, 0},
        {-0.0, 0},
        {1.5, 1500000},
        {-1.5, -1500000},
        {4e-7, 0},
        {-4e-7, 0},
        {6e-7, 1},
        {-6e-7, -1},
        {1000.0 + 1.0 / 60.0, 1000016667},
        {86400.0 * 365.0, 31536000 * S_US},
        {1e13, GS_T_NONE},
        {-1e13, GS_T_NONE},
        {NAN, GS_T_NONE},
        {-NAN, GS_T_NONE},
        {INFINITY, GS_T_NONE},
        {-INFINITY, GS_T_NONE},
        {DBL_MAX, GS_T_NONE},
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        char msg[48];
        snprintf(msg, sizeof msg, "of_s row %u", (unsigned)k);
        TEST_ASSERT_TRUE_MESSAGE(gs_time_us_of_s(rows[k].s) == rows[k].want, msg);
    }
    /* the limit: 2^62 us is taken, the next double beyond it is not */
    TEST_ASSERT_TRUE(gs_time_us_of_s(lim_s) == GS_T_MAX_US);
    TEST_ASSERT_TRUE(gs_time_us_of_s(-lim_s) == -GS_T_MAX_US);
    TEST_ASSERT_TRUE(gs_time_us_of_s(nextafter(lim_s, INFINITY)) == GS_T_NONE);
    TEST_ASSERT_TRUE(gs_time_us_of_s(nextafter(-lim_s, -INFINITY)) == GS_T_NONE);
    /* seconds of a time: NaN for the unknown one */
    TEST_ASSERT_TRUE(isnan(gs_time_s_of_us(GS_T_NONE)));
    TEST_ASSERT_EQUAL_DOUBLE(1.5, gs_time_s_of_us(1500000));
    TEST_ASSERT_EQUAL_DOUBLE(-1e-6, gs_time_s_of_us(-1));
    TEST_ASSERT_EQUAL_DOUBLE(4611686018427.387904, gs_time_s_of_us(GS_T_MAX_US));
    /* round trips: any time below 2^50 us (35 years) comes back exactly */
    uint64_t st = 0xC0FFEE1234567ull;
    for (int i = 0; i < 1000000; i++) {
        st ^= st << 13;
        st ^= st >> 7;
        st ^= st << 17;
        int64_t t = (int64_t)(st >> 14) - (INT64_C(1) << 49);
        if (gs_time_us_of_s(gs_time_s_of_us(t)) != t) {
            char msg[64];
            snprintf(msg, sizeof msg, "round trip of %lld us", (long long)t);
            TEST_FAIL_MESSAGE(msg);
        }
        /* and seconds to microseconds and back are within half a microsecond */
        double s = (double)(int64_t)(st % 200000000000ull) / 1000.0 - 1e8 + 0.000123;
        TEST_ASSERT_DOUBLE_WITHIN(0.5e-6 + 1e-16 * fabs(s), s, gs_time_s_of_us(gs_time_us_of_s(s)));
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_span_s);
    RUN_TEST(test_add_s);
    RUN_TEST(test_us_of_cfg_s);
    RUN_TEST(test_us_of_s_and_back);
    return UNITY_END();
}
