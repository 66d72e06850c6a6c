/* gs_dbits.c - double compares and truncation from the IEEE bits (gs_dbits.h), one
 * copy each: where double is emulated (a Cortex-M4F) they replace libgcc's compare
 * and double-to-integer routines, with the same answers for every input. */
#include "gs_dbits.h"

/* noinline: one copy for every caller, also under LTO */
#define NOINLINE __attribute__((noinline))

NOINLINE GS_DBITS_PCS uint64_t gs_dtrunc_abs(double x)
{
    uint64_t b = gs_dbits_abs(x);
    uint32_t ex = (uint32_t)(b >> 52); /* biased: |x| = 1.f 2^(ex - 1023) */
    if (ex < 1023u) return 0u;         /* |x| < 1 */
    /* the mantissa with its hidden bit at the top, shifted down by the exponent */
    return ((b << 11) | GS_DBITS_SIGN) >> (1086u - ex);
}

/* x's bits as a signed integer in value order (sign and magnitude to two's
 * complement: +0 and -0 both 0); meaningless for NaN */
static int64_t order_key(double x)
{
    int64_t m = (int64_t)gs_dbits_abs(x);
    return (gs_dbits(x) & GS_DBITS_SIGN) ? -m : m;
}

NOINLINE GS_DBITS_PCS int gs_dcmp(double a, double b)
{
    if (gs_disnan(a) || gs_disnan(b)) return 2;
    int64_t ka = order_key(a), kb = order_key(b);
    return (ka > kb) - (ka < kb);
}
