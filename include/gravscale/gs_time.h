/* gs_time.h - times in the core: integer microseconds on the caller's clock.
 *
 * Every time the core keeps, compares or reports is an int64_t count of
 * microseconds (names end in _us): exact for any stream length, the same
 * decisions on every build (a frame count taken from a time ratio cannot round
 * differently in float and double), and no double arithmetic, which a
 * single-precision FPU (the Cortex-M4) would emulate in libgcc. Only spans
 * inside a flight window (well below 2^31 us = 35.8 min) become gs_real seconds.
 * Hosts that count in double seconds convert once at the edge (gs_time_us_of_s,
 * gs_time_s_of_us). */
#ifndef GS_TIME_H
#define GS_TIME_H

#include <math.h>

#include "gs_types.h"

#define GS_T_NONE INT64_MIN                   /* unknown time */
#define GS_T_MAX_US (INT64_C(1) << 62)       /* times beyond +-2^62 us (146 000 years) are refused */
#define GS_US_PER_S 1000000

/* A time the core accepts: within +-GS_T_MAX_US (GS_T_NONE is not). Any two such
 * times have a difference that fits int64_t. */
static inline bool gs_time_ok(int64_t t_us) { return t_us >= -GS_T_MAX_US && t_us <= GS_T_MAX_US; }

/* t1 - t0 (both gs_time_ok or GS_T_NONE) in microseconds, exact below 2^53 us
 * (double) or 2^24 us (float); NaN when either is GS_T_NONE. Where gs_real is float the span saturates at +-2^31 us
 * (only spans inside the ring, which are shorter, take part in arithmetic). */
#ifdef __OPTIMIZE_SIZE__
gs_real gs_time_span_us(int64_t t1_us, int64_t t0_us);
#endif
/* inline where the build optimises for speed (the fits call it per sample); one
 * out-of-line copy in gs_time.c where it optimises for size (the firmware) */
#if !defined(__OPTIMIZE_SIZE__) || defined(GS_TIME_DEFINE)
#ifdef GS_TIME_DEFINE
__attribute__((noinline)) gs_real gs_time_span_us(int64_t t1_us, int64_t t0_us)
#else
static inline gs_real gs_time_span_us(int64_t t1_us, int64_t t0_us)
#endif
{
    if (t1_us == GS_T_NONE || t0_us == GS_T_NONE) return (gs_real)NAN;
    int64_t d = t1_us - t0_us;  /* both within +-2^62: no overflow */
    if (GS_REAL_IS_FLOAT) {
        /* int32 -> float is one instruction; int64 -> float a libgcc call; spans
         * saturate at +-2^31 us (INT32_MIN and -INT32_MAX are both -2^31 as floats) */
        if (d < INT32_MIN || d > INT32_MAX) d = d < 0 ? INT32_MIN : INT32_MAX;
        return (gs_real)(int32_t)d;
    }
    return (gs_real)d;
}
#endif
/* The same in seconds. */
gs_real gs_time_span_s(int64_t t1_us, int64_t t0_us);
/* A span known to lie within +-INT32_MAX us (two held ring samples, a time inside a
 * flight window and its fit's centre) in seconds: what gs_time_span_s gives for it, with
 * 32-bit arguments (a 64-bit time costs two registers and instructions on a 32-bit core).
 * Inline and out of line as gs_time_span_us. */
#ifdef __OPTIMIZE_SIZE__
gs_real gs_time_span32_s(int32_t d_us);
#endif
#if !defined(__OPTIMIZE_SIZE__) || defined(GS_TIME_DEFINE)
#ifdef GS_TIME_DEFINE
__attribute__((noinline)) gs_real gs_time_span32_s(int32_t d_us)
#else
static inline gs_real gs_time_span32_s(int32_t d_us)
#endif
{
    return (gs_real)d_us / GS_R(1e6);
}
#endif
/* t + ds rounded to the nearest microsecond; GS_T_NONE when t is not gs_time_ok,
 * or ds is not finite or |ds| >= 2^31 s. */
int64_t gs_time_add_s(int64_t t_us, gs_real ds);
/* A configured span in whole microseconds, rounded exactly from the float's bits
 * (integer arithmetic: the host and the device compare against the same integer);
 * GS_T_NONE unless 0 <= s < 2^31 s (the config checks bound every span far below). */
int64_t gs_time_us_of_cfg_s(float s);

/* At the edge, for callers on double seconds (hosts; a device passes microseconds):
 * round(t_s * 1e6), or GS_T_NONE when t_s is not finite or beyond GS_T_MAX_US. */
int64_t gs_time_us_of_s(double t_s);
/* t in seconds, NaN for GS_T_NONE. */
double gs_time_s_of_us(int64_t t_us);

#endif
