/* gs_time.c - microsecond times (gs_time.h): spans to seconds and back. */
#include "gravscale/gs_time.h"

#include <math.h>

#define SPAN_MAX_US INT32_MAX  /* spans saturate here where gs_real is float */

gs_real gs_time_span_s(int64_t t1_us, int64_t t0_us)
{
    if (t1_us == GS_T_NONE || t0_us == GS_T_NONE) return (gs_real)NAN;
    int64_t d = t1_us - t0_us;  /* both within +-2^62: no overflow */
    if (GS_REAL_IS_FLOAT) {
        /* int32 -> float is one instruction; int64 -> float a libgcc call */
        if (d > SPAN_MAX_US) d = SPAN_MAX_US;
        if (d < -SPAN_MAX_US) d = -SPAN_MAX_US;
        return (gs_real)(int32_t)d / GS_R(1e6);
    }
    return (gs_real)d / GS_R(1e6);
}

/* whole seconds and the rest: the rest (|x| < 1) scales to microseconds with its
 * full precision, and both conversions are single instructions */
#define ROUND_SPLIT_US(type, x, out)                                                  \
    do {                                                                              \
        int32_t whole_ = (int32_t)(x);                                                \
        type frac_us_ = ((x) - (type)whole_) * (type)1e6;                             \
        int32_t f_ = (int32_t)(frac_us_ + (frac_us_ < (type)0 ? (type)-0.5 : (type)0.5)); \
        (out) = (int64_t)whole_ * GS_US_PER_S + f_;                                   \
    } while (0)

int64_t gs_time_add_s(int64_t t_us, gs_real ds)
{
    if (t_us == GS_T_NONE || !(GS_FABS(ds) < GS_R(2147483648.0))) return GS_T_NONE;  /* NaN fails too */
    int64_t d_us;
    ROUND_SPLIT_US(gs_real, ds, d_us);
    return t_us + d_us;  /* |t| <= 2^62 and |d| < 2^51: no overflow */
}

int64_t gs_time_us_of_cfg_s(float s)
{
    if (!(s >= 0.0f && s < 2147483648.0f)) return GS_T_NONE;
    int64_t us;
    ROUND_SPLIT_US(float, s, us);
    return us;
}

int64_t gs_time_us_of_s(double t_s)
{
    if (!(fabs(t_s) <= (double)GS_T_MAX_US / 1e6)) return GS_T_NONE;  /* NaN fails too */
    return (int64_t)llround(t_s * 1e6);
}

double gs_time_s_of_us(int64_t t_us)
{
    return t_us == GS_T_NONE ? (double)NAN : (double)t_us / 1e6;
}
