/* gs_emit.c - events as JSON Lines or NMEA 0183-style sentences in a caller
 * buffer; all or nothing, never past cap. Field layout: docs/protocol.md.
 * Times are integer microseconds, printed as seconds from their digits; values are
 * gs_real, printed from their exact double value (a float widened from its bits). */
#include "gravscale/gs_emit.h"
#include "gravscale/gs_num.h"

#include <string.h>

#include "gs_dbits.h"
#include "gs_inline.h"

/* NMEA 0183 caps a sentence at 82 characters including "$" and CR LF: the field widths
 * of k_nmea_fields keep every sentence within it (test_emit writes each at full width). */

/* the default version text of both start lines: one object of its own, so that a
 * build with one format does not keep the other format's literals, which the
 * compiler groups with the first function that uses a shared literal */
static const char k_version[] = GS_VERSION;

typedef struct {
    char *buf;
    size_t cap;
    size_t len;
    bool ok;
} gs_w;

static void w_raw(gs_w *w, const char *s, size_t n)
{
    /* keep one byte for the NUL */
    if (!w->ok || w->len + n + 1u > w->cap) {
        w->ok = false;
        return;
    }
    memcpy(w->buf + w->len, s, n);
    w->len += n;
}

/* byte by byte, as w_raw would (one byte kept for the NUL): a counting loop
 * would become a strlen call, which a device build need not link (220 B) */
static void w_lit(gs_w *w, const char *s)
{
    for (; *s && w->ok; s++) {
        if (w->len + 2u > w->cap) w->ok = false;
        else w->buf[w->len++] = *s;
    }
}

/* Length of the valid UTF-8 sequence at s (RFC 3629: no overlong forms, no
 * surrogates, at most U+10FFFF), 0 when invalid. s is NUL-terminated and a NUL
 * fails the continuation test, so nothing past the string is read. */
static size_t utf8_len(const unsigned char *s)
{
    unsigned c = s[0];
    size_t n;
    uint32_t min, cp;
    if (c < 0x80u) return 1;
    if (c >= 0xC2u && c <= 0xDFu) n = 2, min = 0x80u, cp = c & 0x1Fu;
    else if (c >= 0xE0u && c <= 0xEFu) n = 3, min = 0x800u, cp = c & 0x0Fu;
    else if (c >= 0xF0u && c <= 0xF4u) n = 4, min = 0x10000u, cp = c & 0x07u;
    else return 0;
    for (size_t i = 1; i < n; i++) {
        if ((s[i] & 0xC0u) != 0x80u) return 0;
        cp = cp << 6 | (s[i] & 0x3Fu);
    }
    if (cp < min || cp > 0x10FFFFu || (cp >= 0xD800u && cp <= 0xDFFFu)) return 0;
    return n;
}

static size_t w_finish(gs_w *w)
{
    if (!w->ok) {
        if (w->buf && w->cap) w->buf[0] = '\0';
        return 0;
    }
    w->buf[w->len] = '\0';
    return w->len;
}

/* the gs_real at p as a double: exact (where gs_real is float, from its bits: no libgcc conversion) */
static double real_at(const void *p)
{
    gs_real r;
    memcpy(&r, p, sizeof r);
    if (GS_REAL_IS_FLOAT) return gs_dwiden((float)r);
    return (double)r;
}

/* ------------------------------------------------ fields from a table */

/* What a field's bytes at its offset are and how they are written. The first
 * kinds serve both formats; then JSON's, then NMEA's. */
enum {
    V_U32,      /* uint32_t; b = NMEA width */
    V_FIXED,    /* gs_real, a decimals; b = NMEA width */
    V_TIME,     /* int64_t microseconds as seconds, a decimals; b = NMEA width */
    V_SIG,      /* JSON: gs_real, a significant digits */
    V_FLOAT,    /* JSON: float, a decimals */
    V_STR,      /* JSON: const char * string or null; a = 1: NULL is this build's version */
    V_BOOL,     /* JSON: bool as the pair k_json_bool[a] (true, false) */
    V_REASON,   /* JSON: a jump's reject reason, null when accepted */
    V_WARNINGS, /* JSON: uint32_t GS_WARN_* bits as an array of names */
    V_CI95,     /* JSON: the gs_reals mid, lo, hi from here as [lo,hi] or null */
    V_FLAG,     /* NMEA: bool as the letter pair k_nmea_flags[a] (true, false) */
    V_DIGIT,    /* NMEA: a gs_reject_reason as one character, 0-9 then A-Z */
    V_INITIAL,  /* NMEA: a string's first letter in upper case */
    V_HEX8,     /* NMEA: the low byte of a uint32_t in two hex digits */
    V_TEXT      /* NMEA: a string of at most NMEA_TEXT_MAX characters, NULL: this build's version */
};

typedef struct {
    uint8_t off; /* offsetof the field in the event's union member */
    uint8_t kind : 4, a : 4; /* what a means: the kinds above (digits and pairs are below 16) */
    uint8_t b;
} field;
_Static_assert(sizeof(field) == 3, "a field is 3 bytes");
_Static_assert(V_TEXT < 16, "field.kind is 4 bits");

_Static_assert(sizeof(gs_ev_jump) <= 256 && sizeof(gs_ev_session) <= 256, "field.off is 8 bits");

static const void *field_at(const void *base, const field *f) { return (const char *)base + f->off; }

static uint32_t u32_at(const void *p)
{
    uint32_t v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* the number of kind V_U32 (uint32_t, no decimals), V_FIXED (gs_real), V_FLOAT (float) or
 * V_TIME (int64_t microseconds, as seconds) at p with `decimals` decimals: a float from
 * its bits, no double emulated */
static size_t fmt_number(char *t, size_t cap, int kind, const void *p, int decimals)
{
    if (kind == V_U32) return gs_num_fmt_u32(t, cap, u32_at(p));
    if (kind == V_TIME) {
        int64_t us;
        memcpy(&us, p, sizeof us);
        return gs_num_fmt_us(t, cap, us, decimals);
    }
    if (kind == V_FLOAT || GS_REAL_IS_FLOAT) {
        float x;
        memcpy(&x, p, sizeof x);
        return gs_num_fmt_fixed_f(t, cap, x, decimals);
    }
    return gs_num_fmt_fixed(t, cap, real_at(p), decimals);
}

/* That number in at most `width` characters, with fewer decimals when the text is
 * wider (NMEA: keeps a sentence <= 82 chars); false (nothing written) when it is
 * unknown, not finite or beyond 1e15 (at any number of decimals: fewer do not help,
 * every such text is shorter than t) or cannot fit. */
static bool w_number(gs_w *w, int kind, const void *p, int decimals, size_t width)
{
    char t[40];
    for (int d = decimals; d >= 0; d--) {
        size_t n = fmt_number(t, sizeof t, kind, p, d);
        if (n && n <= width) {
            w_raw(w, t, n);
            return true;
        }
    }
    return false;
}

/* ------------------------------------------------------------------ NMEA */

/* NMEA text fields may not hold the delimiters $ * , ! \ ^ ~ or non-printables */
static void n_text(gs_w *w, const char *s, size_t max_len)
{
    for (size_t i = 0; s && s[i] && i < max_len; i++) {
        char c = s[i];
        /* NMEA's reserved characters (not strchr: no libc search linked for this) */
        if (c < 0x20 || c > 0x7e || c == '$' || c == '*' || c == ',' || c == '!' || c == '\\' || c == '^' ||
            c == '~')
            c = '_';
        w_raw(w, &c, 1);
    }
}

static const char k_hex_upper[] = "0123456789ABCDEF";

/* the NMEA letters of a V_FLAG field: true, false */
static const char k_nmea_flags[][2] = {{'A', 'R'}, {'E', 'S'}};

/* the version field's width */
#define NMEA_TEXT_MAX 20

/* after its comma */
static NOINLINE void w_nmea_value(gs_w *w, const void *base, const field *f)
{
    const void *p = field_at(base, f);
    char c[2];
    size_t n = 0;
    switch (f->kind) {
    case V_U32:
    case V_FIXED:
    case V_TIME: (void)w_number(w, f->kind, p, f->a, f->b); return;
    case V_FLAG: {
        bool b;
        memcpy(&b, p, sizeof b);
        c[n++] = k_nmea_flags[f->a][b ? 0 : 1];
        break;
    }
    case V_DIGIT: {
        gs_reject_reason r;
        memcpy(&r, p, sizeof r);
        if ((uint32_t)r <= 9u) c[n++] = (char)('0' + (int)r);
        else if ((uint32_t)r <= 35u) c[n++] = (char)('A' + (int)r - 10);  /* one character: 10 is A */
        break;
    }
    case V_INITIAL: { /* A absence, N new_body, E end_of_stream */
        const char *s;
        memcpy(&s, p, sizeof s);
        if (s) c[n++] = (char)(s[0] >= 'a' && s[0] <= 'z' ? s[0] - 'a' + 'A' : '_');
        break;
    }
    case V_HEX8: { /* the GS_WARN_* bits in hex */
        uint32_t b = u32_at(p);
        c[n++] = k_hex_upper[(b >> 4) & 15u];
        c[n++] = k_hex_upper[b & 15u];
        break;
    }
    default: { /* V_TEXT */
        const char *s;
        memcpy(&s, p, sizeof s);
        n_text(w, s ? s : k_version, NMEA_TEXT_MAX);
        break;
    }
    }
    w_raw(w, c, n);
}

#define NF(type, name, kind, a, b) {(uint8_t)offsetof(type, name), kind, a, b}

/* every sentence's fields, each after a comma, event by event (docs/protocol.md).
 * Widths keep a sentence within 82 characters ("$GS" + tag 6, a comma a field, "*HH\r\n" 5;
 * a V_U32 without width at most 10 digits, V_TEXT 20, a flag, digit or initial 1, hex 2):
 * STA 43, JMP 82 ($GSJMP 10+5+8+9+6+5+6+10+1+1 = 61 = 82 - 6 - 10 - 5), HGT 61, SUM 72,
 * SES 72, WRN 25. */
static const field k_nmea_fields[] = {
#define N_START 0
    NF(gs_ev_start, version, V_TEXT, 0, 0),
    NF(gs_ev_start, fps_source, V_FIXED, 3, 10),
#define N_JUMP 2
    NF(gs_ev_jump, t_takeoff_us, V_TIME, 3, 10),
    NF(gs_ev_jump, flight_time_s, V_FIXED, 3, 5),
    NF(gs_ev_jump, a_px_s2, V_FIXED, 1, 8),
    NF(gs_ev_jump, q_m_per_px, V_FIXED, 7, 9),
    NF(gs_ev_jump, height_m, V_FIXED, 3, 6),
    NF(gs_ev_jump, jump_height_m, V_FIXED, 3, 5),
    NF(gs_ev_jump, takeoff_velocity_m_s, V_FIXED, 2, 6),
    NF(gs_ev_jump, n_samples, V_U32, 0, 10),
    NF(gs_ev_jump, accepted, V_FLAG, 0, 0),
    NF(gs_ev_jump, reason, V_DIGIT, 0, 0),
#define N_HEIGHT 12
    NF(gs_ev_height, height_m, V_FIXED, 4, 12),
    NF(gs_ev_height, ci95_lo_m, V_FIXED, 4, 12),
    NF(gs_ev_height, ci95_hi_m, V_FIXED, 4, 12),
    NF(gs_ev_height, n_jumps, V_U32, 0, 10),
#define N_HEIGHT_END 16 /* the summary adds n_rejected */
    NF(gs_ev_height, n_rejected, V_U32, 0, 10),
#define N_SESSION 17
    NF(gs_ev_session, session, V_U32, 0, 5),
    NF(gs_ev_session, ended, V_FLAG, 1, 0),
    NF(gs_ev_session, reason, V_INITIAL, 0, 0),
    NF(gs_ev_session, t_start_us, V_TIME, 3, 10),
    NF(gs_ev_session, t_end_us, V_TIME, 3, 10),
    NF(gs_ev_session, stature_m, V_FIXED, 3, 6),
    NF(gs_ev_session, n_jumps, V_U32, 0, 3),
    NF(gs_ev_session, best_jump_m, V_FIXED, 3, 5),
    NF(gs_ev_session, mean_jump_m, V_FIXED, 3, 5),
    NF(gs_ev_session, mean_flight_s, V_FIXED, 3, 5),
#define N_WARNING 27
    NF(gs_ev_warning, t_us, V_TIME, 3, 10),
    NF(gs_ev_warning, warnings, V_HEX8, 0, 0),
#define N_END 29
};
_Static_assert(sizeof k_nmea_fields / sizeof k_nmea_fields[0] == N_END, "the N_* indexes match the table");

/* a sentence: $GS, the tag, then fields [first, end); trace events have none */
static const struct {
    char tag[3]; /* no NUL: written as its 3 bytes */
    uint8_t first, end;
} k_nmea_lines[] = {
    {{'S', 'T', 'A'}, N_START, N_JUMP},          {{'J', 'M', 'P'}, N_JUMP, N_HEIGHT},
    {{'H', 'G', 'T'}, N_HEIGHT, N_HEIGHT_END},   {{'S', 'U', 'M'}, N_HEIGHT, N_HEIGHT_END + 1},
    {{'S', 'E', 'S'}, N_SESSION, N_WARNING},     {{'W', 'R', 'N'}, N_WARNING, N_END},
};

size_t gs_emit_nmea(const gs_event *ev, char *buf, size_t cap)
{
    gs_w w = {buf, cap, 0, false};
    if (!buf || !ev || (unsigned)ev->type >= sizeof k_nmea_lines / sizeof k_nmea_lines[0]) return w_finish(&w);
    w.ok = true;
    /* read once: the line's bytes may alias the event */
    unsigned type = (unsigned)ev->type, end = k_nmea_lines[type].end;
    w_raw(&w, "$GS", 3);
    w_raw(&w, k_nmea_lines[type].tag, 3);
    for (unsigned i = k_nmea_lines[type].first; i < end; i++) {
        w_raw(&w, ",", 1);
        w_nmea_value(&w, &ev->u, &k_nmea_fields[i]);
    }
    /* the checksum of a line that failed is not written: w_raw adds nothing once !w.ok */
    unsigned char x = 0;
    for (size_t i = 1; i < w.len; i++) x ^= (unsigned char)w.buf[i];
    char tail[5] = {'*', k_hex_upper[x >> 4], k_hex_upper[x & 15u], '\r', '\n'};
    /* within 82 characters: the widths of k_nmea_fields bound every sentence (their sums there) */
    w_raw(&w, tail, sizeof tail);
    return w_finish(&w);
}

/* ------------------------------------------------------------------ JSON */

/* a JSON string; NULL -> null. Control bytes become \u00XX; valid UTF-8 passes;
 * a byte that is not UTF-8 (a Latin-1 file name) becomes \ufffd, because JSON
 * text must be UTF-8 (RFC 8259 8.1) and readers reject the whole line otherwise. */
static void w_jstr(gs_w *w, const char *s)
{
    static const char hex[] = "0123456789abcdef";
    if (!s) {
        w_lit(w, "null");
        return;
    }
    w_raw(w, "\"", 1);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') {
            char e[2] = {'\\', (char)c};
            w_raw(w, e, 2);
        } else if (c < 0x20u) {
            char e[6] = {'\\', 'u', '0', '0', hex[c >> 4], hex[c & 15u]};
            w_raw(w, e, 6);
        } else if (c < 0x80u) {
            w_raw(w, (const char *)&c, 1);
        } else {
            size_t n = utf8_len((const unsigned char *)s);
            if (n) {
                w_raw(w, s, n);
                s += n - 1;
            } else {
                w_lit(w, "\\ufffd");
            }
        }
    }
    w_raw(w, "\"", 1);
}

/* names of the GS_WARN_* bits, in bit order (protocol names) */
static const char *const k_warn_names[] = {"few_samples", "gravity_tilt", "size_changed", "outliers",
                                           "edge_truncated", "camera_moved", "left_frame", "out_of_plane",
                                           "other_motion", "no_size", "depth_changed", "com_timed",
                                           "com_mismatch"};

/* [names of the known set bits, in bit order] */
static void w_warnings(gs_w *w, uint32_t bits)
{
    w_raw(w, "[", 1);
    bool first = true;
    for (uint32_t b = 0; b < sizeof k_warn_names / sizeof k_warn_names[0]; b++) {
        if (!(bits & (1u << b))) continue;
        if (!first) w_raw(w, ",", 1);
        w_jstr(w, k_warn_names[b]);
        first = false;
    }
    w_raw(w, "]", 1);
}

/* a number, or null */
static void w_json_number(gs_w *w, int kind, const void *p, int decimals)
{
    if (!w_number(w, kind, p, decimals, SIZE_MAX)) w_lit(w, "null");
}

/* [lo,hi], or null: an interval with an unknown end is no interval */
static void w_ci95(gs_w *w, const void *mid_lo_hi)
{
    const gs_real *v = mid_lo_hi;
    if (gs_dfinite(real_at(v + 1)) && gs_dfinite(real_at(v + 2)) && gs_dfinite(real_at(v))) {
        w_raw(w, "[", 1);
        w_json_number(w, V_FIXED, v + 1, 4);
        w_raw(w, ",", 1);
        w_json_number(w, V_FIXED, v + 2, 4);
        w_raw(w, "]", 1);
    } else {
        w_lit(w, "null");
    }
}

static const char *const k_json_bool[][2] = {{"true", "false"}, {"\"end\"", "\"start\""}};

static void w_json_value(gs_w *w, const void *base, const field *f)
{
    const void *p = field_at(base, f);
    double d;
    const char *s;
    bool b;
    switch (f->kind) {
    case V_SIG:
        d = real_at(p);
        char t[40];
        size_t n = gs_num_fmt_sig(t, sizeof t, d, f->a);
        if (n) w_raw(w, t, n);
        else w_lit(w, "null");
        break;
    case V_U32:
    case V_FIXED:
    case V_TIME:
    case V_FLOAT:
        w_json_number(w, f->kind, p, f->a);
        break;
    case V_STR:
        memcpy(&s, p, sizeof s);
        w_jstr(w, s || !f->a ? s : k_version);
        break;
    case V_BOOL:
        memcpy(&b, p, sizeof b);
        w_lit(w, k_json_bool[f->a][b ? 0 : 1]);
        break;
    case V_REASON: {
        const gs_ev_jump *j = (const gs_ev_jump *)base;
        w_jstr(w, j->accepted ? NULL : gs_reject_reason_name(j->reason));
        break;
    }
    case V_WARNINGS: {
        w_warnings(w, u32_at(p));
        break;
    }
    default: w_ci95(w, p); break;
    }
}

/* a JSON field: ,"name": and the value */
typedef struct {
    const char *name;
    field f;
} json_field;

#define JF(type, name, kind, a) {#name, {(uint8_t)offsetof(type, name), kind, a, 0}}
#define JFX(type, name, at, kind, a) {name, {(uint8_t)offsetof(type, at), kind, a, 0}}

_Static_assert(offsetof(gs_ev_height, ci95_lo_m) == offsetof(gs_ev_height, height_m) + sizeof(gs_real) &&
                   offsetof(gs_ev_height, ci95_hi_m) == offsetof(gs_ev_height, height_m) + 2 * sizeof(gs_real) &&
                   offsetof(gs_ev_session, ci95_lo_m) == offsetof(gs_ev_session, stature_m) + sizeof(gs_real) &&
                   offsetof(gs_ev_session, ci95_hi_m) == offsetof(gs_ev_session, stature_m) + 2 * sizeof(gs_real),
               "V_CI95 reads mid, lo, hi in a row");

/* every line's fields, event by event (docs/protocol.md) */
static const json_field k_json_fields[] = {
#define J_START 0
    JF(gs_ev_start, version, V_STR, 1),
    JF(gs_ev_start, config, V_STR, 0),
    JF(gs_ev_start, fps_source, V_SIG, 6),
    JF(gs_ev_start, fps_origin, V_STR, 0),
    JF(gs_ev_start, layout, V_STR, 0),
#define J_JUMP 5
    JF(gs_ev_jump, track, V_U32, 0),
    JF(gs_ev_jump, index, V_U32, 0),
    JFX(gs_ev_jump, "t_takeoff_s", t_takeoff_us, V_TIME, 4),
    JFX(gs_ev_jump, "t_land_s", t_land_us, V_TIME, 4),
    JF(gs_ev_jump, flight_time_s, V_FIXED, 4),
    JFX(gs_ev_jump, "t_apex_s", t_apex_us, V_TIME, 4),
    JF(gs_ev_jump, a_px_s2, V_SIG, 6),
    JF(gs_ev_jump, a_px_se_s2, V_SIG, 6),
    JF(gs_ev_jump, g_dir_deg, V_FIXED, 2),
    JF(gs_ev_jump, q_m_per_px, V_SIG, 6),
    JF(gs_ev_jump, size_px, V_FIXED, 2),
    JF(gs_ev_jump, height_m, V_FIXED, 4),
    JF(gs_ev_jump, height_se_m, V_FIXED, 4),
    JF(gs_ev_jump, jump_height_m, V_FIXED, 4),
    JF(gs_ev_jump, takeoff_velocity_m_s, V_FIXED, 3),
    JF(gs_ev_jump, com_rise_m, V_FIXED, 4),
    JF(gs_ev_jump, contact_time_s, V_FIXED, 4),
    JF(gs_ev_jump, rsi, V_FIXED, 3),
    JF(gs_ev_jump, n_samples, V_U32, 0),
    JF(gs_ev_jump, n_outliers, V_U32, 0),
    JF(gs_ev_jump, rms_px, V_FIXED, 3),
    JF(gs_ev_jump, accepted, V_BOOL, 0),
    JF(gs_ev_jump, reason, V_REASON, 0),
    JF(gs_ev_jump, warnings, V_WARNINGS, 0),
#define J_HEIGHT 29
    JF(gs_ev_height, track, V_U32, 0),
    JF(gs_ev_height, height_m, V_FIXED, 4),
    JFX(gs_ev_height, "ci95_m", height_m, V_CI95, 0),
    JF(gs_ev_height, n_jumps, V_U32, 0),
    JF(gs_ev_height, n_rejected, V_U32, 0),
#define J_SESSION 34
    JF(gs_ev_session, track, V_U32, 0),
    JF(gs_ev_session, session, V_U32, 0),
    JFX(gs_ev_session, "state", ended, V_BOOL, 1),
    JF(gs_ev_session, reason, V_STR, 0),
    JFX(gs_ev_session, "t_start_s", t_start_us, V_TIME, 4),
    JFX(gs_ev_session, "t_end_s", t_end_us, V_TIME, 4),
    JF(gs_ev_session, stature_m, V_FIXED, 4),
    JFX(gs_ev_session, "ci95_m", stature_m, V_CI95, 0),
    JF(gs_ev_session, n_jumps, V_U32, 0),
    JF(gs_ev_session, n_rejected, V_U32, 0),
    JF(gs_ev_session, best_jump_m, V_FIXED, 4),
    JF(gs_ev_session, mean_jump_m, V_FIXED, 4),
    JF(gs_ev_session, best_flight_s, V_FIXED, 4),
    JF(gs_ev_session, mean_flight_s, V_FIXED, 4),
    JF(gs_ev_session, mean_takeoff_velocity_m_s, V_FIXED, 3),
#define J_WARNING 49
    JF(gs_ev_warning, track, V_U32, 0),
    JFX(gs_ev_warning, "t_s", t_us, V_TIME, 4),
    JF(gs_ev_warning, warnings, V_WARNINGS, 0),
#define J_TRACE 52
#if GS_WITH_TRACE /* trace events (gs_features.h): without them, no form (returns 0) */
#define J_STATE J_TRACE
    JFX(gs_ev_state, "t_s", t_us, V_TIME, 4),
    JF(gs_ev_state, from, V_STR, 0),
    JF(gs_ev_state, to, V_STR, 0),
#define J_SAMPLE 55
    JFX(gs_ev_sample, "t_s", t_us, V_TIME, 4),
    JF(gs_ev_sample, x_px, V_FLOAT, 2),
    JF(gs_ev_sample, y_px, V_FLOAT, 2),
    JF(gs_ev_sample, w, V_FLOAT, 3),
    JF(gs_ev_sample, size_px, V_FLOAT, 2),
    JF(gs_ev_sample, upright, V_FLOAT, 3),
#define J_FIT 61
    JF(gs_ev_fit, purpose, V_STR, 0),
    JFX(gs_ev_fit, "t_first_s", t_first_us, V_TIME, 4),
    JFX(gs_ev_fit, "t_last_s", t_last_us, V_TIME, 4),
    JF(gs_ev_fit, n, V_U32, 0),
    JF(gs_ev_fit, a_px_s2, V_SIG, 6),
    JF(gs_ev_fit, g_dir_deg, V_FIXED, 2),
    JF(gs_ev_fit, rms_px, V_FIXED, 3),
#define J_END 68
#else
#define J_END J_TRACE
#endif
};
_Static_assert(sizeof k_json_fields / sizeof k_json_fields[0] == J_END, "the J_* indexes match the table");

/* a line: {"event":"name", then fields [first, end) */
static const struct {
    const char *name;
    uint8_t first, end;
} k_json_lines[] = {
    {"start", J_START, J_JUMP},        {"jump", J_JUMP, J_HEIGHT},         {"height", J_HEIGHT, J_SESSION},
    {"summary", J_HEIGHT, J_SESSION},  {"session", J_SESSION, J_WARNING},  {"warning", J_WARNING, J_TRACE},
#if GS_WITH_TRACE
    {"state", J_STATE, J_SAMPLE},      {"sample", J_SAMPLE, J_FIT},        {"fit", J_FIT, J_END},
#endif
};

size_t gs_emit_json_str(const char *s, char *buf, size_t cap)
{
    gs_w w = {buf, cap, 0, buf != NULL};
    w_jstr(&w, s);
    return w_finish(&w);
}

size_t gs_emit_json(const gs_event *ev, char *buf, size_t cap)
{
    gs_w w = {buf, cap, 0, buf != NULL && ev != NULL};
    if (w.ok && (unsigned)ev->type >= sizeof k_json_lines / sizeof k_json_lines[0]) w.ok = false;
    if (!w.ok) return w_finish(&w);
    w_lit(&w, "{\"event\":\"");
    w_lit(&w, k_json_lines[ev->type].name);
    w_raw(&w, "\"", 1);
    for (unsigned i = k_json_lines[ev->type].first; i < k_json_lines[ev->type].end; i++) {
        w_raw(&w, ",\"", 2);
        w_lit(&w, k_json_fields[i].name);
        w_raw(&w, "\":", 2);
        w_json_value(&w, &ev->u, &k_json_fields[i].f);
    }
    w_lit(&w, "}\n");
    return w_finish(&w);
}

size_t gs_emit(gs_format fmt, const gs_event *ev, char *buf, size_t cap)
{
    /* a format left out of the build (gs_features.h) writes nothing */
    switch (fmt) {
    case GS_FMT_JSON:
        if (GS_WITH_JSON) return gs_emit_json(ev, buf, cap);
        break;
    case GS_FMT_NMEA:
        if (GS_WITH_NMEA) return gs_emit_nmea(ev, buf, cap);
        break;
    }
    if (buf && cap) buf[0] = '\0';
    return 0;
}
