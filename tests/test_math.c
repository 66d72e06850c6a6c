/* test_math.c - the float functions of gs_math.c (used where gs_real is float)
 * against libm's double functions as the reference. */
#include "gravscale/gs_math.h"
#include "unity.h"

#include <math.h>

void setUp(void) {}
void tearDown(void) {}

static uint32_t g_rng = 12345u;
static float rnd_unit(void)
{
    g_rng = g_rng * 1664525u + 1013904223u;
    return (float)(g_rng >> 8) * (1.0f / 16777216.0f);
}

static void test_acos_grid(void)
{
    double worst = 0.0;
    for (int i = -200000; i <= 200000; i++) {
        float x = (float)i / 200000.0f;
        double e = fabs((double)gs_acosf(x) - acos((double)x));
        if (e > worst) worst = e;
    }
    TEST_ASSERT_TRUE(worst < 4e-7);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, gs_acosf(1.0f));
    TEST_ASSERT_TRUE(isnan(gs_acosf(1.0001f)));
    TEST_ASSERT_TRUE(isnan(gs_acosf(-2.0f)));
    TEST_ASSERT_TRUE(isnan(gs_acosf(NAN)));
}

static void test_atan2_random(void)
{
    double worst = 0.0;
    for (int i = 0; i < 1000000; i++) {
        float y = (2.0f * rnd_unit() - 1.0f) * powf(10.0f, (float)(i % 13 - 6));
        float x = (2.0f * rnd_unit() - 1.0f) * powf(10.0f, (float)(i % 7 - 3));
        double e = fabs((double)gs_atan2f(y, x) - atan2((double)y, (double)x));
        if (e > worst) worst = e;
    }
    TEST_ASSERT_TRUE(worst < 4e-7);
}

static void test_atan2_special(void)
{
    TEST_ASSERT_EQUAL_FLOAT(0.0f, gs_atan2f(0.0f, 1.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.14159265f, gs_atan2f(0.0f, -1.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, -3.14159265f, gs_atan2f(-0.0f, -1.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.5707963f, gs_atan2f(1.0f, 0.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, -1.5707963f, gs_atan2f(-3.0f, 0.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.78539816f, gs_atan2f(INFINITY, INFINITY));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.5707963f, gs_atan2f(INFINITY, 5.0f));
    TEST_ASSERT_EQUAL_FLOAT(0.0f, gs_atan2f(0.0f, 0.0f));
    TEST_ASSERT_TRUE(isnan(gs_atan2f(NAN, 1.0f)));
    TEST_ASSERT_TRUE(isnan(gs_atan2f(1.0f, NAN)));
    /* the exact boundary of the reduction and of the quadrants */
    TEST_ASSERT_FLOAT_WITHIN(2e-7f, (float)atan(0.267949192431123), gs_atan2f(0.267949192431123f, 1.0f));
    TEST_ASSERT_FLOAT_WITHIN(2e-7f, (float)(3.0 * atan(1.0)), gs_atan2f(1.0f, -1.0f));
}

static void test_sin_cos(void)
{
    double ws = 0.0, wc = 0.0;
    for (int i = -400000; i <= 400000; i++) {
        float x = (float)i * (4.0f * 3.14159265f / 400000.0f);
        double es = fabs((double)gs_sinf(x) - sin((double)x));
        double ec = fabs((double)gs_cosf(x) - cos((double)x));
        if (es > ws) ws = es;
        if (ec > wc) wc = ec;
    }
    TEST_ASSERT_TRUE(ws < 6e-7);
    TEST_ASSERT_TRUE(wc < 6e-7);
    /* where the core uses them: latitudes and gate angles up to 90 degrees */
    for (int d = 0; d <= 90; d++) {
        float r = (float)d * (3.14159265f / 180.0f);
        TEST_ASSERT_FLOAT_WITHIN(2e-7f, (float)sin((double)r), gs_sinf(r));
        TEST_ASSERT_FLOAT_WITHIN(2e-7f, (float)cos((double)r), gs_cosf(r));
    }
    TEST_ASSERT_TRUE(isnan(gs_sinf(INFINITY)));
    TEST_ASSERT_TRUE(isnan(gs_cosf(NAN)));
    TEST_ASSERT_EQUAL_FLOAT(1.0f, gs_cosf(0.0f));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_acos_grid);
    RUN_TEST(test_atan2_random);
    RUN_TEST(test_atan2_special);
    RUN_TEST(test_sin_cos);
    return UNITY_END();
}
