/* gs_math.c - single-precision atan2, acos, sin and cos for float builds (gs_math.h).
 * Plain series after an argument reduction, evaluated by Horner's rule (no lookup tables). */
#include "gravscale/gs_math.h"

#include <math.h>
#include <stdbool.h>

#include "gs_finite.h"

#define PI_F      3.14159265358979f
#define PI_2_F    1.57079632679490f
#define PI_6_F    0.523598775598299f
#define TAN_PI_12 0.267949192431123f  /* 2 - sqrt(3) */
#define SQRT3_F   1.73205080756888f

/* Series coefficients, highest power first, for Horner's rule in z = x^2. */
/* atan: odd Taylor series to a^11; the next term is below 3e-9 for |a| <= tan(pi/12) */
static const float atan_c[5] = {-1.0f / 11.0f, 1.0f / 9.0f, -1.0f / 7.0f, 1.0f / 5.0f, -1.0f / 3.0f};
/* sin and cos for |x| <= pi/4 (Taylor to x^11 / x^12: error below 1e-10) */
static const float sin_c[5] = {-1.0f / 39916800.0f, 1.0f / 362880.0f, -1.0f / 5040.0f, 1.0f / 120.0f, -1.0f / 6.0f};
static const float cos_c[6] = {1.0f / 479001600.0f, -1.0f / 3628800.0f, 1.0f / 40320.0f, -1.0f / 720.0f,
                               1.0f / 24.0f, -0.5f};

/* c[0] z^(n-1) + ... + c[n-1] by Horner's rule */
static float horner(float z, const float *c, int n)
{
    float p = c[0];
    for (int k = 1; k < n; k++) {
        p = p * z + c[k];
    }
    return p;
}

/* atan(a) for 0 <= a <= 1 */
static float atan01(float a)
{
    float off = 0.0f;
    if (a > TAN_PI_12) {
        /* atan(a) = pi/6 + atan((a sqrt3 - 1) / (a + sqrt3)); the new argument is within tan(pi/12) */
        a = (a * SQRT3_F - 1.0f) / (a + SQRT3_F);
        off = PI_6_F;
    }
    float z = a * a;
    return off + (a + a * z * horner(z, atan_c, 5));
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
    return gs_acosf_clamped(x);
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

/* sin(x + quarter_turns pi/2): cos(x) is sin a quarter turn on, so both share one body */
static float sin_turned(float x, int quarter_turns)
{
    if (!gs_finite_f(x)) return x - x;
    int q;
    float r = reduce(x, &q);
    float z = r * r;
    q = (q + quarter_turns) & 3;
    /* odd quadrants take the cosine series 1 + z p(z), even ones the sine r + r z p(z);
     * the second half-turn the minus sign */
    bool odd = (q & 1) != 0;
    float v = (odd ? 1.0f : r) + (odd ? z : r * z) * horner(z, odd ? cos_c : sin_c, odd ? 6 : 5);
    return (q & 2) ? -v : v;
}

float gs_sinf(float x)
{
    return sin_turned(x, 0);
}

float gs_cosf(float x)
{
    return sin_turned(x, 1);
}
