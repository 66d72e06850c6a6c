/* gs_num.c - decimal parsing and formatting without strtod/printf.
 * Parsing: a fast path (a mantissa <= 2^53 times an exact power of ten: one
 * rounding) and an exact big-integer path for the rest: correctly rounded. Formatting: exact decimal digits of the
 * binary value from a big integer, rounded half away from zero.
 * double: it is the number format of the lines (event fields are double). */
#include "gravscale/gs_num.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* 124 x 32 bits hold D * 2^s for 800 digits against 10^1124 (see parse_slow). */
#define BIG_W 124
/* Digits kept exactly by the slow parser; more become one sticky digit
 * (a halfway point between doubles needs at most 767 digits). */
#define PARSE_MAX_DIGITS 800

typedef struct {
    uint32_t n;          /* words in use, w[n-1] != 0 unless n == 0 */
    uint32_t w[BIG_W];   /* little-endian base 2^32 */
} gs_big;

/* 10^0..10^22 are exact doubles, so one multiply or divide rounds once. */
static const double k_pow10_dbl[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static const uint32_t k_pow10_u32[10] = {1u,      10u,      100u,      1000u,      10000u,
                                         100000u, 1000000u, 10000000u, 100000000u, 1000000000u};

static const uint32_t k_pow5_u32[14] = {1u,      5u,       25u,       125u,       625u,
                                        3125u,   15625u,   78125u,    390625u,    1953125u,
                                        9765625u, 48828125u, 244140625u, 1220703125u};

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

static bool big_mul_pow5(gs_big *b, uint32_t k)
{
    for (; k >= 13; k -= 13)
        if (!big_mul_add(b, 1220703125u, 0)) return false;
    return k ? big_mul_add(b, k_pow5_u32[k], 0) : true;
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
    if (isinf(r)) return false;
    *out = neg ? -r : r;
    return true;
}

/* Exact conversion of the digits in s[0..mant_len) (with an optional '.')
 * times 10^exp10_in. nsig > 0 significant digits. */
static bool parse_slow(const char *s, size_t mant_len, int64_t nsig, int64_t nfrac,
                       int64_t exp10_in, bool neg, double *out)
{
    gs_big d, v;
    big_set(&d, 0);
    int64_t taken = 0;
    bool tail = false;
    uint32_t chunk = 0, chunk_n = 0;
    for (size_t i = 0; i < mant_len; i++) {
        char c = s[i];
        if (c < '0' || c > '9') continue;
        uint32_t dig = (uint32_t)(c - '0');
        if (taken == 0 && dig == 0) continue;
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

/* m * 10^e10 by scaling in double (m <= 19 digits): a few roundings, within 16 ulp
 * of the correctly rounded value (relative 4e-15; subnormals lose more). */
static bool scale_pow10(uint64_t m, int64_t e10, bool neg, double *out)
{
    double r = (double)m;
    for (; e10 > 22; e10 -= 22) r *= 1e22;
    for (; e10 < -22 && r != 0.0; e10 += 22) r /= 1e22;
    if (e10 >= -22) r = e10 < 0 ? r / k_pow10_dbl[-e10] : r * k_pow10_dbl[e10];
    if (isinf(r)) return false;
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
    uint64_t m = 0;
    int nkept = 0;
    int64_t nsig = 0, nfrac = 0, exp_adj = 0, ndig = 0;
    bool point = false, tail = false;
    for (; i < len; i++) {
        char c = s[i];
        if (c >= '0' && c <= '9') {
            unsigned dg = (unsigned)(c - '0');
            ndig++;
            if (point) nfrac++;
            if (nsig == 0 && dg == 0) {
                if (point) exp_adj--;
                continue;
            }
            nsig++;
            if (nkept < 19) {
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
    if (ndig == 0) return false;
    size_t mant_end = i;
    int64_t e = 0;
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
    if (nsig == 0) {
        *out = neg ? -0.0 : 0.0;
        return true;
    }
    int64_t e10 = exp_adj + e;
    int64_t dec_exp = e10 + nkept; /* value < 10^dec_exp */
    if (dec_exp > 310) return false;
    if (dec_exp < -324) {
        *out = neg ? -0.0 : 0.0;
        return true;
    }
    if (!tail) {
        const uint64_t two53 = 1ull << 53;
        if (m <= two53) {
            if (e10 >= -22 && e10 <= 22) {
                double r = (double)m;
                r = e10 < 0 ? r / k_pow10_dbl[-e10] : r * k_pow10_dbl[e10];
                *out = neg ? -r : r;
                return true;
            }
            if (e10 > 22 && e10 <= 22 + 15) {
                uint64_t mm = m;
                bool ok = true;
                for (int64_t k = 0; k < e10 - 22 && ok; k++) {
                    if (mm > two53 / 10u) ok = false;
                    else mm *= 10u;
                }
                if (ok) {
                    double r = (double)mm * 1e22;
                    if (isinf(r)) return false;
                    *out = neg ? -r : r;
                    return true;
                }
            }
        } else if (!exact && e10 >= -22 && e10 <= 22) {
            /* 17-19 digits in the scaled parser: two roundings, within 1 ulp. The
             * exact parser takes the big-integer path: (double)m rounds once
             * already (m > 2^53), so m * 10^e10 may land 1 ulp off. */
            double r = (double)m;
            r = e10 < 0 ? r / k_pow10_dbl[-e10] : r * k_pow10_dbl[e10];
            *out = neg ? -r : r;
            return true;
        }
    }
    if (!exact) return scale_pow10(m, e10, neg, out);
    return parse_slow(s + mant_start, mant_end - mant_start, nsig, nfrac, e, neg, out);
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

/* The exact decimal expansion of a > 0: a = N * 10^-p, N in base-1e4 chunks. */
typedef struct {
    uint16_t c[204]; /* base-10^4 chunks, c[0] least significant (810 digits) */
    int nc;
    int nd;         /* decimal digits of N */
    int p;
} gs_dec;

static void dec_expand(double a, gs_dec *d)
{
    /* a = mant * 2^e2 from the IEEE bits (no frexp/ldexp, no double arithmetic) */
    uint64_t bits;
    memcpy(&bits, &a, sizeof bits);
    int be = (int)((bits >> 52) & 0x7FFu);
    uint64_t mant = bits & ((1ull << 52) - 1u);
    int e2;
    if (be == 0) {
        e2 = -1074;  /* subnormal */
    } else {
        mant |= 1ull << 52;
        e2 = be - 1075;
    }
    while (!(mant & 1u)) {
        mant >>= 1;
        e2++;
    }
    gs_big n;
    big_set(&n, mant);
    /* 2^53 * 5^1074 < 2^2560 and 2^1024 both fit BIG_W words */
    if (e2 >= 0) {
        (void)big_shl(&n, (uint32_t)e2);
        d->p = 0;
    } else {
        (void)big_mul_pow5(&n, (uint32_t)(-e2));
        d->p = -e2;
    }
    d->nc = 0;
    while (n.n && d->nc < 204) d->c[d->nc++] = (uint16_t)big_divmod_small(&n, 10000u);
    uint32_t top = d->c[d->nc - 1];
    int td = 1;
    while (td < 4 && top >= k_pow10_u32[td]) td++;
    d->nd = 4 * (d->nc - 1) + td;
}

/* digit i counted from the most significant (0); zeros past the end */
static int dec_digit(const gs_dec *d, int i)
{
    if (i < 0 || i >= d->nd) return 0;
    int j = d->nd - 1 - i;
    return (int)((d->c[j / 4] / k_pow10_u32[j % 4]) % 10u);
}

/* Keep the first n digits (n <= 30) in out[] as values 0..9, rounded half away
 * using digit n. Returns 1 when the rounding carried into a new leading digit. */
static int dec_round(const gs_dec *d, int n, char *out)
{
    for (int i = 0; i < n; i++) out[i] = (char)dec_digit(d, i);
    if (dec_digit(d, n) < 5) return 0;
    for (int i = n - 1; i >= 0; i--) {
        if (out[i] < 9) {
            out[i]++;
            return 0;
        }
        out[i] = 0;
    }
    return 1;
}

static size_t put_fail(char *buf, size_t cap)
{
    if (buf && cap) buf[0] = '\0';
    return 0;
}

static size_t put_out(char *buf, size_t cap, const char *t, size_t n)
{
    if (!buf || n + 1u > cap) {
        if (buf && cap) buf[0] = '\0';
        return 0;
    }
    memcpy(buf, t, n);
    buf[n] = '\0';
    return n;
}

size_t gs_num_fmt_fixed(char *buf, size_t cap, double v, int decimals)
{
    if (!isfinite(v) || fabs(v) >= 1e15 || decimals < 0 || decimals > 9)
        return put_fail(buf, cap);
    char buf_dig[32]; /* the integer round(|v| * 10^decimals), most significant first */
    char *dig = buf_dig + 1;
    int nd = 0;
    if (v != 0.0) {
        gs_dec d;
        dec_expand(fabs(v), &d);
        int count = d.nd - d.p + decimals; /* digits at or above 10^-decimals */
        if (count >= 0) {
            int carry = dec_round(&d, count, dig);
            nd = count;
            if (carry) { /* a new leading 1 in front (no memmove linked) */
                dig = buf_dig;
                dig[0] = 1;
                nd = count + 1;
            }
        }
    }
    int lead = 0;
    while (lead < nd && dig[lead] == 0) lead++;
    bool zero = lead == nd;
    char t[48];
    size_t n = 0;
    if (v < 0 && !zero) t[n++] = '-';
    int nr = nd - lead; /* significant digits of the rounded integer */
    const char *r = dig + lead;
    if (nr > decimals) {
        for (int i = 0; i < nr - decimals; i++) t[n++] = (char)('0' + r[i]);
    } else {
        t[n++] = '0';
    }
    if (decimals > 0) {
        t[n++] = '.';
        for (int i = 0; i < decimals - nr; i++) t[n++] = '0';
        for (int i = nr > decimals ? nr - decimals : 0; i < nr; i++) t[n++] = (char)('0' + r[i]);
    }
    return put_out(buf, cap, t, n);
}

size_t gs_num_fmt_sig(char *buf, size_t cap, double v, int sig)
{
    if (!isfinite(v) || sig < 1 || sig > 15) return put_fail(buf, cap);
    if (v == 0.0) return put_out(buf, cap, "0", 1u);
    gs_dec d;
    dec_expand(fabs(v), &d);
    char dig[32];
    int k = d.nd - d.p - 1; /* decimal exponent of the first digit */
    if (dec_round(&d, sig, dig)) {
        dig[0] = 1;
        for (int i = 1; i < sig; i++) dig[i] = 0;
        k++;
    }
    /* Near the largest double, rounding up can give a decimal that no double
     * is nearest to (1.79e308 to 1 digit: 2e+308; DBL_MAX to 15: 1.79769313486232e+308,
     * beyond DBL_MAX + half an ulp): it would parse back as an overflow. There
     * the digits are cut instead of rounded up, the nearest decimal of `sig` digits
     * that is still a finite double (1e+308, 1.79769313486231e+308). Below 10^308,
     * and for DBL_MAX's first 16 digits, cut and round-up limit are the same. */
    static const char k_max_dig[16] = {1, 7, 9, 7, 6, 9, 3, 1, 3, 4, 8, 6, 2, 3, 1, 5};
    if (k == 308 && memcmp(dig, k_max_dig, (size_t)sig) > 0)
        for (int i = 0; i < sig; i++) dig[i] = (char)dec_digit(&d, i);
    int nk = sig;
    while (nk > 1 && dig[nk - 1] == 0) nk--;
    char t[48];
    size_t n = 0;
    if (v < 0) t[n++] = '-';
    if (k >= -4 && k <= 14) {
        if (k >= 0) {
            for (int i = 0; i <= k; i++) t[n++] = (char)('0' + (i < nk ? dig[i] : 0));
            if (nk > k + 1) {
                t[n++] = '.';
                for (int i = k + 1; i < nk; i++) t[n++] = (char)('0' + dig[i]);
            }
        } else {
            t[n++] = '0';
            t[n++] = '.';
            for (int i = 0; i < -k - 1; i++) t[n++] = '0';
            for (int i = 0; i < nk; i++) t[n++] = (char)('0' + dig[i]);
        }
    } else {
        t[n++] = (char)('0' + dig[0]);
        if (nk > 1) {
            t[n++] = '.';
            for (int i = 1; i < nk; i++) t[n++] = (char)('0' + dig[i]);
        }
        t[n++] = 'e';
        t[n++] = k < 0 ? '-' : '+';
        int ak = k < 0 ? -k : k;
        if (ak >= 100) t[n++] = (char)('0' + ak / 100);
        t[n++] = (char)('0' + (ak / 10) % 10);
        t[n++] = (char)('0' + ak % 10);
    }
    return put_out(buf, cap, t, n);
}
