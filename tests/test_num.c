/* test_num.c - gs_num against libc (strtod, snprintf) as the reference. */
#include "gravscale/gs_num.h"
#include "unity.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void setUp(void) {}
void tearDown(void) {}

/* deterministic PRNG (splitmix64) so failures reproduce */
static uint64_t g_rng = 0x9E3779B97F4A7C15ull;
static uint64_t rnd64(void)
{
    uint64_t z = (g_rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double rnd_unit(void) { return (double)(rnd64() >> 11) * (1.0 / 9007199254740992.0); }

/* a random finite double with a random exponent over the whole range */
static double rnd_any_double(void)
{
    for (;;) {
        uint64_t b = rnd64();
        double d;
        memcpy(&d, &b, sizeof d);
        if (isfinite(d)) return d;
    }
}

/* distance in ulps between two finite doubles of the same sign */
static uint64_t ulp_dist(double a, double b)
{
    int64_t ia, ib;
    memcpy(&ia, &a, 8);
    memcpy(&ib, &b, 8);
    if (ia < 0) ia = INT64_MIN - ia;
    if (ib < 0) ib = INT64_MIN - ib;
    return ia > ib ? (uint64_t)(ia - ib) : (uint64_t)(ib - ia);
}

static bool parse_str(const char *s, double *out) { return gs_num_parse(s, strlen(s), out); }

/* ------------------------------------------------------------ parse table */
typedef struct {
    const char *in;
    bool ok;
} parse_case;

static const parse_case k_parse_cases[] = {
    {"0", true},      {"-0", true},    {"1e308", true},  {"1e309", false}, {"1e-320", true},
    {".5", true},     {"5.", true},    {"+1", true},     {"", false},      {"-", false},
    {"1e", false},    {"1e+", false},  {"1.2.3", false}, {"nan", false},   {"inf", false},
    {" 1", false},    {"1 ", false},   {"0x10", false},  {".", false},     {"+", false},
    {"-.", false},    {"e5", false},   {".e5", false},   {"1e5.5", false}, {"--1", false},
    {"1e-400", true}, {"2.4703282292062328e-324", true}, {"2.4703282292062327e-324", true},
    {"4.9406564584124654e-324", true}, {"2.2250738585072011e-308", true},
    {"2.2250738585072014e-308", true}, {"1.7976931348623157e308", true},
    {"1.7976931348623158e308", true},  {"1.7976931348623159e308", false},
    {"9007199254740993", true},        {"9007199254740992.5", true},
    {"123456789012345678901234567890", true}, {"0.000000000000000000000000000000001", true},
    {"1e+00000000000000000000000000005", true}, {"1e-99999999999999999999", true},
    {"1e99999999999999999999", false}, {"00000000000000000000000000001.5", true},
    {"1.00000000000000000000000000000000000000000000001", true},
    {"-1.5E-3", true}, {"1E3", true}, {"3.14159", true}, {"1,5", false}, {"1e3x", false},
};

void test_parse_table(void)
{
    for (size_t i = 0; i < sizeof k_parse_cases / sizeof k_parse_cases[0]; i++) {
        const parse_case *c = &k_parse_cases[i];
        double got = 12345.0;
        bool ok = parse_str(c->in, &got);
        char msg[160];
        snprintf(msg, sizeof msg, "input \"%s\"", c->in);
        TEST_ASSERT_EQUAL_MESSAGE(c->ok, ok, msg);
        if (!ok) {
            TEST_ASSERT_EQUAL_DOUBLE_MESSAGE(12345.0, got, msg); /* out untouched */
            continue;
        }
        double ref = strtod(c->in, NULL);
        /* these are all exact-path inputs: bit-identical to libc, signs of zero included */
        TEST_ASSERT_TRUE_MESSAGE(memcmp(&ref, &got, sizeof got) == 0, msg);
    }
    double z = 1.0;
    TEST_ASSERT_TRUE(parse_str("-0", &z));
    TEST_ASSERT_TRUE(signbit(z));
    /* 1e-320 is a subnormal and comes back as one (not flushed to 0) */
    TEST_ASSERT_TRUE(parse_str("1e-320", &z));
    TEST_ASSERT_TRUE(z > 0 && z < 2.2250738585072014e-308);
    /* exact length is honoured: "12" out of "123" */
    TEST_ASSERT_TRUE(gs_num_parse("123", 2, &z));
    TEST_ASSERT_EQUAL_DOUBLE(12.0, z);
    TEST_ASSERT_FALSE(gs_num_parse(NULL, 0, &z));
}

/* the float builds' parser (gs_num_parse_scaled): the same accept/reject decisions,
 * values within 16 ulp of strtod's for normal doubles */
void test_parse_scaled(void)
{
    for (size_t i = 0; i < sizeof k_parse_cases / sizeof k_parse_cases[0]; i++) {
        const parse_case *c = &k_parse_cases[i];
        double got = 0.0, want = 0.0;
        bool ok = gs_num_parse_scaled(c->in, strlen(c->in), &got);
        bool ok_exact = gs_num_parse(c->in, strlen(c->in), &want);
        if (ok_exact && fabs(want) > 1.7976931348623e308) continue;  /* within 16 ulp of DBL_MAX may overflow */
        TEST_ASSERT_EQUAL_MESSAGE(ok_exact, ok, c->in);
        if (ok && isnormal(want)) {
            TEST_ASSERT_TRUE_MESSAGE(ulp_dist(want, got) <= 16, c->in);
        }
    }
    static const char *fmts[] = {"%.17g", "%.21e", "%.25g", "%.9e", "%.3f"};
    char s[64];
    uint64_t worst = 0;
    uint64_t rng_saved = g_rng;  /* the other tests keep their random sequences */
    for (int it = 0; it < 20000; it++) {
        double v = it % 2 ? ldexp(rnd_unit() + 0.5, (int)(rnd64() % 2000) - 1000) : (rnd_unit() - 0.5) * 4000.0;
        for (size_t f = 0; f < sizeof fmts / sizeof fmts[0]; f++) {
            int len = snprintf(s, sizeof s, fmts[f], v);
            if (len <= 0 || len >= (int)sizeof s) continue;
            double ref = strtod(s, NULL), got = 0.0;
            TEST_ASSERT_TRUE_MESSAGE(gs_num_parse_scaled(s, (size_t)len, &got), s);
            if (!isnormal(ref)) continue;
            uint64_t d = ulp_dist(ref, got);
            TEST_ASSERT_TRUE_MESSAGE(d <= 16, s);
            if (d > worst) worst = d;
        }
    }
    g_rng = rng_saved;
    printf("parse_scaled: worst %llu ulp\n", (unsigned long long)worst);
    /* what a profile holds: short decimals are exact */
    double x = 0.0;
    TEST_ASSERT_TRUE(gs_num_parse_scaled("0.02", 4, &x));
    TEST_ASSERT_EQUAL_DOUBLE(0.02, x);
    TEST_ASSERT_TRUE(gs_num_parse_scaled("2.5", 3, &x));
    TEST_ASSERT_EQUAL_DOUBLE(2.5, x);
}

/* --------------------------------------------------------- parse random */
/* significant digits of a decimal string's mantissa (trailing zeros count) */
static int sig_digits(const char *s)
{
    int n = 0;
    bool started = false;
    for (; *s && *s != 'e' && *s != 'E'; s++) {
        if (*s < '0' || *s > '9') continue;
        if (*s != '0') started = true;
        if (started) n++;
    }
    return n;
}
void test_parse_random_vs_strtod(void)
{
    static const char *fmts[] = {"%.17g", "%.16g", "%.15g", "%.6g", "%.3f", "%.1f", "%.9e", "%.0f"};
    char s[64];
    long n = 0, long_ = 0;
    for (int it = 0; it < 20000; it++) {
        double v;
        if (it % 3 == 0) v = rnd_any_double();
        else if (it % 3 == 1) v = (rnd_unit() - 0.5) * 4000.0;
        else v = ldexp(rnd_unit(), (int)(rnd64() % 200) - 100);
        for (size_t f = 0; f < sizeof fmts / sizeof fmts[0]; f++) {
            int len = snprintf(s, sizeof s, fmts[f], v);
            if (len <= 0 || len >= (int)sizeof s) continue;
            double ref = strtod(s, NULL), got = 0;
            TEST_ASSERT_TRUE_MESSAGE(gs_num_parse(s, (size_t)len, &got), s);
            uint64_t d = ulp_dist(ref, got);
            /* correctly rounded: bit-identical to strtod, 17-19 digits included */
            TEST_ASSERT_TRUE_MESSAGE(d == 0, s);
            n++;
            long_ += sig_digits(s) > 15;
        }
    }
    printf("parse random: %ld values bit-identical to strtod (%ld with more than 15 digits)\n", n, long_);
}

/* long mantissas and big exponents go the exact big-integer way: bit-identical */
void test_parse_long_digits_exact(void)
{
    char s[900];
    for (int it = 0; it < 3000; it++) {
        int nd = 20 + (int)(rnd64() % (it < 100 ? 780 : 40));
        size_t n = 0;
        if (rnd64() & 1) s[n++] = '-';
        int point = (int)(rnd64() % (unsigned)(nd + 1));
        for (int i = 0; i < nd; i++) {
            if (i == point) s[n++] = '.';
            s[n++] = (char)('0' + rnd64() % 10);
        }
        int e = (int)(rnd64() % 700) - 350;
        n += (size_t)snprintf(s + n, sizeof s - n, "e%d", e);
        double ref = strtod(s, NULL), got = 0;
        bool ok = gs_num_parse(s, n, &got);
        if (isinf(ref)) {
            TEST_ASSERT_FALSE_MESSAGE(ok, s);
            continue;
        }
        TEST_ASSERT_TRUE_MESSAGE(ok, s);
        TEST_ASSERT_TRUE_MESSAGE(memcmp(&ref, &got, 8) == 0, s);
    }
    /* exact halfway cases between doubles decided by a digit far away */
    const char *halfway[] = {
        "9007199254740993",                       /* 2^53 + 1: tie, even -> 2^53 */
        "9007199254740993.0000000000000000000001", /* just above the tie -> up */
        "9007199254740992.9999999999999999999999",
        "2.47032822920623272088284396434110686182529901307162382212792841250337753635104375932649918180817996189898282347722858865463328355177969898199387398005390939063150356595155702263922908583924491051844359318028499365361525003193704576782492193656236698636584807570015857692699037063119282795585513329278343384093519780155312465972635795746227664652728272200563740064854999770965994704540208281662262378573934507363390079677619305775067401763246736009689513405355374585166611342237666786041621596804619144672918403005300575308490487653917113865916462395249126236538818796362393732804238910186723484976682350898633885879256283027559956575244555072551893136908362547791869486679949683240497058210285131854513962138377228261454376934125320985913276672363281255e-324",
    };
    for (size_t i = 0; i < sizeof halfway / sizeof halfway[0]; i++) {
        double ref = strtod(halfway[i], NULL), got = 0;
        TEST_ASSERT_TRUE(parse_str(halfway[i], &got));
        TEST_ASSERT_TRUE_MESSAGE(memcmp(&ref, &got, 8) == 0, halfway[i]);
    }
}

/* -------------------------------------------------- parse: edge cases */
/* Each is compared with strtod bit for bit; an overflow (strtod: inf) must be
 * rejected. Long mantissas whose digits past the 19th are zeros used to take
 * the 19-digit fast path, (double)m then * or / 10^k: two roundings, 1 ulp off. */
static const char *const k_parse_edges[] = {
    /* the case found: 20 digits, the last 0 */
    "-16007.816808735412460e36", "16007.816808735412460e36", "-16007.81680873541246e36",
    /* 17-20 digits (with trailing zeros) that two roundings got wrong */
    "-4974018679106650433.000e-12", "-2461762994.8065416200e-11", "-7014337581386.2490e1",
    "-7158391585803203.48e21", "-3733.011881218523434e27", "1973406.63072513177e-8",
    "-180172249.417117879e-8", "-9.8937817903179624550e-2", "-263848731505283601200e9",
    "9957.49917041793210e27", "2467094168083544980.0e-20", "2558744664564112.62300e2",
    /* trailing zeros in long mantissas, integers and fractions */
    "12345678901234567890", "123456789012345678900000", "1234567890123456789000000000000000000000",
    "9007199254740993000", "9007199254740993.000000", "9007199254740993e3", "90071992547409930e-1",
    "9007199254740992.50000000000000000000", "9007199254740993.00000000000000000001",
    "1.0000000000000000000", "1.00000000000000000000000000000000000000000000000000",
    "0.10000000000000000000000000000000", "100000000000000000000000", "1000000000000000000000000",
    "4503599627370496.5000000000000000000", "4503599627370497.50000000000000000000",
    /* 19, 20, 21 and more digits */
    "1234567890123456789", "9999999999999999999", "18446744073709551615", "18446744073709551616",
    "99999999999999999999", "123456789012345678901", "999999999999999999999e-21",
    "3.1415926535897932384626433832795028841971", "2.7182818284590452353602874713526624977572e100",
    "0.30000000000000000000000000000000000000000000001", "8.98846567431158e307",
    "17976931348623157081452742373170435679807056752584499659891747680315726078002853876058955"
    "86327668781715404589535143824642343213268894641827684675467035375169860499105765512820762"
    "45490090389328944075868508455133942304583236903222948165808559332123348274797826204144723"
    "168738177180919299881250404026184124858368",
    /* near DBL_MAX: the limit is DBL_MAX + half an ulp (a tie, rounds to even = 2^1024) */
    "1.7976931348623157e308", "-1.7976931348623157e308", "1.7976931348623158e308",
    "1.797693134862315807e308", "1.7976931348623158079e308", "1.79769313486231580793e308",
    "1.797693134862315807937289714053e308", "1.7976931348623159e308", "1.79769313486232e308",
    "179769313486231570000000000000000000000000000000000000000000000000000000000000000000000"
    "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
    "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
    "000000000000000000000000000000000000000000000000000", "1e308", "2e308", "1.7e308", "1.8e308",
    "0.17976931348623157e309", "17976931348623157e292", "17976931348623158e292",
    /* subnormals: the smallest, half of it (a tie to 0), the boundary to normals */
    "4.9406564584124654e-324", "4.9406564584124654417656879286822137236505980e-324",
    "2.4703282292062328e-324", "2.4703282292062327e-324", "2.47032822920623272088e-324",
    "2.47032822920623272089e-324", "7.4109846876186982e-324", "1e-323", "3e-324", "5e-324",
    "2.2250738585072009e-308", "2.2250738585072011e-308", "2.2250738585072012e-308",
    "2.2250738585072013e-308", "2.2250738585072014e-308", "2.225073858507201136057409796709131975934819546351645648e-308",
    "4.4501477170144023e-308", "1.0000000000000000000000000e-310", "12345678901234567890e-330",
    "0.000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
    "00000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
    "0000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
    "0000000000000000000000000000000000000000000000000000000000000000000000494065645841246544",
    "1e-400", "-1e-400",
};

void test_parse_edge_table(void)
{
    for (size_t i = 0; i < sizeof k_parse_edges / sizeof k_parse_edges[0]; i++) {
        const char *s = k_parse_edges[i];
        double ref = strtod(s, NULL), got = 12345.0;
        bool ok = gs_num_parse(s, strlen(s), &got);
        TEST_ASSERT_EQUAL_MESSAGE(!isinf(ref), ok, s);
        if (ok) {
            TEST_ASSERT_TRUE_MESSAGE(memcmp(&ref, &got, sizeof got) == 0, s);
        } else {
            TEST_ASSERT_EQUAL_DOUBLE_MESSAGE(12345.0, got, s);
        }
    }
}

/* Random 17-25 digit mantissas, 0-6 trailing zeros, the point anywhere, the
 * exponent near the fast path's (|e| <= 40) or anywhere: bit-identical to strtod. */
void test_parse_long_mantissa_sweep(void)
{
    uint64_t rng_saved = g_rng; /* the other tests keep their random sequences */
    char s[80];
    long n = 0;
    for (int it = 0; it < 300000; it++) {
        int nd = 17 + (int)(rnd64() % 9), nz = (int)(rnd64() % 7);
        size_t k = 0;
        if (rnd64() & 1) s[k++] = '-';
        int point = (int)(rnd64() % (uint64_t)(nd + nz + 1));
        for (int i = 0; i < nd + nz; i++) {
            if (i == point) s[k++] = '.';
            s[k++] = (char)(i == 0 ? '1' + rnd64() % 9 : i < nd ? '0' + rnd64() % 10 : '0');
        }
        int e = it % 4 ? (int)(rnd64() % 81) - 40 : (int)(rnd64() % 700) - 350;
        k += (size_t)snprintf(s + k, sizeof s - k, "e%d", e);
        double ref = strtod(s, NULL), got = 0.0;
        bool ok = gs_num_parse(s, k, &got);
        TEST_ASSERT_EQUAL_MESSAGE(!isinf(ref), ok, s);
        if (ok) {
            TEST_ASSERT_TRUE_MESSAGE(memcmp(&ref, &got, sizeof got) == 0, s);
        }
        n++;
    }
    g_rng = rng_saved;
    printf("parse long mantissas: %ld values bit-identical to strtod\n", n);
}

void test_parse_speed(void)
{
    enum { N = 2000000 };
    static char text[N * 12];
    static size_t off[N + 1];
    size_t n = 0;
    for (int i = 0; i < N; i++) {
        off[i] = n;
        n += (size_t)snprintf(text + n, sizeof text - n, "%.3f", (rnd_unit() - 0.3) * 2000.0);
    }
    off[N] = n;
    clock_t t0 = clock();
    double sum = 0;
    for (int i = 0; i < N; i++) {
        double v;
        TEST_ASSERT_TRUE(gs_num_parse(text + off[i], off[i + 1] - off[i], &v));
        sum += v;
    }
    double dt = (double)(clock() - t0) / CLOCKS_PER_SEC;
    printf("parse speed: %.1f million numbers/s (\"%%.3f\" keypoint-like values, checksum %.3f)\n",
           N / dt / 1e6, sum);
    TEST_ASSERT_TRUE(dt > 0);
}

/* --------------------------------------------------------------- parse_int */
void test_parse_int_table(void)
{
    static const struct {
        const char *in;
        bool ok;
        long v;
    } c[] = {
        {"0", true, 0},      {"-0", true, 0},   {"+7", true, 7},     {"512", true, 512},
        {"", false, 0},      {"-", false, 0},   {"1.0", false, 0},   {" 1", false, 0},
        {"1 ", false, 0},    {"0x10", false, 0}, {"1e3", false, 0},  {"9223372036854775807", true, 9223372036854775807L},
        {"-9223372036854775808", true, (-9223372036854775807L - 1)},
        {"9223372036854775808", false, 0},  {"-9223372036854775809", false, 0},
        {"99999999999999999999999", false, 0},
    };
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        long v = 4242;
        bool ok = gs_num_parse_int(c[i].in, strlen(c[i].in), &v);
        TEST_ASSERT_EQUAL_MESSAGE(c[i].ok, ok, c[i].in);
        TEST_ASSERT_TRUE_MESSAGE(v == (ok ? c[i].v : 4242), c[i].in);
    }
}

/* ------------------------------------------------------ formatting oracle */
/* The reference rounds glibc's exact expansion half away from zero. */
static bool ref_fixed(double v, int dec, char *out)
{
    static char exact[1400];
    snprintf(exact, sizeof exact, "%.1100f", fabs(v)); /* glibc prints the exact binary value */
    char *pt = strchr(exact, '.');
    size_t ni = (size_t)(pt - exact);
    char dig[64];
    size_t nd = 0;
    bool tie = pt[1 + dec] == '5' && strspn(pt + 2 + dec, "0") == strlen(pt + 2 + dec);
    for (size_t i = 0; i < ni; i++) dig[nd++] = exact[i];
    for (int i = 0; i < dec; i++) dig[nd++] = pt[1 + i];
    if (pt[1 + dec] >= '5') {
        size_t i = nd;
        while (i > 0 && dig[i - 1] == '9') dig[--i] = '0';
        if (i == 0) {
            memmove(dig + 1, dig, nd++);
            dig[0] = '1';
        } else {
            dig[i - 1]++;
        }
    }
    bool zero = true;
    for (size_t i = 0; i < nd; i++) zero = zero && dig[i] == '0';
    size_t n = 0;
    if (v < 0 && !zero) out[n++] = '-';
    size_t nint = nd - (size_t)dec;
    for (size_t i = 0; i < nint; i++) out[n++] = dig[i];
    if (dec) {
        out[n++] = '.';
        for (int i = 0; i < dec; i++) out[n++] = dig[nint + (size_t)i];
    }
    out[n] = 0;
    return tie;
}

static void ref_sig(double v, int sig, char *out)
{
    static char exact[1400];
    snprintf(exact, sizeof exact, "%.1100e", fabs(v));
    char dig[32];
    dig[0] = exact[0];
    for (int i = 1; i < sig; i++) dig[i] = exact[1 + i];
    int k = atoi(strchr(exact, 'e') + 1);
    if (exact[1 + sig] >= '5') {
        int i = sig;
        while (i > 0 && dig[i - 1] == '9') dig[--i] = '0';
        if (i == 0) {
            dig[0] = '1';
            k++;
        } else {
            dig[i - 1]++;
        }
    }
    /* beyond DBL_MAX + half an ulp a decimal parses as an overflow: the digits
     * are cut there instead (the formatter's rule, see gs_num.h) */
    if (k == 308 && strncmp(dig, "1797693134862315", (size_t)sig) > 0) {
        dig[0] = exact[0];
        for (int i = 1; i < sig; i++) dig[i] = exact[1 + i];
    }
    int nk = sig;
    while (nk > 1 && dig[nk - 1] == '0') nk--;
    dig[nk] = 0;
    size_t n = 0;
    if (v < 0) out[n++] = '-';
    if (k >= -4 && k <= 14) {
        if (k >= 0) {
            for (int i = 0; i <= k; i++) out[n++] = i < nk ? dig[i] : '0';
            if (nk > k + 1) {
                out[n++] = '.';
                for (int i = k + 1; i < nk; i++) out[n++] = dig[i];
            }
        } else {
            n += (size_t)sprintf(out + n, "0.%.*s%s", -k - 1, "0000", dig);
        }
        out[n] = 0;
    } else {
        sprintf(out + n, "%c%s%s%se%c%02d", dig[0], nk > 1 ? "." : "", dig + 1, "", k < 0 ? '-' : '+',
                k < 0 ? -k : k);
    }
}

typedef struct {
    double v;
    int d;
    const char *want;
} fmt_case;

void test_fmt_fixed_table(void)
{
    static const fmt_case c[] = {
        {0.125, 2, "0.13"},   /* exact tie: half away from zero (glibc's %.2f gives 0.12) */
        {-0.125, 2, "-0.13"},
        {2.5, 0, "3"},        {-2.5, 0, "-3"},
        {0.145, 2, "0.14"},   /* binary 0.14499999999999999 */
        {-0.0, 3, "0.000"},   {-0.0004, 3, "0.000"},  {0.0005, 3, "0.001"},
        {999.9996, 3, "1000.000"}, {0, 0, "0"},  {1.5, 9, "1.500000000"},
        {123456789012345.6, 0, "123456789012346"},  {-999999999999999.9, 0, "-1000000000000000"},
        {1e-300, 4, "0.0000"}, {5e-324, 9, "0.000000000"}, {0.99999999995, 9, "1.000000000"},
        {12.3456, 4, "12.3456"}, {-1.23456789, 3, "-1.235"},
    };
    char buf[64];
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        size_t n = gs_num_fmt_fixed(buf, sizeof buf, c[i].v, c[i].d);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(c[i].want, buf, c[i].want);
        TEST_ASSERT_EQUAL(strlen(c[i].want), n);
    }
    /* not representable: 0 and "" */
    const double bad[] = {NAN, INFINITY, -INFINITY, 1e15, -1e15, 1e300};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        strcpy(buf, "xx");
        TEST_ASSERT_EQUAL(0, gs_num_fmt_fixed(buf, sizeof buf, bad[i], 3));
        TEST_ASSERT_EQUAL_STRING("", buf);
    }
    TEST_ASSERT_EQUAL(0, gs_num_fmt_fixed(buf, sizeof buf, 1.0, 10));
    TEST_ASSERT_EQUAL(0, gs_num_fmt_fixed(buf, sizeof buf, 1.0, -1));
}

/* microseconds as seconds: exact digits, ties half away from zero, sign symmetric */
void test_fmt_us_table(void)
{
    static const struct { int64_t t_us; int d; const char *want; } c[] = {
        {0, 0, "0"},          {0, 4, "0.0000"},       {0, 9, "0.000000000"},
        {1, 6, "0.000001"},   {-1, 6, "-0.000001"},   {1, 5, "0.00000"},     {5, 5, "0.00001"},
        {-5, 5, "-0.00001"},  {-4, 5, "0.00000"},     {500000, 0, "1"},      {499999, 0, "0"},
        {-500000, 0, "-1"},   {-499999, 0, "0"},      {1500000, 0, "2"},     {2500000, 0, "3"},
        {-2500000, 0, "-3"},  {12345679, 4, "12.3457"}, {12345650, 4, "12.3457"}, {12345649, 4, "12.3456"},
        {-12345650, 4, "-12.3457"}, {999999500, 3, "1000.000"}, {-999999500, 3, "-1000.000"},
        {1234567, 9, "1.234567000"}, {-1234567, 7, "-1.2345670"}, {33333, 4, "0.0333"},
        {86400000000, 3, "86400.000"}, {4611686018427387904, 4, "4611686018427.3879"},
        {-4611686018427387904, 6, "-4611686018427.387904"}, {INT64_MAX, 0, "9223372036855"},
        {INT64_MAX, 6, "9223372036854.775807"}, {INT64_MIN + 1, 9, "-9223372036854.775807000"},
        {INT64_MIN + 1, 2, "-9223372036854.78"},
    };
    char buf[64];
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        size_t n = gs_num_fmt_us(buf, sizeof buf, c[i].t_us, c[i].d);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(c[i].want, buf, c[i].want);
        TEST_ASSERT_EQUAL(strlen(c[i].want), n);
    }
    /* unknown, or no such format: 0 and "" */
    strcpy(buf, "xx");
    TEST_ASSERT_EQUAL(0, gs_num_fmt_us(buf, sizeof buf, INT64_MIN, 3));
    TEST_ASSERT_EQUAL_STRING("", buf);
    TEST_ASSERT_EQUAL(0, gs_num_fmt_us(buf, sizeof buf, 1, 10));
    TEST_ASSERT_EQUAL(0, gs_num_fmt_us(buf, sizeof buf, 1, -1));
    TEST_ASSERT_EQUAL(0, gs_num_fmt_us(NULL, 0, 1, 2));
    /* the exact size: all or nothing, never past cap */
    for (size_t cap = 0; cap <= 8; cap++) {
        char b[16];
        memset(b, 0xA5, sizeof b);
        size_t n = gs_num_fmt_us(b, cap, -1234567, 4); /* "-1.2346": 7 characters and the NUL */
        TEST_ASSERT_EQUAL(cap == 8 ? 7u : 0u, n);
        for (size_t k = cap; k < sizeof b; k++) TEST_ASSERT_EQUAL_HEX8(0xA5, (uint8_t)b[k]);
        if (cap) TEST_ASSERT_EQUAL_STRING(cap == 8 ? "-1.2346" : "", b);
    }
}

/* the reference: integer arithmetic with printf; and gs_num_fmt_fixed of t / 1e6 away from ties */
void test_fmt_us_random(void)
{
    uint64_t st = 0x1234567887654321ull;
    char got[64], want[80], fx[64];
    int n_fixed = 0;
    for (int it = 0; it < 200000; it++) {
        st ^= st << 13;
        st ^= st >> 7;
        st ^= st << 17;
        int d = (int)(st % 10u);
        int64_t t;
        switch ((st >> 8) % 4u) {
        case 0: t = (int64_t)(st >> 1) * ((st >> 5) & 1u ? -1 : 1); break; /* any magnitude */
        case 1: t = (int64_t)((st >> 12) % 2000000000000ull) - 1000000000000; break; /* +-11.6 days */
        case 2: t = (int64_t)((st >> 12) % 20000001u) - 10000000; break;
        default: t = ((int64_t)((st >> 12) % 2001u) - 1000) * 50; break; /* many exact ties */
        }
        if (t == INT64_MIN) continue;
        uint64_t mag = t < 0 ? (uint64_t)-t : (uint64_t)t;
        uint64_t scale = 1;
        for (int k = d; k < 6; k++) scale *= 10u;
        uint64_t q = d >= 6 ? mag : mag / scale, r = d >= 6 ? 0 : mag % scale;
        bool tie = d < 6 && 2u * r == scale;
        if (d < 6 && 2u * r >= scale) q++;
        uint64_t p10 = 1;
        for (int k = 0; k < (d < 6 ? d : 6); k++) p10 *= 10u;
        int len = snprintf(want, sizeof want, "%s%llu", (q && t < 0) ? "-" : "", (unsigned long long)(q / p10));
        if (d > 0) {
            len += snprintf(want + len, sizeof want - (size_t)len, ".%0*llu", d < 6 ? d : 6, (unsigned long long)(q % p10));
            for (int k = 6; k < d; k++) want[len++] = '0';
            want[len] = '\0';
        }
        size_t n = gs_num_fmt_us(got, sizeof got, t, d);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(want, got, want);
        TEST_ASSERT_EQUAL((size_t)len, n);
        /* the text the double-seconds format gave for the same time: equal except at exact ties */
        if (!tie && d <= 6 && mag < 1000000000000000ull) { /* beyond 6 decimals the double has other digits */
            gs_num_fmt_fixed(fx, sizeof fx, (double)t / 1e6, d);
            TEST_ASSERT_EQUAL_STRING_MESSAGE(fx, got, fx);
            n_fixed++;
        }
    }
    printf("fmt_us random: 200000 times equal to the integer reference; %d equal to gs_num_fmt_fixed(t / 1e6)\n", n_fixed);
}

void test_fmt_fixed_random_vs_libc(void)
{
    char got[64], want[64], libc[64];
    long ties = 0, n = 0;
    for (int it = 0; it < 40000; it++) {
        double v;
        switch (it % 4) {
        case 0: v = (rnd_unit() - 0.5) * 2e4; break;
        case 1: v = ldexp(rnd_unit() - 0.5, (int)(rnd64() % 100) - 60); break;
        case 2: v = (double)(int64_t)(rnd64() % 2000000 - 1000000) / 1000.0; break; /* many exact ties */
        default: v = (double)(int64_t)(rnd64() % 20000 - 10000) / 8.0; break;       /* x.125 ties */
        }
        int d = (int)(rnd64() % 10);
        size_t len = gs_num_fmt_fixed(got, sizeof got, v, d);
        bool tie = ref_fixed(v, d, want);
        TEST_ASSERT_EQUAL_STRING(want, got);
        TEST_ASSERT_EQUAL(strlen(want), len);
        snprintf(libc, sizeof libc, "%.*f", d, v);
        const char *lc = strcmp(libc, "-0") == 0 || strncmp(libc, "-0.", 3) == 0 ? libc + 1 : libc;
        bool negz = lc != libc && strspn(lc, "0.") == strlen(lc);
        if (!negz) lc = libc;
        if (strcmp(lc, got) != 0) {
            /* only exact ties may differ from glibc's half-to-even */
            TEST_ASSERT_TRUE_MESSAGE(tie, got);
            ties++;
        }
        n++;
    }
    printf("fmt_fixed random: %ld values equal to the exact half-away reference; %ld differ from glibc "
           "(exact ties, glibc rounds half to even)\n",
           n, ties);
}

void test_fmt_sig_table(void)
{
    static const fmt_case c[] = {
        {1.5e-05, 6, "1.5e-05"},   {0.0001, 6, "0.0001"},    {0.00012345678, 3, "0.000123"},
        {9.81, 6, "9.81"},         {-9.81, 6, "-9.81"},      {123456.0, 3, "123000"},
        {1e15, 6, "1e+15"},        {999999999999999.0, 15, "999999999999999"},
        {999999999999999.0, 6, "1e+15"}, {0.0, 6, "0"},      {-0.0, 6, "0"},
        {1e300, 6, "1e+300"},      {-2.5e-308, 2, "-2.5e-308"}, {5e-324, 3, "4.94e-324"},
        {0.00099999, 2, "0.001"},  {0.000099999, 2, "0.0001"}, {1234.5678, 6, "1234.57"},
        {0.0023456789, 6, "0.00234568"}, {30.0, 6, "30"}, {29.97002997, 6, "29.97"},
        {2.5, 1, "3"},
        /* near DBL_MAX: rounding up would overflow when parsed back, so cut */
        {1.7976931348623157e308, 15, "1.79769313486231e+308"}, {-1.7976931348623157e308, 1, "-1e+308"},
        {1.7976931348623157e308, 4, "1.797e+308"},   {1.75e308, 1, "1e+308"},  {1.75e308, 2, "1.7e+308"},
        {1.79769313486231e308, 15, "1.79769313486231e+308"}, {1.7976931348623e308, 14, "1.7976931348623e+308"},
        {1.55e308, 1, "1e+308"},   {1.79769313486e308, 3, "1.79e+308"},
        /* rounding up that stays in range is kept */
        {1.45e308, 1, "1e+308"},   {9.9999e307, 2, "1e+308"},  {1.7976931348617e308, 13, "1.797693134862e+308"},
    };
    char buf[64];
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        size_t n = gs_num_fmt_sig(buf, sizeof buf, c[i].v, c[i].d);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(c[i].want, buf, c[i].want);
        TEST_ASSERT_EQUAL(strlen(c[i].want), n);
    }
    const double bad[] = {NAN, INFINITY, -INFINITY};
    for (size_t i = 0; i < 3; i++) {
        strcpy(buf, "xx");
        TEST_ASSERT_EQUAL(0, gs_num_fmt_sig(buf, sizeof buf, bad[i], 6));
        TEST_ASSERT_EQUAL_STRING("", buf);
    }
    TEST_ASSERT_EQUAL(0, gs_num_fmt_sig(buf, sizeof buf, 1.0, 0));
    TEST_ASSERT_EQUAL(0, gs_num_fmt_sig(buf, sizeof buf, 1.0, 16));
}

/* every output is a JSON number that parses back to within its rounding */
void test_fmt_sig_random(void)
{
    char got[64], want[64];
    for (int it = 0; it < 30000; it++) {
        double v = (it & 1) ? rnd_any_double() : ldexp(rnd_unit() - 0.5, (int)(rnd64() % 80) - 40);
        int sig = 1 + (int)(rnd64() % 15);
        size_t len = gs_num_fmt_sig(got, sizeof got, v, sig);
        ref_sig(v, sig, want);
        TEST_ASSERT_EQUAL_STRING(want, got);
        TEST_ASSERT_EQUAL(strlen(want), len);
        double back = 0;
        TEST_ASSERT_TRUE_MESSAGE(gs_num_parse(got, len, &back), got);
        TEST_ASSERT_TRUE_MESSAGE(isfinite(back), got);
        /* half a unit of the last digit plus the re-parse rounding (2 ulp); a whole
         * unit where the digits near DBL_MAX are cut */
        double unit = fabs(v) > 1.7e308 ? 1.0 : 0.5;
        TEST_ASSERT_TRUE_MESSAGE(fabs(back - v) <= fabs(v) * (pow(10, 1 - sig) * unit + 0x1p-51), got);
        TEST_ASSERT_NULL(strpbrk(got, "infa"));
    }
}

/* Near DBL_MAX every output of every length parses back to a finite double
 * (1.79e308 to one digit is 1e+308: 2e+308 would be an overflow), equal to the
 * half-away rounding wherever that one is finite. */
void test_fmt_sig_near_max(void)
{
    char got[64], want[64];
    double v = 1.7976931348623157e308;
    for (int it = 0; it < 4000; it++) {
        double x = it & 1 ? -v : v;
        for (int sig = 1; sig <= 15; sig++) {
            size_t len = gs_num_fmt_sig(got, sizeof got, x, sig);
            ref_sig(x, sig, want);
            TEST_ASSERT_EQUAL_STRING(want, got);
            double back = 0.0;
            TEST_ASSERT_TRUE_MESSAGE(gs_num_parse(got, len, &back), got);
            TEST_ASSERT_TRUE_MESSAGE(isfinite(back) && signbit(back) == signbit(x), got);
            TEST_ASSERT_TRUE_MESSAGE(fabs(back - x) <= fabs(x) * pow(10, 1 - sig), got);
            /* the plain half-away rounding, when it parses as a finite double, is what is printed */
            char half[64];
            snprintf(half, sizeof half, "%.*e", sig - 1, fabs(x));
            double h = strtod(half, NULL);
            if (isfinite(h)) {
                TEST_ASSERT_TRUE_MESSAGE(fabs(fabs(back) - h) <= h * 0x1p-52, got);
            }
        }
        /* walk down from DBL_MAX: ulp steps first, then big steps to 1e308 */
        v = it < 1000 ? nextafter(v, 0.0) : v - 7.9e304 * rnd_unit();
        if (v < 1e308) v = 1.7976931348623157e308 - 1e292 * rnd_unit();
    }
}

/* canaries: neither formatter writes at or past cap, and a short cap gives "" */
void test_fmt_caps_canary(void)
{
    const double vals[] = {0.0, -1.25, 123456.789, -9.99999e-200, 1e14, 0.00042};
    for (size_t vi = 0; vi < sizeof vals / sizeof vals[0]; vi++) {
        for (int which = 0; which < 2; which++) {
            char full[64];
            size_t need = which ? gs_num_fmt_sig(full, sizeof full, vals[vi], 7)
                                : gs_num_fmt_fixed(full, sizeof full, vals[vi], 4);
            if (which == 0 && fabs(vals[vi]) < 1e-100) {
                TEST_ASSERT_EQUAL_STRING("0.0000", full);
            }
            TEST_ASSERT_TRUE(need > 0);
            for (size_t cap = 0; cap <= need + 3; cap++) {
                char buf[80];
                memset(buf, 0xA5, sizeof buf);
                size_t n = which ? gs_num_fmt_sig(buf + 8, cap, vals[vi], 7)
                                 : gs_num_fmt_fixed(buf + 8, cap, vals[vi], 4);
                for (size_t i = 0; i < 8; i++) TEST_ASSERT_EQUAL_HEX8(0xA5, (uint8_t)buf[i]);
                for (size_t i = 8 + cap; i < sizeof buf; i++) TEST_ASSERT_EQUAL_HEX8(0xA5, (uint8_t)buf[i]);
                if (cap > need) {
                    TEST_ASSERT_EQUAL(need, n);
                    TEST_ASSERT_EQUAL_STRING(full, buf + 8);
                } else {
                    TEST_ASSERT_EQUAL(0, n);
                    if (cap) {
                        TEST_ASSERT_EQUAL_HEX8(0, (uint8_t)buf[8]);
                    }
                }
            }
        }
    }
    TEST_ASSERT_EQUAL(0, gs_num_fmt_fixed(NULL, 0, 1.0, 2));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_parse_table);
    RUN_TEST(test_parse_random_vs_strtod);
    RUN_TEST(test_parse_scaled);
    RUN_TEST(test_parse_long_digits_exact);
    RUN_TEST(test_parse_edge_table);
    RUN_TEST(test_parse_long_mantissa_sweep);
    RUN_TEST(test_parse_speed);
    RUN_TEST(test_parse_int_table);
    RUN_TEST(test_fmt_fixed_table);
    RUN_TEST(test_fmt_fixed_random_vs_libc);
    RUN_TEST(test_fmt_us_table);
    RUN_TEST(test_fmt_us_random);
    RUN_TEST(test_fmt_sig_table);
    RUN_TEST(test_fmt_sig_random);
    RUN_TEST(test_fmt_sig_near_max);
    RUN_TEST(test_fmt_caps_canary);
    return UNITY_END();
}
