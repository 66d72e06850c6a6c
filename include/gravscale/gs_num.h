/* gs_num.h - number parsing and formatting without libc's strtod/printf
 * (newlib's allocate on a microcontroller). */
#ifndef GS_NUM_H
#define GS_NUM_H

#include "gs_types.h"

/* Parse exactly s[0..len) as a decimal number: optional sign, digits, optional
 * '.' and digits, optional exponent (e/E, sign, digits). No spaces, no hex, no
 * "nan"/"inf". Returns false (out untouched) on any syntax error or when the
 * value overflows a double. The result is correctly rounded (round half to
 * even, subnormals included: the same double as a correct strtod) for any
 * number of digits. */
bool gs_num_parse(const char *s, size_t len, double *out);

/* The same syntax, but numbers beyond the fast exact cases (more than 19
 * significant digits, or a decimal exponent beyond +-22 of them) are scaled in
 * double: within 16 ulp instead of correctly rounded (and a value within 16 ulp
 * of the largest double may overflow), no multi-precision code. gs_num_parse is this where gs_real is float (the Cortex-M4 build: its
 * profile values are floats); exposed so that host tests check it. */
bool gs_num_parse_scaled(const char *s, size_t len, double *out);

/* Parse exactly s[0..len) as a base-10 integer (optional sign). */
bool gs_num_parse_int(const char *s, size_t len, long *out);

/* Format a finite v with exactly `decimals` (0..9) digits after the point,
 * rounded half away from zero, "-0.000" printed as "0.000". Writes a NUL.
 * Returns chars written (without the NUL), or 0 when v is not finite, |v| >= 1e15,
 * or cap is too small (buf then holds ""). */
size_t gs_num_fmt_fixed(char *buf, size_t cap, double v, int decimals);

/* gs_num_fmt_fixed of the float v's exact value, from its bits: where doubles are
 * emulated (a Cortex-M4F) no widening to double. */
size_t gs_num_fmt_fixed_f(char *buf, size_t cap, float v, int decimals);

/* Format t_us microseconds as seconds with exactly `decimals` (0..9) digits after
 * the point, rounded half away from zero (exact: from the integer's decimal digits),
 * "-0.000" printed as "0.000". Writes a NUL. Returns chars written (without the NUL),
 * or 0 when t_us is INT64_MIN (GS_T_NONE, gs_time.h) or cap is too small (buf then
 * holds ""). */
size_t gs_num_fmt_us(char *buf, size_t cap, int64_t t_us, int decimals);

/* Format v in decimal. Writes a NUL. Returns chars written (without the NUL), or 0 when
 * cap is too small (buf then holds ""). */
size_t gs_num_fmt_u32(char *buf, size_t cap, uint32_t v);

/* Format a finite v with `sig` (1..15) significant digits, in plain notation
 * when 1e-4 <= |v| < 1e15, otherwise as d.ddde-XX; trailing zeros trimmed.
 * Rounded half away from zero, except where that would exceed the double range
 * (near DBL_MAX the digits are cut: 1.79e308 to 1 digit is "1e+308", not "2e+308"),
 * so the text always parses back to a finite double. The text is a valid JSON
 * number. Same return convention as above. */
size_t gs_num_fmt_sig(char *buf, size_t cap, double v, int sig);

#endif
