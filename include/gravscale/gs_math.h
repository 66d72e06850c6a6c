/* gs_math.h - the few single-precision functions the core needs where gs_real is
 * float (a Cortex-M4F), so that no libm trigonometry (with its large-argument
 * range reduction tables) is linked. Host (double) builds keep libm's: their
 * results do not change. Accuracy against libm (tests/test_math.c): atan2f and
 * acosf within 4e-7 rad, sinf and cosf within 6e-7 for |x| <= 4 pi. sinf and
 * cosf reduce the argument in float: meant for thresholds and latitudes, not
 * for huge arguments. */
#ifndef GS_MATH_H
#define GS_MATH_H

#include <math.h>

float gs_atan2f(float y, float x);
float gs_acosf(float x);  /* NaN outside [-1, 1] */
/* gs_acosf of an x the caller has clamped to [-1, 1] (a NaN gives a NaN): no range test */
static inline float gs_acosf_clamped(float x) { return gs_atan2f(sqrtf((1.0f - x) * (1.0f + x)), x); }
float gs_sinf(float x);
float gs_cosf(float x);

/* float where gs_real is float, libm's double/float functions otherwise */
#define GS_REAL_IS_FLOAT (sizeof(gs_real) < sizeof(double))
#define GS_ACOSF(x) (GS_REAL_IS_FLOAT ? gs_acosf(x) : acosf(x))
#define GS_ACOSF_CLAMPED(x) (GS_REAL_IS_FLOAT ? gs_acosf_clamped(x) : acosf(x))
#define GS_ATAN2F(y, x) (GS_REAL_IS_FLOAT ? gs_atan2f(y, x) : atan2f(y, x))
/* |x| of a gs_real, exactly libm's fabs where gs_real is double */
#define GS_FABSR(x) (GS_REAL_IS_FLOAT ? (gs_real)fabsf((float)(x)) : (gs_real)fabs((double)(x)))

#endif
