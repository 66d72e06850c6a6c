/* gs_dbits.h - tests of a double from its IEEE bits (private to the core's
 * files). Where double is emulated (a Cortex-M4F) each
 * isfinite/isnan/compare is a libgcc call; these are a few integer instructions
 * and give the same answers. */
#ifndef GS_DBITS_H
#define GS_DBITS_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#define GS_DBITS_SIGN 0x8000000000000000ull
#define GS_DBITS_INF 0x7FF0000000000000ull /* bits of +inf; larger magnitudes are NaN */

static inline uint64_t gs_dbits(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

/* the bits of |x|: for non-negative doubles, integer order is value order */
static inline uint64_t gs_dbits_abs(double x) { return gs_dbits(x) & ~GS_DBITS_SIGN; }

/* the exponent field not all ones (a test of the high word only) */
static inline bool gs_dfinite(double x)
{
    return ((uint32_t)(gs_dbits(x) >> 32) & 0x7FF00000u) != 0x7FF00000u;
}

static inline bool gs_disnan(double x) { return gs_dbits_abs(x) > GS_DBITS_INF; }

/* (double)x from the IEEE bits, exactly (subnormals normalized, inf, NaN with its
 * payload): where double is emulated the conversion is otherwise a libgcc call */
static inline double gs_dwiden(float x)
{
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    uint64_t d = (uint64_t)(b >> 31) << 63;
    uint32_t ex = (b >> 23) & 0xFFu, m = b & 0x7FFFFFu;
    if (ex == 0xFFu) {
        d |= GS_DBITS_INF | (uint64_t)m << 29; /* the quiet bit lands on double's */
    } else if (ex != 0u) {
        d |= (uint64_t)(ex + (1023u - 127u)) << 52 | (uint64_t)m << 29;
    } else if (m != 0u) {
        /* m * 2^-149: shift the leading bit up to the hidden bit's place */
        uint32_t e = 1023u - 126u;
        while (!(m & 0x800000u)) {
            m <<= 1;
            e--;
        }
        d |= (uint64_t)e << 52 | (uint64_t)(m & 0x7FFFFFu) << 29;
    }
    double r;
    memcpy(&r, &d, sizeof r);
    return r;
}

/* ---- in gs_dbits.c: one copy of what libgcc's double compare did ---- */

/* Where doubles are passed in FPU registers (hard-float ARM) but computed in core
 * registers (soft double on a single-precision FPU), these take them in core registers
 * as libgcc's routines do: no moves at the call sites. */
#if defined(__arm__) && defined(__ARM_PCS_VFP)
#define GS_DBITS_PCS __attribute__((pcs("aapcs")))
#else
#define GS_DBITS_PCS
#endif

/* IEEE's order of a and b from the bits: -1 (a < b), 0 (equal; -0 == +0), 1 (a > b), or
 * 2 (unordered: a NaN). Where double is emulated each compare is otherwise a libgcc call,
 * and any of them links its whole compare routine. */
GS_DBITS_PCS int gs_dcmp(double a, double b);

/* The compares of the core: through gs_dcmp where double is emulated (an ARM FPU
 * without double precision: __ARM_FP lacks bit 3), the plain operators where it is
 * native (hosts: one instruction, the same answers; tests/test_dbits.c checks both). */
#if defined(__arm__) && (!defined(__ARM_FP) || !(__ARM_FP & 8))
#define GS_DBITS_SOFT 1
#else
#define GS_DBITS_SOFT 0
#endif
static inline bool gs_dle(double a, double b) { return GS_DBITS_SOFT ? gs_dcmp(a, b) <= 0 : a <= b; }
static inline bool gs_dge(double a, double b) { return GS_DBITS_SOFT ? (unsigned)gs_dcmp(a, b) <= 1u : a >= b; }

#endif
