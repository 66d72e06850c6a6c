/* test_fastnum.c - the readers' fast decimal path (src/io/gs_fastnum.h) against
 * strtod: what it takes is strtod's double bit for bit, what it declines goes to
 * gs_num_parse, and nothing that is not a finite number comes back as one. */
#include "gs_fastnum.h"
#include "unity.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void setUp(void) {}
void tearDown(void) {}

static uint64_t bits(double d)
{
    uint64_t b;
    memcpy(&b, &d, sizeof b);
    return b;
}

/* fast: 1 the fast scan takes the whole string, 0 it declines; full: 1 the
 * reader's parse gives strtod's value, 0 it refuses the field */
typedef struct {
    const char *s;
    int fast, full;
} row;

static const row k_rows[] = {
    /* the common fields */
    {"0", 1, 1}, {"7", 1, 1}, {"959.60", 1, 1}, {"0.74", 1, 1}, {"1.00", 1, 1}, {"0.000000", 1, 1},
    {"1199.966667", 1, 1}, {"12.5", 1, 1}, {"0.1", 1, 1}, {"0.3", 1, 1}, {"2.675", 1, 1},
    /* signs and zeros */
    {"-0", 1, 1}, {"-0.00", 1, 1}, {"+0", 1, 1}, {"+1.5", 1, 1}, {"-1.5", 1, 1}, {"-959.60", 1, 1},
    {"007", 1, 1}, {"000.0001", 1, 1}, {"-000000000000000", 1, 1},
    /* 15 digits: the longest fast mantissa, the point anywhere */
    {"999999999999999", 1, 1}, {"99999999999999.9", 1, 1}, {"0.99999999999999", 1, 1},
    {".999999999999999", 0, 1}, {"1.23456789012345", 1, 1}, {"-123456789.012345", 1, 1},
    {"0.00000000000001", 1, 1},
    /* longer mantissas: the full parser, still strtod's double */
    {"9999999999999999", 0, 1}, {"1.234567890123456", 0, 1}, {"9007199254740993", 0, 1},
    {"0.1000000000000000055511151231257827", 0, 1}, {"123456789012345678901234567890", 0, 1},
    {"2.2250738585072011e-308", 0, 1}, {"4.9406564584124654e-324", 0, 1},
    {"1.7976931348623157e308", 0, 1}, {"0.000000000000000000000000000001", 0, 1},
    /* exponents */
    {"1e5", 0, 1}, {"1E5", 0, 1}, {"1.5e-3", 0, 1}, {"-2.5E+2", 0, 1}, {"1e22", 0, 1}, {"1e23", 0, 1},
    {"1e-400", 0, 1}, {"0e0", 0, 1},
    /* strtod takes them, the readers do not: no silent inf or nan */
    {"1e400", 0, 0}, {"-1e309", 0, 0}, {"nan", 0, 0}, {"NaN", 0, 0}, {"-nan", 0, 0}, {"inf", 0, 0},
    {"-inf", 0, 0}, {"Infinity", 0, 0}, {"0x10", 0, 0}, {"0x1p3", 0, 0},
    /* not numbers */
    {"", 0, 0}, {"-", 0, 0}, {"+", 0, 0}, {".", 0, 0}, {"-.", 0, 0}, {"e5", 0, 0}, {"1e", 0, 0},
    {"1e+", 0, 0}, {"1.2.3", 0, 0}, {"1,5", 0, 0}, {"abc", 0, 0}, {"12a", 0, 0}, {"--1", 0, 0},
    {"+-1", 0, 0}, {" 1", 0, 0}, {"1 ", 0, 0}, {"1_000", 0, 0}, {"0..5", 0, 0},
    /* the fast path's own edges: the full parser's */
    {".5", 0, 1}, {"5.", 0, 1}, {"-.5", 0, 1}, {"+5.", 0, 1},
};

/* the scan on a copy of s followed by zeros, as the reader's buffer ends in its sentinel */
static const char *scan_padded(const char *s, double *v, size_t *stop)
{
    static char buf[96];
    size_t n = strlen(s);
    TEST_ASSERT_TRUE(n + 16 < sizeof buf);
    memset(buf, 0, sizeof buf);
    memcpy(buf, s, n);
    const char *e = gs_fastnum_scan(buf, v);
    *stop = e ? (size_t)(e - buf) : 0;
    return e;
}

/* the reader's parse as csv_row calls it: strtod's value, or a refusal */
static void check_full(const char *s, int want)
{
    size_t n = strlen(s);
    double got = -12345.0;
    bool ok = gs_fastnum_parse(s, n, &got);
    char *end;
    errno = 0;
    double ref = strtod(s, &end);
    bool ref_ok = n > 0 && end == s + n && isfinite(ref);
    char msg[128];
    snprintf(msg, sizeof msg, "'%s'", s);
    TEST_ASSERT_EQUAL_INT_MESSAGE(want, ok, msg);
    if (ok) {
        TEST_ASSERT_TRUE_MESSAGE(ref_ok, msg);
        TEST_ASSERT_EQUAL_HEX64_MESSAGE(bits(ref), bits(got), msg);
    }
}

static void check_fast(const char *s, int want)
{
    double got;
    size_t stop;
    const char *e = scan_padded(s, &got, &stop);
    char msg[128];
    snprintf(msg, sizeof msg, "'%s'", s);
    bool whole = e && stop == strlen(s);
    TEST_ASSERT_EQUAL_INT_MESSAGE(want, whole, msg);
    if (whole)
        TEST_ASSERT_EQUAL_HEX64_MESSAGE(bits(strtod(s, NULL)), bits(got), msg);
}

static void test_table(void)
{
    for (size_t i = 0; i < sizeof k_rows / sizeof k_rows[0]; i++) {
        check_fast(k_rows[i].s, k_rows[i].fast);
        check_full(k_rows[i].s, k_rows[i].full);
    }
}

/* the scan stops at the delimiter, the line end or the sentinel, and says where */
static void test_stops(void)
{
    static const struct {
        const char *s;
        size_t at; /* where it stops; 0 = declined */
    } k[] = {{"959.60,250.31", 6}, {"0.74\n", 4}, {"0.74\r\n", 4}, {"-3,", 2}, {"12 ", 2},
             {"1.5e3,", 3}, {"5.,", 0}, {"1234567,", 7}, {"12345678,", 8},
             {"1234567.1234567,", 15}, {"1234567.12345678,", 16}, {"1234567.123456789,", 0}, {"12345678.1234567,", 16}, {"-1.2\xff", 4},
             {"9\x80", 1}, {"1.2/", 3}, {"1.2:", 3}, {",1", 0}, {"1234567890123456,", 0}, {"1.x", 0}};
    for (size_t i = 0; i < sizeof k / sizeof k[0]; i++) {
        double v;
        size_t stop;
        scan_padded(k[i].s, &v, &stop);
        TEST_ASSERT_EQUAL_UINT_MESSAGE((unsigned)k[i].at, (unsigned)stop, k[i].s);
    }
}

/* the field is not NUL-terminated in the reader's buffer: the next byte is a digit here */
static void test_field_inside_buffer(void)
{
    const char *buf = "959.601234";
    double v;
    TEST_ASSERT_TRUE(gs_fastnum_parse(buf, 6, &v));
    TEST_ASSERT_EQUAL_HEX64(bits(strtod("959.60", NULL)), bits(v));
    TEST_ASSERT_TRUE(gs_fastnum_parse(buf, 3, &v));
    TEST_ASSERT_EQUAL_HEX64(bits(959.0), bits(v));
}

/* deterministic PRNG (splitmix64) so failures reproduce */
static uint64_t g_rng = 0x2545F4914F6CDD1Dull;
static uint64_t rnd64(void)
{
    uint64_t z = (g_rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* a million random plain decimals of 1..18 digits, the point anywhere, either sign */
static void test_random_decimals(void)
{
    char s[40];
    for (int i = 0; i < 1000000; i++) {
        uint64_t r = rnd64();
        int nd = 1 + (int)(r % 18);
        int pt = (int)((r >> 8) % (uint64_t)(nd + 1)); /* digits before the point; nd: none */
        size_t n = 0;
        if ((r >> 16) & 1u)
            s[n++] = (r >> 17) & 1u ? '-' : '+';
        uint64_t d = rnd64();
        for (int k = 0; k < nd; k++) {
            if (k == pt && pt > 0)
                s[n++] = '.';
            s[n++] = (char)('0' + (k == 0 && (r >> 18) % 4 == 0 ? 0 : (int)(d % 10)));
            d /= 10;
            if (d == 0)
                d = rnd64();
        }
        s[n] = '\0';
        double ref = strtod(s, NULL);
        double v;
        size_t stop;
        const char *e = scan_padded(s, &v, &stop);
        bool want_fast = nd <= 15;
        TEST_ASSERT_EQUAL_INT_MESSAGE(want_fast, e && stop == n, s);
        if (e)
            TEST_ASSERT_EQUAL_HEX64_MESSAGE(bits(ref), bits(v), s);
        TEST_ASSERT_TRUE_MESSAGE(gs_fastnum_parse(s, n, &v), s);
        TEST_ASSERT_EQUAL_HEX64_MESSAGE(bits(ref), bits(v), s);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_table);
    RUN_TEST(test_stops);
    RUN_TEST(test_field_inside_buffer);
    RUN_TEST(test_random_decimals);
    return UNITY_END();
}
