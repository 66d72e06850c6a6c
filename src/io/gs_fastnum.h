/* gs_fastnum.h - the exact fast path of the readers' number parsing: a plain
 * decimal "[+-]digits[.digits]" of at most 15 digits is the integer m of its
 * digits over 10^k, both exact doubles (m < 2^53, k <= 15), so one correctly
 * rounded division gives strtod's value bit for bit (Clinger's fast path).
 * Everything else (exponents, longer mantissas, ".5", "5.", nan, inf, junk)
 * is declined, and gs_num_parse decides. */
#ifndef GS_FASTNUM_H
#define GS_FASTNUM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gravscale/gs_num.h"

#ifdef __cplusplus
extern "C" {
#endif

static const double gs_fastnum_pow10[16] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                            1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};

/* The plain decimal starting at p, to *out; returns where it stops, or NULL
 * when none starts there. The byte where it stops must exist and be neither a
 * digit nor '.' (a delimiter, a line end or a terminating sentinel): the scan
 * has no end pointer. */
static inline const char *gs_fastnum_scan(const char *p, double *out)
{
    bool neg = false;
    if ((unsigned char)*p < '0') { /* '+' and '-' sort below the digits */
        neg = *p == '-';
        if (!neg && *p != '+')
            return NULL;
        p++;
    }
    unsigned d = (unsigned)(unsigned char)*p - '0';
    if (d >= 10u)
        return NULL;
    uint64_t m = d;
    size_t digits = 1;
    while ((d = (unsigned)(unsigned char)p[digits] - '0') < 10u) {
        m = m * 10u + d; /* wraps beyond 19 digits: declined below anyway */
        digits++;
    }
    p += digits;
    size_t frac = 0;
    if (d == (unsigned)('.' - '0')) {
        if ((d = (unsigned)(unsigned char)p[1] - '0') >= 10u)
            return NULL; /* "5.": no fraction digit */
        m = m * 10u + d;
        frac = 1;
        while ((d = (unsigned)(unsigned char)p[1 + frac] - '0') < 10u) {
            m = m * 10u + d;
            frac++;
        }
        p += 1 + frac;
    }
    if (digits + frac > 15)
        return NULL;
    double v = (double)(int64_t)m / gs_fastnum_pow10[frac]; /* m < 10^15: exact */
    *out = neg ? -v : v;
    return p;
}

/* s[0..n) as a number, the fast path when it covers the whole field, else the full parser. */
static inline bool gs_fastnum_parse(const char *s, size_t n, double *out)
{
    double v;
    /* the fast scan needs a stop byte: a copy when the field is its whole buffer's end */
    char tmp[24];
    const char *p = s;
    if (n < sizeof tmp) {
        for (size_t i = 0; i < n; i++)
            tmp[i] = s[i];
        tmp[n] = '\0';
        p = tmp;
        const char *e = gs_fastnum_scan(p, &v);
        if (e == p + n) {
            *out = v;
            return true;
        }
    }
    return gs_num_parse(s, n, out);
}

#ifdef __cplusplus
}
#endif

#endif
