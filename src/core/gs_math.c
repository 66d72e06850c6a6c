/* gs_math.c - single-precision atan2, acos, sin and cos for float builds (gs_math.h).
 * Plain series after an argument reduction, evaluated by Horner's rule; no tables. */
#include "gravscale/gs_math.h"

#include <math.h>

#define PI_F      3.14159265358979f
#define PI_2_F    1.57079632679490f
#define PI_6_F    0.523598775598299f
#define TAN_PI_12 0.267949192431123f  /* 2 - sqrt(3) */
#define SQRT3_F   1.73205080756888f

/* atan(a) for 0 <= a <= 1 */
static float atan01(float a)
{
    float off = 0.0f;
    if (a > TAN_PI_12) {
        /* atan(a) = pi/6 + atan((a sqrt3 - 1) / (a + sqrt3)); the new argument is within tan(pi/12) */
        a = (a * SQRT3_F - 1.0f) / (a + SQRT3_F);
        off = PI_6_F;
    }
    /* odd Taylor series to a^11: the next term is below 3e-9 for |a| <= tan(pi/12) */
    float z = a * a;
    float p = -1.0f / 11.0f;
    p = p * z + 1.0f / 9.0f;
    p = p * z - 1.0f / 7.0f;
    p = p * z + 1.0f / 5.0f;
    p = p * z - 1.0f / 3.0f;
    return off + (a + a * z * p);
}

float gs_atan2f(float y, float x)
{
    float ay = fabsf(y), ax = fabsf(x), r;
    if (isnan(x) || isnan(y)) return x + y;
    if (ay == 0.0f && ax == 0.0f) r = 0.0f;
    else if (isinf(ay) && isinf(ax)) r = PI_2_F * 0.5f;
    else if (ay <= ax) r = atan01(ay / ax);
    else r = PI_2_F - atan01(ax / ay);
    if (signbit(x)) r = PI_F - r;
    return signbit(y) ? -r : r;
}

float gs_acosf(float x)
{
    if (!(x >= -1.0f && x <= 1.0f)) return NAN;
    return gs_atan2f(sqrtf((1.0f - x) * (1.0f + x)), x);
}

/* sin(x) and cos(x) for |x| <= pi/4 (Taylor to x^11 / x^12: error below 1e-10) */
static float sin_q(float x)
{
    float z = x * x;
    float p = -1.0f / 39916800.0f;
    p = p * z + 1.0f / 362880.0f;
    p = p * z - 1.0f / 5040.0f;
    p = p * z + 1.0f / 120.0f;
    p = p * z - 1.0f / 6.0f;
    return x + x * z * p;
}

static float cos_q(float x)
{
    float z = x * x;
    float p = 1.0f / 479001600.0f;
    p = p * z - 1.0f / 3628800.0f;
    p = p * z + 1.0f / 40320.0f;
    p = p * z - 1.0f / 720.0f;
    p = p * z + 1.0f / 24.0f;
    p = p * z - 0.5f;
    return 1.0f + z * p;
}

/* x = k pi/2 + r with |r| <= pi/4 (a little more at ties); k mod 4 in *quad. The
 * reduction is in float (pi/2 split into two parts): exact enough for the small
 * arguments the core has (|x| < 1e6 at all). */
static float reduce(float x, int *quad)
{
    float t = x * (2.0f / PI_F);
    long n = (long)(t + (t < 0.0f ? -0.5f : 0.5f));  /* nearest, ties away (no rintf) */
    float k = (float)n;
    *quad = (int)(n & 3);
    return (x - k * 1.57079625129700f) - k * 7.54978995489e-8f;
}

float gs_sinf(float x)
{
    if (!isfinite(x)) return x - x;
    int q;
    float r = reduce(x, &q);
    switch (q) {
    case 0: return sin_q(r);
    case 1: return cos_q(r);
    case 2: return -sin_q(r);
    default: return -cos_q(r);
    }
}

float gs_cosf(float x)
{
    if (!isfinite(x)) return x - x;
    int q;
    float r = reduce(x, &q);
    switch (q) {
    case 0: return cos_q(r);
    case 1: return -sin_q(r);
    case 2: return -cos_q(r);
    default: return sin_q(r);
    }
}
