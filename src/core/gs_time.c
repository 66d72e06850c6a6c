/* gs_time.c - microsecond times (gs_time.h): spans to seconds and back. */
#ifdef __OPTIMIZE_SIZE__
#define GS_TIME_DEFINE  /* gs_time_span_us's and gs_time_span32_s's one out-of-line copies (gs_time.h) */
#endif
#include "gravscale/gs_time.h"

#include <math.h>
#include <string.h>

/* one copy (called per sample by the fits and the flight): inlined, it grows every caller */
#define NOINLINE __attribute__((noinline))

NOINLINE gs_real gs_time_span_s(int64_t t1_us, int64_t t0_us)
{
    return gs_time_span_us(t1_us, t0_us) / GS_R(1e6);
}

int64_t gs_time_add_s(int64_t t_us, gs_real ds)
{
    if (!gs_time_ok(t_us) || !(GS_FABSR(ds) < GS_R(2147483648.0))) return GS_T_NONE;  /* NaN fails too */
    /* whole seconds and the rest: the rest (|x| < 1) scales to microseconds with its
     * full precision, and both conversions are single instructions */
    int32_t whole_s = (int32_t)ds;
    gs_real frac_us = (ds - (gs_real)whole_s) * GS_R(1e6);
    int32_t frac_whole_us = (int32_t)(frac_us + (frac_us < GS_R(0.0) ? GS_R(-0.5) : GS_R(0.5)));
    return t_us + (int64_t)whole_s * GS_US_PER_S + frac_whole_us;  /* |t| <= 2^62, the rest < 2^51 */
}

int64_t gs_time_us_of_cfg_s(float s)
{
    if (!(s >= 0.0f && s < 2147483648.0f)) return GS_T_NONE;
    /* exactly rounded from the bits, s = m 2^sh: a float product (frac * 1e6) could be
     * 1 us off (8.579f -> 8579001); integer multiply and shift are cheap everywhere */
    uint32_t b;
    memcpy(&b, &s, sizeof b);
    uint32_t ex = (b >> 23) & 0xFFu;
    if (ex == 0u) return 0;  /* +-0 and subnormals: far below half a microsecond */
    /* s x 1e6 = m 1e6 2^(ex-150) = q 2^-r with q = m 1e6 2^7 < 2^51 and 0 <= r = 157 - ex
     * (ex <= 157 below 2^31 s); one rounding shift, half up: (2q + 2^r) >> (r + 1), which
     * is ((2q >> r) + 1) >> 1 (the bits below 2^r cannot carry into the half) */
    uint64_t q = (uint64_t)((b & 0x7FFFFFu) | 0x800000u) * (uint64_t)GS_US_PER_S << 7;
    uint32_t r = 157u - ex;
    if (r > 52u) return 0;  /* below 2^-1 us */
    return (int64_t)(((q << 1 >> r) + 1u) >> 1);
}

int64_t gs_time_us_of_s(double t_s)
{
    double us = t_s * 1e6;  /* the limit on the product: t_s at the bound may round past it */
    if (!(fabs(us) <= (double)GS_T_MAX_US)) return GS_T_NONE;  /* NaN fails too */
    return (int64_t)llround(us);
}

double gs_time_s_of_us(int64_t t_us)
{
    return t_us == GS_T_NONE ? (double)NAN : (double)t_us / 1e6;
}
