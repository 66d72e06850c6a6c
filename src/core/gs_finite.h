/* gs_finite.h - finiteness of floats and gs_reals, alone or several at once (private to the core's files). */
#ifndef GS_FINITE_H
#define GS_FINITE_H

#include <math.h>
#include <stdbool.h>

#include "gravscale/gs_types.h"

/* Where the build optimises for size (the Cortex-M4), x - x == 0: a subtraction and a
 * test against zero, shorter there than isfinite's magnitude test; elsewhere isfinite,
 * fewer instructions on hosts. Both are true exactly for finite x. */
#ifdef __OPTIMIZE_SIZE__
static inline bool gs_finite_f(float x) { return x - x == 0.0f; }
/* (x - x) + (y - y) is 0 when both are finite, NaN otherwise: one test for the pair */
static inline bool gs_finite2_f(float x, float y) { return (x - x) + (y - y) == 0.0f; }
#else
static inline bool gs_finite_f(float x) { return isfinite(x); }
static inline bool gs_finite2_f(float x, float y) { return isfinite(x) && isfinite(y); }
#endif
/* a gs_real's finiteness: the float test where gs_real is float */
static inline bool gs_finite_r(gs_real x) { return sizeof(gs_real) < sizeof(double) ? gs_finite_f((float)x) : isfinite(x); }
/* three gs_reals finite: where the build optimises for size one test, as gs_finite2_f
 * ((x - x) + (y - y) + (z - z) is 0 exactly then, NaN otherwise) */
#ifdef __OPTIMIZE_SIZE__
static inline bool gs_finite3_r(gs_real x, gs_real y, gs_real z) { return (x - x) + (y - y) + (z - z) == GS_R(0.0); }
#else
static inline bool gs_finite3_r(gs_real x, gs_real y, gs_real z) { return gs_finite_r(x) && gs_finite_r(y) && gs_finite_r(z); }
#endif

#endif
