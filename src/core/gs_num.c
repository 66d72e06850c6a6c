/* gs_num.c - decimal parsing and formatting without strtod/printf.
 * Parsing: a fast path (a mantissa <= 2^53 times an exact power of ten: one
 * rounding) and an exact big-integer path for the rest: correctly rounded. Formatting: exact decimal digits of the
 * binary value from a big integer, rounded half away from zero.
 * Times (integer microseconds) are formatted from their decimal digits, with the
 * same digit writer. */
#include "gravscale/gs_num.h"

#include <limits.h>
#include <math.h>
#include <string.h>

#include "gs_dbits.h"

/* 124 x 32 bits hold D * 2^s for 800 digits against 10^1124 (see parse_slow). */
#define BIG_W 124
/* Digits kept exactly by the slow parser; more become one sticky digit
 * (a halfway point between doubles needs at most 767 digits). */
#define PARSE_MAX_DIGITS 800

typedef struct {
    uint32_t n;          /* words in use, w[n-1] != 0 unless n == 0 */
    uint32_t w[BIG_W];   /* little-endian base 2^32 */
} gs_big;

static const uint32_t k_pow10_u32[10] = {1u,      10u,      100u,      1000u,      10000u,
                                         100000u, 1000000u, 10000000u, 100000000u, 1000000000u};

static void big_set(gs_big *b, uint64_t v)
{
    b->w[0] = (uint32_t)v;
    b->w[1] = (uint32_t)(v >> 32);
    b->n = (v >> 32) ? 2u : (v ? 1u : 0u);
}

/* b = b * m + add; false when it no longer fits. */
static bool big_mul_add(gs_big *b, uint32_t m, uint32_t add)
{
    uint64_t carry = add;
    for (uint32_t i = 0; i < b->n; i++) {
        uint64_t p = (uint64_t)b->w[i] * m + carry;
        b->w[i] = (uint32_t)p;
        carry = p >> 32;
    }
    if (carry) {
        if (b->n >= BIG_W) return false;
        b->w[b->n++] = (uint32_t)carry;
    }
    return true;
}

static bool big_mul_pow10(gs_big *b, uint32_t k)
{
    for (; k >= 9; k -= 9)
        if (!big_mul_add(b, 1000000000u, 0)) return false;
    return k ? big_mul_add(b, k_pow10_u32[k], 0) : true;
}

static uint32_t bitlen32(uint32_t x)
{
    uint32_t n = 0;
    while (x) { n++; x >>= 1; }
    return n;
}

static uint32_t bitlen64(uint64_t x)
{
    return (x >> 32) ? 32u + bitlen32((uint32_t)(x >> 32)) : bitlen32((uint32_t)x);
}

static uint32_t big_bitlen(const gs_big *b)
{
    return b->n ? 32u * (b->n - 1u) + bitlen32(b->w[b->n - 1u]) : 0u;
}

static bool big_shl(gs_big *b, uint32_t bits)
{
    if (b->n == 0 || bits == 0) return true;
    if (big_bitlen(b) + bits > 32u * BIG_W) return false;
    uint32_t ws = bits / 32u, bs = bits % 32u;
    if (bs) {
        uint32_t top = b->n;
        uint32_t spill = b->w[top - 1u] >> (32u - bs);
        for (uint32_t i = top - 1u; i > 0; i--)
            b->w[i + ws] = (b->w[i] << bs) | (b->w[i - 1u] >> (32u - bs));
        b->w[ws] = b->w[0] << bs;
        b->n = top + ws;
        if (spill) b->w[b->n++] = spill;
    } else {
        for (uint32_t i = b->n; i-- > 0;) b->w[i + ws] = b->w[i];
        b->n += ws;
    }
    for (uint32_t i = 0; i < ws; i++) b->w[i] = 0;
    return true;
}

static int big_cmp(const gs_big *a, const gs_big *b)
{
    if (a->n != b->n) return a->n < b->n ? -1 : 1;
    for (uint32_t i = a->n; i-- > 0;)
        if (a->w[i] != b->w[i]) return a->w[i] < b->w[i] ? -1 : 1;
    return 0;
}

/* a -= b, requires a >= b */
static void big_sub(gs_big *a, const gs_big *b)
{
    uint64_t borrow = 0;
    for (uint32_t i = 0; i < a->n; i++) {
        uint64_t bi = (i < b->n ? b->w[i] : 0u) + borrow;
        uint64_t ai = a->w[i];
        borrow = ai < bi ? 1u : 0u;
        a->w[i] = (uint32_t)(ai - bi);
    }
    while (a->n && a->w[a->n - 1u] == 0) a->n--;
}

static void big_shr1(gs_big *b)
{
    for (uint32_t i = 0; i < b->n; i++) {
        uint32_t hi = (i + 1u < b->n) ? b->w[i + 1u] : 0u;
        b->w[i] = (b->w[i] >> 1) | (hi << 31);
    }
    while (b->n && b->w[b->n - 1u] == 0) b->n--;
}

/* b /= d for 0 < d <= 2^16, returns the remainder. Long division in 16-bit
 * digits: every step is a 32-bit division (one instruction on a Cortex-M4, no
 * 64-bit division helper linked). */
static uint32_t big_divmod_small(gs_big *b, uint32_t d)
{
    uint32_t rem = 0;
    for (uint32_t i = b->n; i-- > 0;) {
        uint32_t w = b->w[i];
        uint32_t hi = (rem << 16) | (w >> 16);   /* rem < d <= 2^16: no overflow */
        uint32_t qh = hi / d;
        rem = hi % d;
        uint32_t lo = (rem << 16) | (w & 0xFFFFu);
        b->w[i] = (qh << 16) | (lo / d);
        rem = lo % d;
    }
    while (b->n && b->w[b->n - 1u] == 0) b->n--;
    return rem;
}

/* ------------------------------------------------------------------ parse */

/* 2^k for -1022 <= k <= 1023, from its bits */
static double pow2(int k)
{
    uint64_t bits = (uint64_t)(k + 1023) << 52;
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

/* value = (q + f) * 2^-s with 0 <= f < 1, f > 0 iff sticky; round half even
 * to the nearest double (subnormals included). false on overflow. */
static bool round_to_double(uint64_t q, bool sticky, int64_t s, bool neg, double *out)
{
    if (q == 0) {
        *out = neg ? -0.0 : 0.0;
        return true;
    }
    int64_t L = (int64_t)bitlen64(q);
    int64_t e2 = L - 1 - s;
    int64_t keep = 53;
    if (e2 > 1100) return false;
    if (e2 < -1022) keep = 53 - (-1022 - e2);
    if (keep < 0) {
        *out = neg ? -0.0 : 0.0;
        return true;
    }
    int64_t drop = L - keep;
    uint64_t qr = q;
    if (drop > 0) {
        qr = drop >= 64 ? 0u : q >> drop;
        uint64_t rem = drop >= 64 ? q : (q & ((1ull << drop) - 1u));
        uint64_t half = 1ull << (drop - 1);
        if (rem > half || (rem == half && (sticky || (qr & 1u)))) qr++;
    } else {
        drop = 0; /* q holds >= 54 bits whenever sticky is set, so this is exact */
    }
    /* qr * 2^k is representable (qr was rounded to the bits it keeps): scaling by
     * exact powers of two in steps that stay normal is exact (no ldexp linked) */
    double r = (double)qr;
    int64_t k = drop - s;
    while (k > 1000) { r *= pow2(1000); k -= 1000; }
    while (k < -1000) { r *= pow2(-1000); k += 1000; }
    r *= pow2((int)k);
    if (!gs_dfinite(r)) return false;
    *out = neg ? -r : r;
    return true;
}

/* Exact conversion of the digits in s[0..mant_len) (with an optional '.')
 * times 10^exp10_in; at least one digit is not 0. */
static bool parse_slow(const char *s, size_t mant_len, int64_t exp10_in, bool neg, double *out)
{
    gs_big d, v;
    big_set(&d, 0);
    int64_t nsig = 0, nfrac = 0, taken = 0;
    bool point = false, tail = false;
    uint32_t chunk = 0, chunk_n = 0;
    for (size_t i = 0; i < mant_len; i++) {
        if (s[i] == '.') {
            point = true;
            continue;
        }
        uint32_t dig = (uint32_t)(s[i] - '0');
        if (point) nfrac++;
        if (nsig == 0 && dig == 0) continue; /* leading zeros */
        nsig++;
        if (taken < PARSE_MAX_DIGITS - 1) {
            chunk = chunk * 10u + dig;
            taken++;
            if (++chunk_n == 9) {
                if (!big_mul_add(&d, 1000000000u, chunk)) return false;
                chunk = 0;
                chunk_n = 0;
            }
        } else if (dig) {
            tail = true;
        }
    }
    if (chunk_n && !big_mul_add(&d, k_pow10_u32[chunk_n], chunk)) return false;
    int64_t e10 = exp10_in - nfrac;
    if (nsig > taken) {
        /* dropped digits: one sticky digit keeps the rounding direction */
        if (!big_mul_add(&d, 10u, tail ? 1u : 0u)) return false;
        e10 += nsig - taken - 1;
    }
    uint64_t q;
    bool sticky = false;
    int64_t sh;
    if (e10 >= 0) {
        if (e10 > 400 || !big_mul_pow10(&d, (uint32_t)e10)) return false;
        uint32_t L = big_bitlen(&d);
        if (L > 64) {
            uint32_t drop = L - 64u;
            uint32_t ws = drop / 32u, bs = drop % 32u;
            for (uint32_t i = 0; i < ws; i++)
                if (d.w[i]) sticky = true;
            if (bs && (d.w[ws] & ((1u << bs) - 1u))) sticky = true;
            q = 0;
            for (uint32_t i = 0; i < 3u; i++) {
                uint32_t idx = ws + i;
                uint64_t word = idx < d.n ? d.w[idx] : 0u;
                /* bits [drop + 32i - bs ...] of d land at position 32i - bs of q */
                if (i == 0) q |= word >> bs;
                else if (32u * i >= bs) {
                    uint32_t pos = 32u * i - bs;
                    if (pos < 64u) q |= word << pos;
                }
            }
            sh = -(int64_t)drop;
        } else {
            q = ((uint64_t)(d.n > 1 ? d.w[1] : 0u) << 32) | (d.n ? d.w[0] : 0u);
            sh = 0;
        }
    } else {
        if (e10 < -1200) {
            *out = neg ? -0.0 : 0.0;
            return true;
        }
        big_set(&v, 1);
        if (!big_mul_pow10(&v, (uint32_t)(-e10))) return false;
        int64_t s_bits = 63 + (int64_t)big_bitlen(&v) - (int64_t)big_bitlen(&d);
        if (s_bits >= 0) {
            if (!big_shl(&d, (uint32_t)s_bits)) return false;
        } else if (!big_shl(&v, (uint32_t)(-s_bits))) {
            return false;
        }
        int64_t k = (int64_t)big_bitlen(&d) - (int64_t)big_bitlen(&v);
        if (k < 0) k = 0;
        if (!big_shl(&v, (uint32_t)k)) return false;
        q = 0;
        for (int64_t j = k; j >= 0; j--) {
            if (big_cmp(&d, &v) >= 0) {
                big_sub(&d, &v);
                q |= 1ull << j;
            }
            big_shr1(&v);
        }
        sticky = d.n != 0;
        sh = s_bits;
    }
    return round_to_double(q, sticky, sh, neg, out);
}

/* 10^k: for k <= 22 every product is an exact double, so this is the literal
 * (no 184-byte table) */
static double pow10_exact(int k)
{
    double p = 1.0;
    while (k-- > 0) p *= 10.0;
    return p;
}

/* m * 10^e10 by scaling in double (m <= 19 digits): a few roundings, within 16 ulp
 * of the correctly rounded value (relative 4e-15; subnormals lose more). With
 * m <= 2^53 and |e10| <= 22 it is the one rounding of the exact fast path. */
static bool scale_pow10(uint64_t m, int e10, bool neg, double *out)
{
    double r = (double)m; /* m > 0 */
    bool down = e10 < 0;
    int k = down ? -e10 : e10;
    /* 10^22 at a time; an underflow to 0 stays 0 (and 0 / 10^k is 0) */
    for (; k > 22 && gs_dbits_abs(r) != 0u; k -= 22) r = down ? r / 1e22 : r * 1e22;
    double p = pow10_exact(k);
    r = down ? r / p : r * p;
    if (!gs_dfinite(r)) return false;
    *out = neg ? -r : r;
    return true;
}

static bool parse_impl(const char *s, size_t len, double *out, bool exact);

bool gs_num_parse(const char *s, size_t len, double *out)
{
    /* where gs_real is float (a Cortex-M4) the exact slow path is not linked */
    return parse_impl(s, len, out, !GS_REAL_IS_FLOAT);
}

bool gs_num_parse_scaled(const char *s, size_t len, double *out)
{
    return parse_impl(s, len, out, false);
}

static bool parse_impl(const char *s, size_t len, double *out, bool exact)
{
    if (!s || !out) return false;
    size_t i = 0;
    bool neg = false;
    if (i < len && (s[i] == '+' || s[i] == '-')) {
        neg = s[i] == '-';
        i++;
    }
    size_t mant_start = i;
    /* the first 19 significant digits in m, the value = m * 10^(exp_adj + exponent);
     * ptrdiff_t: counts of an object's characters (32-bit arithmetic on an M4) */
    uint64_t m = 0;
    int nkept = 0;
    ptrdiff_t exp_adj = 0;
    bool point = false, tail = false, digits = false;
    for (; i < len; i++) {
        char c = s[i];
        if (c >= '0' && c <= '9') {
            unsigned dg = (unsigned)(c - '0');
            digits = true;
            if (m == 0 && dg == 0) { /* a leading zero (m == 0 until the first other digit) */
                if (point) exp_adj--;
            } else if (nkept < 19) {
                m = m * 10u + dg;
                nkept++;
                if (point) exp_adj--;
            } else {
                if (!point) exp_adj++;
                if (dg) tail = true;
            }
        } else if (c == '.' && !point) {
            point = true;
        } else {
            break;
        }
    }
    if (!digits) return false;
    size_t mant_end = i;
    int e = 0;
    if (i < len && (s[i] == 'e' || s[i] == 'E')) {
        i++;
        bool eneg = false;
        if (i < len && (s[i] == '+' || s[i] == '-')) {
            eneg = s[i] == '-';
            i++;
        }
        size_t es = i;
        for (; i < len && s[i] >= '0' && s[i] <= '9'; i++)
            if (e < 100000000) e = e * 10 + (s[i] - '0'); /* saturate: far beyond any double */
        if (i == es) return false;
        if (eneg) e = -e;
    }
    if (i != len) return false;
    int64_t e10 = (int64_t)exp_adj + e;
    int64_t dec_exp = e10 + nkept; /* value < 10^dec_exp */
    if (m == 0 || dec_exp < -324) { /* all digits zero, or below half the smallest subnormal */
        *out = neg ? -0.0 : 0.0;
        return true;
    }
    if (dec_exp > 310) return false;
    /* from here -343 <= e10 <= 310 */
    const uint64_t two53 = 1ull << 53;
    if (!tail && m <= two53) {
        /* m * 10^e10 with m and 10^e10 exact doubles: one rounding. Beyond 10^22
         * the mantissa takes what it can exactly (1e30 = 10^8 * 1e22). */
        uint64_t mm = m;
        int k = (int)e10;
        for (; k > 22 && mm <= two53 / 10u; k--) mm *= 10u;
        if (k >= -22 && k <= 22) return scale_pow10(mm, k, neg, out);
    }
    /* The scaled parser's 17-19 digits with |e10| <= 22: two roundings, within 1 ulp.
     * The exact parser takes the big-integer path: (double)m rounds once
     * already (m > 2^53), so m * 10^e10 may land 1 ulp off. */
    if (!exact) return scale_pow10(m, (int)e10, neg, out);
    return parse_slow(s + mant_start, mant_end - mant_start, e, neg, out);
}

bool gs_num_parse_int(const char *s, size_t len, long *out)
{
    if (!s || !out) return false;
    size_t i = 0;
    bool neg = false;
    if (i < len && (s[i] == '+' || s[i] == '-')) {
        neg = s[i] == '-';
        i++;
    }
    if (i == len) return false;
    /* accumulate the magnitude as unsigned so LONG_MIN fits */
    unsigned long lim = neg ? (unsigned long)LONG_MAX + 1ul : (unsigned long)LONG_MAX;
    unsigned long acc = 0;
    for (; i < len; i++) {
        if (s[i] < '0' || s[i] > '9') return false;
        unsigned long dg = (unsigned long)(s[i] - '0');
        if (acc > (lim - dg) / 10ul) return false;
        acc = acc * 10ul + dg;
    }
    if (neg) *out = acc == (unsigned long)LONG_MAX + 1ul ? LONG_MIN : -(long)acc;
    else *out = (long)acc;
    return true;
}

/* ------------------------------------------------------------------ format */

/* The leading decimal digits of a finite a > 0, exact: a = D * 10^-p with D an
 * integer of nd digits, of which at least the first DEC_KEEP - 3 are kept (enough
 * for gs_num_fmt_sig's 15 digits and the rounding digit). */
#define DEC_KEEP 32 /* a power of two: the digits are a ring */
typedef struct {
    char ring[DEC_KEEP]; /* digit j of D counted from the least significant at ring[j % DEC_KEEP] */
    int nd;
    int p;
} gs_dec;

/* n = mant * 2^e2 * 10^p, an integer: (mant * 5^-e2) * 10^e2 with p = -e2 when e2 < 0;
 * returns p. 2^53 * 5^1074 < 2^2560 and 2^1024 fit BIG_W words. */
static int big_exact(gs_big *n, uint64_t mant, int e2)
{
    /* fewer factors for the same value (a float's mantissa ends in 29 zero bits) */
    for (; mant && !(mant & 1u); mant >>= 1) e2++;
    big_set(n, mant);
    uint32_t base = e2 < 0 ? 5u : 2u;
    for (int k = e2 < 0 ? -e2 : e2; k > 0;) {
        /* a pass over n multiplies by as many factors as 32 bits hold (5^13, 2^30) */
        uint32_t m = 1;
        for (; k > 0 && m <= UINT32_MAX / 5u; k--) m *= base;
        (void)big_mul_add(n, m, 0);
    }
    return e2 < 0 ? -e2 : 0;
}

/* the decimal digits of a = mant * 2^e2 (mant > 0) into d */
static void dec_expand(uint64_t mant, int e2, gs_dec *d)
{
    gs_big n;
    d->p = big_exact(&n, mant, e2);
    /* 4 digits a pass over n, least significant first; 10^4 <= 2^16: the divisions are
     * 32-bit, no 64-bit division routine linked */
    d->nd = 0;
    do /* a > 0: at least one pass */
        for (uint32_t r = big_divmod_small(&n, 10000u), j = 0; j < 4; j++, r /= 10u)
            d->ring[d->nd++ & (DEC_KEEP - 1)] = (char)(r % 10u);
    while (n.n);
    while (d->ring[(d->nd - 1) & (DEC_KEEP - 1)] == 0) d->nd--; /* the top pass's leading zeros (a > 0) */
}

/* the magnitude bits of a double (finite) as mant * 2^e2 (no frexp/ldexp, no double arithmetic) */
static uint64_t dbits_mant(uint64_t abs_bits, int *e2)
{
    int be = (int)(abs_bits >> 52);
    uint64_t mant = abs_bits & ((1ull << 52) - 1u);
    if (be) mant |= 1ull << 52;
    *e2 = be ? be - 1075 : -1074;
    return mant;
}

/* digit i counted from the most significant (0); zeros past the end */
static char dec_digit(const gs_dec *d, int i)
{
    return i >= 0 && i < d->nd && i < DEC_KEEP ? d->ring[(d->nd - 1 - i) & (DEC_KEEP - 1)] : 0;
}

/* Keep the first n digits (n < DEC_KEEP) in out[] as values 0..9, rounded half
 * away using digit n. On a carry into a new leading digit out[] is 1 and n zeros
 * (one digit more) and it returns 1. */
static int dec_round(const gs_dec *d, int n, char *out)
{
    for (int i = 0; i <= n; i++) out[i] = dec_digit(d, i);
    bool up = out[n] >= 5;
    out[n] = 0;
    for (int i = n - 1; up && i >= 0; i--) {
        up = out[i] == 9;
        out[i] = up ? 0 : (char)(out[i] + 1);
    }
    if (up) out[0] = 1;
    return up;
}

/* a length no buffer holds: put_out writes "" and returns 0 */
#define FMT_FAIL SIZE_MAX

static size_t put_out(char *buf, size_t cap, const char *t, size_t n)
{
    if (!buf || n >= cap) {
        if (buf && cap) buf[0] = '\0';
        return 0;
    }
    memcpy(buf, t, n);
    buf[n] = '\0';
    return n;
}

/* |value| = n * 10^-p (n consumed) with `decimals` >= 0 decimals, rounded half away
 * from zero, a minus sign when neg and the rounded value is not 0 */
static size_t fmt_fixed_n(char *buf, size_t cap, gs_big *n, int p, bool neg, int decimals)
{
    /* right to left: the place of n's last digit is decimals - p; below 0 dropped (the
     * last one dropped rounds), above 0 zeros before it; at least one before the point */
    int first = decimals - p;
    uint32_t up = 0;
    bool nonzero = false;
    char t[48];
    char *s = t + sizeof t;
    for (int i = first < 0 ? first : 0; i <= decimals || n->n || up; i++) {
        uint32_t dg = i < first ? 0u : big_divmod_small(n, 10u);
        if (i < 0) {
            up = dg >= 5u;
            continue;
        }
        if (i == decimals && i) *--s = '.';
        dg += up;
        up = dg == 10u;
        if (up) dg = 0;
        nonzero |= dg != 0;
        *--s = (char)('0' + dg);
    }
    if (neg && nonzero) *--s = '-';
    return put_out(buf, cap, s, (size_t)(t + sizeof t - s));
}

/* a uint64_t worth n * 10^-p, as fmt_fixed_n; "" unless 0 <= decimals <= 9 */
static size_t fmt_fixed_u64(char *buf, size_t cap, uint64_t n, int p, bool neg, int decimals)
{
    if (decimals < 0 || decimals > 9) return put_out(buf, cap, "", FMT_FAIL);
    gs_big b;
    big_set(&b, n);
    return fmt_fixed_n(buf, cap, &b, p, neg, decimals);
}

size_t gs_num_fmt_fixed(char *buf, size_t cap, double v, int decimals)
{
    uint64_t mag = gs_dbits_abs(v);
    /* not finite or |v| >= 1e15: NaN and inf have the largest magnitude bits */
    if (mag >= gs_dbits(1e15) || decimals < 0 || decimals > 9) return put_out(buf, cap, "", FMT_FAIL);
    int e2;
    uint64_t mant = dbits_mant(mag, &e2);
    gs_big n;
    int p = big_exact(&n, mant, e2);
    /* 4 digits a pass while more than the rounding digit stays below 10^-decimals: it
     * alone rounds (fmt_fixed_n takes it) */
    for (; p > decimals + 4; p -= 4) (void)big_divmod_small(&n, 10000u);
    return fmt_fixed_n(buf, cap, &n, p, (gs_dbits(v) & GS_DBITS_SIGN) != 0u, decimals);
}

size_t gs_num_fmt_fixed_f(char *buf, size_t cap, float v, int decimals)
{
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    uint32_t mag = bits & 0x7FFFFFFFu;
    float below_1e15 = 1e15f; /* the float nearest 1e15 is the largest below it */
    uint32_t limit;
    memcpy(&limit, &below_1e15, sizeof limit);
    /* not finite or |v| >= 1e15: NaN and inf have the largest magnitude bits */
    if (mag > limit) return put_out(buf, cap, "", FMT_FAIL);
    /* |v| = mant * 2^e2 from the IEEE bits, as dbits_mant */
    uint32_t be = mag >> 23, mant = mag & 0x7FFFFFu;
    if (be) mant |= 0x800000u;
    int e2 = be ? (int)be - 150 : -149;
    /* The rounding reads the digits down to 10^-(decimals + 1) and no further: below 2^24
     * those of floor(|v| 10^(decimals + 1)) = mant 10^(decimals + 1) >> -e2 (< 2^58), an
     * integer with decimals + 1 decimals; above, |v| = mant << e2 < 2^50 is an integer.
     * 64-bit integers, bit by bit: no big integer, no variable 64-bit shift. */
    uint64_t n = mant;
    int p = e2 < 0 && decimals >= 0 && decimals <= 9 ? decimals + 1 : 0; /* else fmt_fixed_u64 refuses */
    for (int k = 0; k < p; k++) n *= 10u;
    for (; e2 > 0; e2--) n <<= 1;
    for (; e2 < 0; e2++) n >>= 1; /* at most 149 steps */
    return fmt_fixed_u64(buf, cap, n, p, (bits >> 31) != 0u, decimals);
}

size_t gs_num_fmt_us(char *buf, size_t cap, int64_t t_us, int decimals)
{
    if (t_us == INT64_MIN) return put_out(buf, cap, "", FMT_FAIL);
    uint64_t mag = t_us < 0 ? (uint64_t)-t_us : (uint64_t)t_us;
    return fmt_fixed_u64(buf, cap, mag, 6, t_us < 0, decimals);
}

size_t gs_num_fmt_u32(char *buf, size_t cap, uint32_t v)
{
    return fmt_fixed_u64(buf, cap, v, 0, false, 0);
}

size_t gs_num_fmt_sig(char *buf, size_t cap, double v, int sig)
{
    uint64_t mag = gs_dbits_abs(v);
    if (mag >= GS_DBITS_INF || sig < 1 || sig > 15) return put_out(buf, cap, "", FMT_FAIL);
    if (!mag) return put_out(buf, cap, "0", 1u);
    gs_dec d;
    int e2;
    uint64_t mant = dbits_mant(mag, &e2);
    dec_expand(mant, e2, &d);
    char dig[DEC_KEEP];
    int k = d.nd - d.p - 1; /* decimal exponent of the first digit */
    k += dec_round(&d, sig, dig); /* a carry: 1 and zeros, cut to sig digits below */
    /* Near the largest double, rounding up can give a decimal that no double
     * is nearest to (1.79e308 to 1 digit: 2e+308; DBL_MAX to 15: 1.79769313486232e+308,
     * beyond DBL_MAX + half an ulp): it would parse back as an overflow. There
     * the digits are cut instead of rounded up, the nearest decimal of `sig` digits
     * that is still a finite double (1e+308, 1.79769313486231e+308). Below 10^308,
     * and for DBL_MAX's first 16 digits, cut and round-up limit are the same. */
    static const char k_max_dig[16] = {1, 7, 9, 7, 6, 9, 3, 1, 3, 4, 8, 6, 2, 3, 1, 5};
    if (k == 308 && memcmp(dig, k_max_dig, (size_t)sig) > 0)
        for (int i = 0; i < sig; i++) dig[i] = dec_digit(&d, i);
    int nk = sig;
    while (nk > 1 && dig[nk - 1] == 0) nk--;
    bool neg = gs_dbits(v) & GS_DBITS_SIGN;
    /* the nk digits as an integer D < 10^15: |v| ~ D * 10^(k + 1 - nk), no rounding left */
    uint64_t D = 0;
    for (int i = 0; i < nk; i++) D = D * 10u + (uint64_t)dig[i];
    gs_big n;
    big_set(&n, D);
    int p = nk - 1 - k;
    if (k >= -4 && k <= 14) return fmt_fixed_n(buf, cap, &n, p, neg, p > 0 ? p : 0);
    char t[48]; /* d.ddd (at most 17 characters) and e+XXX */
    size_t len = fmt_fixed_n(t, sizeof t, &n, nk - 1, neg, nk - 1);
    t[len++] = 'e';
    t[len++] = k < 0 ? '-' : '+';
    int ak = k < 0 ? -k : k;
    if (ak >= 100) t[len++] = (char)('0' + ak / 100);
    t[len++] = (char)('0' + (ak / 10) % 10);
    t[len++] = (char)('0' + ak % 10);
    return put_out(buf, cap, t, len);
}
