/* gs_dfinite.h - private to gs_fit.c, gs_ring.c and gs_pipeline.c: isfinite of a
 * double from its exponent bits. Where double is emulated (Cortex-M4F) isfinite is
 * two libgcc compare calls; the bits give the same answer for every value. */
#ifndef GS_DFINITE_H
#define GS_DFINITE_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* false for +-inf and NaN (exponent field all ones), true otherwise */
static inline bool gs_double_finite(double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    return (bits & 0x7FF0000000000000u) != 0x7FF0000000000000u;
}

#endif
