/* gs_finite.h - a float's finiteness (private to the core's files). */
#ifndef GS_FINITE_H
#define GS_FINITE_H

#include <math.h>
#include <stdbool.h>

/* Where the build optimises for size (the Cortex-M4), x - x == 0: a subtraction and a
 * test against zero, shorter there than isfinite's magnitude test; elsewhere isfinite,
 * fewer instructions on hosts. Both are true exactly for finite x. */
#ifdef __OPTIMIZE_SIZE__
static inline bool gs_finite_f(float x) { return x - x == 0.0f; }
#else
static inline bool gs_finite_f(float x) { return isfinite(x); }
#endif

#endif
