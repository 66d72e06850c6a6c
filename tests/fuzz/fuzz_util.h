/* fuzz_util.h - shared by the libFuzzer harnesses (tests/fuzz/run.sh builds
 * them with clang; not part of the CMake build): a byte reader that turns the
 * fuzzer's input into values, inputs written to a temp file for readers that
 * take a path, an independent JSON validator (RFC 8259 grammar plus UTF-8) used
 * as the oracle, and a checker for the emitter's lines. Header-only, static. */
#ifndef GS_FUZZ_UTIL_H
#define GS_FUZZ_UTIL_H

#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* a failed property: say which, then abort so libFuzzer keeps the input */
#define FZ_CHECK(cond)                                                                         \
    do {                                                                                       \
        if (!(cond)) {                                                                         \
            fprintf(stderr, "%s:%d: property failed: %s\n", __FILE__, __LINE__, #cond);       \
            abort();                                                                           \
        }                                                                                      \
    } while (0)

/* ---------------------------------------------------------------- byte reader */

typedef struct {
    const uint8_t *p;
    size_t n;
} fz_in;

static inline uint8_t fz_u8(fz_in *in)
{
    if (!in->n) return 0;
    in->n--;
    return *in->p++;
}

static inline uint32_t fz_u32(fz_in *in)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) v = v << 8 | fz_u8(in);
    return v;
}

/* a double: one selector byte picks an edge case, else 8 raw bytes (any bit pattern) */
static inline double fz_double(fz_in *in)
{
    static const double edge[] = {NAN, INFINITY, -INFINITY, 0.0, -0.0, 1e15, -1e15, 999999999999999.9,
                                  -999999999999999.9, 1e300, -1e300, 1.7976931348623157e308,
                                  4.9e-324, 2.2250738585072014e-308, 0.5, 1.0, 9.81, 1.73456, -3.25e-5,
                                  0.00005, 123456.789, 1e7, 4294967296.5, 1e-7, 0.99995, 9.99995};
    const uint8_t sel = fz_u8(in);
    if (sel < sizeof edge / sizeof edge[0]) return edge[sel];
    if (sel < 128) return (double)(int8_t)fz_u8(in) * 0.37 + (double)fz_u8(in); /* ordinary values */
    uint64_t bits = 0;
    for (int i = 0; i < 8; i++) bits = bits << 8 | fz_u8(in);
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

/* NULL or a NUL-terminated string of up to max bytes copied into dst[max + 1] */
static inline const char *fz_str(fz_in *in, char *dst, size_t max)
{
    uint8_t sel = fz_u8(in);
    if (sel == 0) return NULL;
    size_t n = sel % (max + 1);
    size_t i = 0;
    for (; i < n && in->n; i++) {
        dst[i] = (char)fz_u8(in);
        if (dst[i] == '\0') break;
    }
    dst[i] = '\0';
    return dst;
}

/* ------------------------------------------------------- inputs as temp files */

/* Write data to a temp file kept for the process (one per process, so
 * libFuzzer's -fork/-jobs workers do not collide); returns its path. */
static inline const char *fz_write_temp(const uint8_t *data, size_t size, const char *suffix)
{
    static char path[256];
    if (!path[0]) {
        const char *dir = getenv("TMPDIR");
        if (!dir || !dir[0]) dir = "/tmp";
        snprintf(path, sizeof path, "%s/gs_fuzz_%ld%s", dir, (long)getpid(), suffix);
    }
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (fd < 0) {
        perror(path);
        abort(); /* the harness cannot work: not a finding in the code under test */
    }
    size_t done = 0;
    while (done < size) {
        ssize_t w = write(fd, data + done, size - done);
        if (w <= 0) {
            perror(path);
            abort();
        }
        done += (size_t)w;
    }
    close(fd);
    return path;
}

/* ------------------------------------------------------------ JSON validation */

/* Independent of src/io/gs_json_tok.c on purpose (it is the oracle for it):
 * a recursive-descent check of one JSON text. depth_max bounds nesting like
 * the tokenizer (GS_JSON_MAX_DEPTH); utf8 also demands valid UTF-8 in strings. */
typedef struct {
    const unsigned char *p, *e;
    int depth, depth_max;
    bool utf8;
} fz_json;

static void fz_ws(fz_json *j)
{
    while (j->p < j->e && (*j->p == ' ' || *j->p == '\t' || *j->p == '\r' || *j->p == '\n')) j->p++;
}

static bool fz_hex(unsigned char c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

/* one UTF-8 sequence at p (RFC 3629: no overlongs, no surrogates, <= U+10FFFF); its length or 0 */
static size_t fz_utf8_len(const unsigned char *p, const unsigned char *e)
{
    unsigned c = p[0];
    size_t n;
    unsigned min, cp;
    if (c < 0x80) return 1;
    if (c >= 0xC2 && c <= 0xDF) n = 2, min = 0x80, cp = c & 0x1F;
    else if (c >= 0xE0 && c <= 0xEF) n = 3, min = 0x800, cp = c & 0x0F;
    else if (c >= 0xF0 && c <= 0xF4) n = 4, min = 0x10000, cp = c & 0x07;
    else return 0;
    if ((size_t)(e - p) < n) return 0;
    for (size_t i = 1; i < n; i++) {
        if ((p[i] & 0xC0) != 0x80) return 0;
        cp = cp << 6 | (p[i] & 0x3Fu);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
    return n;
}

static bool fz_jstring(fz_json *j)
{
    j->p++; /* the opening quote */
    while (j->p < j->e) {
        unsigned char c = *j->p;
        if (c == '"') {
            j->p++;
            return true;
        }
        if (c < 0x20) return false;
        if (c == '\\') {
            if (j->e - j->p < 2) return false;
            unsigned char x = j->p[1];
            if (x == 'u') {
                if (j->e - j->p < 6) return false;
                for (int i = 2; i < 6; i++)
                    if (!fz_hex(j->p[i])) return false;
                j->p += 6;
            } else if (x == '"' || x == '\\' || x == '/' || x == 'b' || x == 'f' || x == 'n' || x == 'r' ||
                       x == 't') {
                j->p += 2;
            } else {
                return false;
            }
            continue;
        }
        if (j->utf8 && c >= 0x80) {
            size_t n = fz_utf8_len(j->p, j->e);
            if (!n) return false;
            j->p += n;
            continue;
        }
        j->p++;
    }
    return false;
}

static bool fz_digit(const fz_json *j) { return j->p < j->e && *j->p >= '0' && *j->p <= '9'; }

static bool fz_jnumber(fz_json *j)
{
    if (j->p < j->e && *j->p == '-') j->p++;
    if (!fz_digit(j)) return false;
    if (*j->p == '0') j->p++;
    else
        while (fz_digit(j)) j->p++;
    if (j->p < j->e && *j->p == '.') {
        j->p++;
        if (!fz_digit(j)) return false;
        while (fz_digit(j)) j->p++;
    }
    if (j->p < j->e && (*j->p == 'e' || *j->p == 'E')) {
        j->p++;
        if (j->p < j->e && (*j->p == '+' || *j->p == '-')) j->p++;
        if (!fz_digit(j)) return false;
        while (fz_digit(j)) j->p++;
    }
    return true;
}

static bool fz_jword(fz_json *j, const char *w)
{
    size_t n = strlen(w);
    if ((size_t)(j->e - j->p) < n || memcmp(j->p, w, n) != 0) return false;
    j->p += n;
    return true;
}

static bool fz_jvalue(fz_json *j)
{
    fz_ws(j);
    if (j->p >= j->e) return false;
    unsigned char c = *j->p;
    if (c == '{' || c == '[') {
        if (j->depth >= j->depth_max) return false;
        j->depth++;
        j->p++;
        fz_ws(j);
        unsigned char close = c == '{' ? '}' : ']';
        if (j->p < j->e && *j->p == close) {
            j->p++;
            j->depth--;
            return true;
        }
        for (;;) {
            if (c == '{') {
                fz_ws(j);
                if (j->p >= j->e || *j->p != '"' || !fz_jstring(j)) return false;
                fz_ws(j);
                if (j->p >= j->e || *j->p != ':') return false;
                j->p++;
            }
            if (!fz_jvalue(j)) return false;
            fz_ws(j);
            if (j->p >= j->e) return false;
            if (*j->p == ',') {
                j->p++;
                continue;
            }
            if (*j->p != close) return false;
            j->p++;
            j->depth--;
            return true;
        }
    }
    if (c == '"') return fz_jstring(j);
    if (c == '-' || (c >= '0' && c <= '9')) return fz_jnumber(j);
    return fz_jword(j, "true") || fz_jword(j, "false") || fz_jword(j, "null");
}

/* s[0..n) is exactly one JSON text (surrounding blanks allowed) */
static inline bool fz_json_valid(const char *s, size_t n, int depth_max, bool utf8)
{
    fz_json j = {(const unsigned char *)s, (const unsigned char *)s + n, 0, depth_max, utf8};
    if (!fz_jvalue(&j)) return false;
    fz_ws(&j);
    return j.p == j.e;
}

/* ------------------------------------------------------------ emitted lines */

/* A JSON Lines record: one object, valid UTF-8, '\n' last and nowhere else. */
static inline void fz_check_json_line(const char *buf, size_t n)
{
    FZ_CHECK(n > 0 && strlen(buf) == n);
    FZ_CHECK(buf[n - 1] == '\n');
    FZ_CHECK(!memchr(buf, '\n', n - 1) && !memchr(buf, '\r', n));
    FZ_CHECK(buf[0] == '{');
    FZ_CHECK(strncmp(buf, "{\"event\":\"", 10) == 0);
    FZ_CHECK(fz_json_valid(buf, n - 1, 64, true));
}

/* An NMEA 0183 sentence: "$" + printable fields + "*HH\r\n", at most 82
 * characters, the checksum the XOR of everything between '$' and '*'. */
static inline void fz_check_nmea_line(const char *buf, size_t n)
{
    static const char hex[] = "0123456789ABCDEF";
    FZ_CHECK(n >= 11 && n <= 82 && strlen(buf) == n);
    FZ_CHECK(buf[0] == '$' && strncmp(buf, "$GS", 3) == 0);
    FZ_CHECK(buf[n - 5] == '*' && buf[n - 2] == '\r' && buf[n - 1] == '\n');
    unsigned char x = 0;
    for (size_t i = 1; i < n - 5; i++) {
        unsigned char c = (unsigned char)buf[i];
        FZ_CHECK(c >= 0x20 && c <= 0x7e && !strchr("$*!\\^~", c));
        x ^= c;
    }
    FZ_CHECK(buf[n - 4] == hex[x >> 4] && buf[n - 3] == hex[x & 15u]);
}

#endif
