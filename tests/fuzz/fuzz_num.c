/* fuzz_num.c - libFuzzer harness for gs_num: parse never reads past len,
 * parse -> format -> parse stays within the format's rounding, formatters
 * never write past cap; microseconds printed as seconds parse back. Built by tests/fuzz/run.sh (clang), not by CMake.
 * -DGS_FUZZ_MAIN adds a main() that replays files or random inputs (gcc). */
#include "gravscale/gs_num.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* an exact-size heap copy lets ASan catch any read past len */
    char *s = malloc(size ? size : 1);
    if (!s) return 0;
    if (size) memcpy(s, data, size);
    double v;
    if (gs_num_parse(s, size, &v)) {
        if (!isfinite(v)) abort();
        char buf[64];
        for (int sig = 1; sig <= 15; sig++) {
            size_t n = gs_num_fmt_sig(buf, sizeof buf, v, sig);
            double back;
            if (n == 0) abort();
            if (!gs_num_parse(buf, n, &back)) {
                /* only rounding up past DBL_MAX (e.g. 1.8e308 -> "2e+308") may not parse back */
                if (fabs(v) < 1e308) abort();
                continue;
            }
            /* half a unit of the last digit, plus the re-parse rounding (2 ulp) */
            if (fabs(back - v) > fabs(v) * (pow(10, 1 - sig) * 0.5 + 0x1p-51)) abort();
        }
        if (fabs(v) < 1e15) {
            for (int d = 0; d <= 9; d++) {
                size_t n = gs_num_fmt_fixed(buf, sizeof buf, v, d);
                double back;
                if (n == 0 || !gs_num_parse(buf, n, &back)) abort();
                if (fabs(back - v) > 0.5000001 * pow(10, -d) + 1e-15 * fabs(v)) abort();
            }
        }
        /* every cap: exact-size heap buffers */
        size_t need = gs_num_fmt_sig(buf, sizeof buf, v, 7);
        for (size_t cap = 0; cap <= need + 1; cap++) {
            char *b = malloc(cap ? cap : 1);
            if (!b) break;
            size_t n = gs_num_fmt_sig(cap ? b : NULL, cap, v, 7);
            if (n != (cap > need ? need : 0)) abort();
            free(b);
        }
    }
    long l;
    (void)gs_num_parse_int(s, size, &l);
    /* the first 8 bytes as microseconds: gs_num_fmt_us parses back to t / 1e6 within
     * half a unit of its last digit, the same text for t and -t (but the sign), and
     * never past cap */
    if (size >= 8) {
        int64_t t;
        memcpy(&t, data, sizeof t);
        char buf[64], neg[64];
        for (int d = 0; d <= 9; d++) {
            size_t n = gs_num_fmt_us(buf, sizeof buf, t, d);
            if (t == INT64_MIN) {
                if (n != 0 || buf[0] != '\0') abort();
                continue;
            }
            double back;
            if (n == 0 || !gs_num_parse(buf, n, &back)) abort();
            if (fabs(back - (double)t / 1e6) > 0.5000001 * pow(10, -d) + 1e-15 * fabs((double)t / 1e6)) abort();
            size_t m = gs_num_fmt_us(neg, sizeof neg, -t, d);
            const char *a = buf[0] == '-' ? buf + 1 : buf, *b = neg[0] == '-' ? neg + 1 : neg;
            if (strcmp(a, b) != 0 || (m != n && m != n + 1 && m + 1 != n)) abort();
            char *e = malloc(n);  /* one byte short: nothing written but the NUL */
            if (e && gs_num_fmt_us(e, n, t, d) != 0) abort();
            free(e);
        }
    }
    free(s);
    return 0;
}
