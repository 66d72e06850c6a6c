/* gs_dbits.c - the double compare from the IEEE bits (gs_dbits.h), one copy: where
 * double is emulated (a Cortex-M4F) it replaces libgcc's compare routines, with the
 * same answers for every input (the config parser's range checks use it). */
#include "gs_dbits.h"

/* noinline: one copy for every caller, also under LTO */
#define NOINLINE __attribute__((noinline))

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
