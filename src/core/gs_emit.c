/* gs_emit.c - events as JSON Lines or NMEA 0183-style sentences in a caller
 * buffer; all or nothing, never past cap. Field layout: docs/protocol.md.
 * double: event fields are double (times of day-long streams); one line per event. */
#include "gravscale/gs_emit.h"
#include "gravscale/gs_num.h"

#include <math.h>
#include <string.h>

/* NMEA 0183 caps a sentence at 82 characters including "$" and CR LF. */
#define NMEA_MAX 82u

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

static void w_u32(gs_w *w, uint32_t v)
{
    char t[12];
    size_t n = sizeof t;
    do {
        t[--n] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v);
    w_raw(w, t + n, sizeof t - n);
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

static void w_fixed(gs_w *w, double v, int decimals)
{
    char t[40];
    size_t n = gs_num_fmt_fixed(t, sizeof t, v, decimals);
    if (n) w_raw(w, t, n);
    else w_lit(w, "null"); /* NaN, inf, or beyond 1e15 */
}

static void w_sig(gs_w *w, double v, int sig)
{
    char t[40];
    size_t n = gs_num_fmt_sig(t, sizeof t, v, sig);
    if (n) w_raw(w, t, n);
    else w_lit(w, "null");
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

/* names of the GS_WARN_* bits, in bit order (protocol names) */
static const char *const k_warn_names[] = {"few_samples", "gravity_tilt", "size_changed", "outliers",
                                           "edge_truncated", "camera_moved", "left_frame", "out_of_plane",
                                           "other_motion"};

/* ,"warnings":[names of the known set bits, in bit order] */
static void w_warnings(gs_w *w, uint32_t bits)
{
    w_lit(w, ",\"warnings\":[");
    bool first = true;
    for (uint32_t b = 0; b < sizeof k_warn_names / sizeof k_warn_names[0]; b++) {
        if (!(bits & (1u << b))) continue;
        if (!first) w_raw(w, ",", 1);
        w_jstr(w, k_warn_names[b]);
        first = false;
    }
    w_lit(w, "]");
}

/* An event's numbers as a table: the text before the value (key and separator)
 * and where the value is. One loop writes them all (the hand-written sequence of
 * calls cost about 20 bytes of code per field). */
enum { F_U32 = 0xFF, F_SIG = 0x10 }; /* kind: 0..9 fixed decimals, F_SIG + n significant digits */
typedef struct {
    const char *key;
    uint8_t off;  /* offsetof the double or uint32_t field */
    uint8_t kind;
} json_field;

#define JF(type, field, key, kind) {key, (uint8_t)offsetof(type, field), kind}
_Static_assert(sizeof(gs_ev_jump) <= 256 && sizeof(gs_ev_session) <= 256, "json_field.off is 8 bits");

static void w_fields(gs_w *w, const void *base, const json_field *t, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const char *p = (const char *)base + t[i].off;
        w_lit(w, t[i].key);
        if (t[i].kind == F_U32) {
            uint32_t v;
            memcpy(&v, p, sizeof v);
            w_u32(w, v);
        } else {
            double v;
            memcpy(&v, p, sizeof v);
            if (t[i].kind >= F_SIG) w_sig(w, v, t[i].kind - F_SIG);
            else w_fixed(w, v, t[i].kind);
        }
    }
}

static const json_field k_jump_fields[] = {
    JF(gs_ev_jump, track, "{\"event\":\"jump\",\"track\":", F_U32),
    JF(gs_ev_jump, index, ",\"index\":", F_U32),
    JF(gs_ev_jump, t_takeoff_s, ",\"t_takeoff_s\":", 4),
    JF(gs_ev_jump, t_land_s, ",\"t_land_s\":", 4),
    JF(gs_ev_jump, flight_time_s, ",\"flight_time_s\":", 4),
    JF(gs_ev_jump, t_apex_s, ",\"t_apex_s\":", 4),
    JF(gs_ev_jump, a_px_s2, ",\"a_px_s2\":", F_SIG + 6),
    JF(gs_ev_jump, a_px_se_s2, ",\"a_px_se_s2\":", F_SIG + 6),
    JF(gs_ev_jump, g_dir_deg, ",\"g_dir_deg\":", 2),
    JF(gs_ev_jump, q_m_per_px, ",\"q_m_per_px\":", F_SIG + 6),
    JF(gs_ev_jump, size_px, ",\"size_px\":", 2),
    JF(gs_ev_jump, height_m, ",\"height_m\":", 4),
    JF(gs_ev_jump, height_se_m, ",\"height_se_m\":", 4),
    JF(gs_ev_jump, jump_height_m, ",\"jump_height_m\":", 4),
    JF(gs_ev_jump, takeoff_velocity_m_s, ",\"takeoff_velocity_m_s\":", 3),
    JF(gs_ev_jump, n_samples, ",\"n_samples\":", F_U32),
    JF(gs_ev_jump, n_outliers, ",\"n_outliers\":", F_U32),
    JF(gs_ev_jump, rms_px, ",\"rms_px\":", 3),
};

static void json_jump(gs_w *w, const gs_ev_jump *j)
{
    w_fields(w, j, k_jump_fields, sizeof k_jump_fields / sizeof k_jump_fields[0]);
    w_lit(w, j->accepted ? ",\"accepted\":true,\"reason\":" : ",\"accepted\":false,\"reason\":");
    w_jstr(w, j->accepted ? NULL : gs_reject_reason_name(j->reason));
    w_warnings(w, j->warnings);
    w_lit(w, "}\n");
}

/* ,"ci95_m":[lo,hi], or null: an interval with an unknown end is no interval */
static void w_ci95(gs_w *w, double mid, double lo, double hi)
{
    w_lit(w, ",\"ci95_m\":");
    if (isfinite(lo) && isfinite(hi) && isfinite(mid)) {
        w_raw(w, "[", 1);
        w_fixed(w, lo, 4);
        w_raw(w, ",", 1);
        w_fixed(w, hi, 4);
        w_raw(w, "]", 1);
    } else {
        w_lit(w, "null");
    }
}

static const json_field k_height_counts[] = {
    JF(gs_ev_height, n_jumps, ",\"n_jumps\":", F_U32),
    JF(gs_ev_height, n_rejected, ",\"n_rejected\":", F_U32),
};

static void json_height(gs_w *w, const gs_ev_height *h, bool summary)
{
    w_lit(w, summary ? "{\"event\":\"summary\",\"track\":" : "{\"event\":\"height\",\"track\":");
    w_u32(w, h->track);
    w_lit(w, ",\"height_m\":");
    w_fixed(w, h->height_m, 4);
    w_ci95(w, h->height_m, h->ci95_lo_m, h->ci95_hi_m);
    w_fields(w, h, k_height_counts, 2);
    w_lit(w, "}\n");
}

static const json_field k_session_head[] = {
    JF(gs_ev_session, track, "{\"event\":\"session\",\"track\":", F_U32),
    JF(gs_ev_session, session, ",\"session\":", F_U32),
};
static const json_field k_session_times[] = {
    JF(gs_ev_session, t_start_s, ",\"t_start_s\":", 4),
    JF(gs_ev_session, t_end_s, ",\"t_end_s\":", 4),
    JF(gs_ev_session, stature_m, ",\"stature_m\":", 4),
};
static const json_field k_session_tail[] = {
    JF(gs_ev_session, n_jumps, ",\"n_jumps\":", F_U32),
    JF(gs_ev_session, n_rejected, ",\"n_rejected\":", F_U32),
    JF(gs_ev_session, best_jump_m, ",\"best_jump_m\":", 4),
    JF(gs_ev_session, mean_jump_m, ",\"mean_jump_m\":", 4),
    JF(gs_ev_session, best_flight_s, ",\"best_flight_s\":", 4),
    JF(gs_ev_session, mean_flight_s, ",\"mean_flight_s\":", 4),
    JF(gs_ev_session, mean_takeoff_velocity_m_s, ",\"mean_takeoff_velocity_m_s\":", 3),
};

static void json_session(gs_w *w, const gs_ev_session *e)
{
    w_fields(w, e, k_session_head, 2);
    w_lit(w, e->ended ? ",\"state\":\"end\",\"reason\":" : ",\"state\":\"start\",\"reason\":");
    w_jstr(w, e->reason);
    w_fields(w, e, k_session_times, 3);
    w_ci95(w, e->stature_m, e->ci95_lo_m, e->ci95_hi_m);
    w_fields(w, e, k_session_tail, sizeof k_session_tail / sizeof k_session_tail[0]);
    w_lit(w, "}\n");
}

size_t gs_emit_json_str(const char *s, char *buf, size_t cap)
{
    gs_w w = {buf, cap, 0, buf != NULL};
    w_jstr(&w, s);
    return w_finish(&w);
}

size_t gs_emit_json(const gs_event *ev, char *buf, size_t cap)
{
    gs_w w = {buf, cap, 0, buf != NULL && ev != NULL};
    if (!w.ok) return w_finish(&w);
    switch (ev->type) {
    case GS_EV_START: {
        const gs_ev_start *s = &ev->u.start;
        w_lit(&w, "{\"event\":\"start\",\"version\":");
        w_jstr(&w, s->version ? s->version : GS_VERSION);
        w_lit(&w, ",\"config\":");
        w_jstr(&w, s->config);
        w_lit(&w, ",\"fps_source\":");
        w_sig(&w, s->fps_source, 6);
        w_lit(&w, ",\"fps_origin\":");
        w_jstr(&w, s->fps_origin);
        w_lit(&w, ",\"layout\":");
        w_jstr(&w, s->layout);
        w_lit(&w, "}\n");
        break;
    }
    case GS_EV_JUMP: json_jump(&w, &ev->u.jump); break;
    case GS_EV_HEIGHT: json_height(&w, &ev->u.height, false); break;
    case GS_EV_SUMMARY: json_height(&w, &ev->u.height, true); break;
    case GS_EV_SESSION: json_session(&w, &ev->u.session); break;
    case GS_EV_WARNING:
        w_lit(&w, "{\"event\":\"warning\",\"track\":");
        w_u32(&w, ev->u.warning.track);
        w_lit(&w, ",\"t_s\":");
        w_fixed(&w, ev->u.warning.t_s, 4);
        w_warnings(&w, ev->u.warning.warnings);
        w_lit(&w, "}\n");
        break;
#if GS_WITH_TRACE /* trace events (gs_features.h): without them, no form (returns 0) */
    case GS_EV_STATE: {
        const gs_ev_state *s = &ev->u.state;
        w_lit(&w, "{\"event\":\"state\",\"t_s\":");
        w_fixed(&w, s->t_s, 4);
        w_lit(&w, ",\"from\":");
        w_jstr(&w, s->from);
        w_lit(&w, ",\"to\":");
        w_jstr(&w, s->to);
        w_lit(&w, "}\n");
        break;
    }
    case GS_EV_SAMPLE: {
        const gs_ev_sample *s = &ev->u.sample;
        w_lit(&w, "{\"event\":\"sample\",\"t_s\":");
        w_fixed(&w, s->t_s, 4);
        w_lit(&w, ",\"x_px\":");
        w_fixed(&w, (double)s->x_px, 2);
        w_lit(&w, ",\"y_px\":");
        w_fixed(&w, (double)s->y_px, 2);
        w_lit(&w, ",\"w\":");
        w_fixed(&w, (double)s->w, 3);
        w_lit(&w, ",\"size_px\":");
        w_fixed(&w, (double)s->size_px, 2);
        w_lit(&w, ",\"upright\":");
        w_fixed(&w, (double)s->upright, 3);
        w_lit(&w, "}\n");
        break;
    }
    case GS_EV_FIT: {
        const gs_ev_fit *f = &ev->u.fit;
        w_lit(&w, "{\"event\":\"fit\",\"purpose\":");
        w_jstr(&w, f->purpose);
        w_lit(&w, ",\"t_first_s\":");
        w_fixed(&w, f->t_first_s, 4);
        w_lit(&w, ",\"t_last_s\":");
        w_fixed(&w, f->t_last_s, 4);
        w_lit(&w, ",\"n\":");
        w_u32(&w, f->n);
        w_lit(&w, ",\"a_px_s2\":");
        w_sig(&w, f->a_px_s2, 6);
        w_lit(&w, ",\"g_dir_deg\":");
        w_fixed(&w, f->g_dir_deg, 2);
        w_lit(&w, ",\"rms_px\":");
        w_fixed(&w, f->rms_px, 3);
        w_lit(&w, "}\n");
        break;
    }
#endif
    default: w.ok = false; break;
    }
    return w_finish(&w);
}

/* ------------------------------------------------------------------ NMEA */

/* A number in at most `width` characters: `decimals` decimals, fewer when the
 * value is large, empty when it is unknown or cannot fit (keeps <= 82 chars). */
static void n_num(gs_w *w, double v, int decimals, size_t width)
{
    w_raw(w, ",", 1);
    if (!isfinite(v)) return;
    for (int d = decimals; d >= 0; d--) {
        char t[40];
        size_t n = gs_num_fmt_fixed(t, sizeof t, v, d);
        if (n && n <= width) {
            w_raw(w, t, n);
            return;
        }
    }
}

/* fields of a sentence from a table, as json_field: offset, decimals and width of a double */
typedef struct {
    uint8_t off, decimals, width;
} nmea_field;
#define NF(type, field, dec, width) {(uint8_t)offsetof(type, field), dec, width}

static void n_fields(gs_w *w, const void *base, const nmea_field *t, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        double v;
        memcpy(&v, (const char *)base + t[i].off, sizeof v);
        n_num(w, v, t[i].decimals, t[i].width);
    }
}

static void n_u32(gs_w *w, uint32_t v)
{
    w_raw(w, ",", 1);
    w_u32(w, v);
}

/* NMEA text fields may not hold the delimiters $ * , ! \ ^ ~ or non-printables */
static void n_text(gs_w *w, const char *s, size_t max_len)
{
    w_raw(w, ",", 1);
    for (size_t i = 0; s && s[i] && i < max_len; i++) {
        char c = s[i];
        /* NMEA's reserved characters (not strchr: no libc search linked for this) */
        if (c < 0x20 || c > 0x7e || c == '$' || c == '*' || c == ',' || c == '!' || c == '\\' || c == '^' ||
            c == '~')
            c = '_';
        w_raw(w, &c, 1);
    }
}

size_t gs_emit_nmea(const gs_event *ev, char *buf, size_t cap)
{
    gs_w w = {buf, cap, 0, buf != NULL && ev != NULL};
    if (!w.ok) return w_finish(&w);
    switch (ev->type) {
    case GS_EV_JUMP: {
        /* widths: 10+5+8+9+6+5+6+10+1+1 = 61 = 82 - "$GSJMP" - 10 commas - "*HH\r\n" */
        static const nmea_field k_jmp[] = {
            NF(gs_ev_jump, t_takeoff_s, 3, 10), NF(gs_ev_jump, flight_time_s, 3, 5),
            NF(gs_ev_jump, a_px_s2, 1, 8),      NF(gs_ev_jump, q_m_per_px, 7, 9),
            NF(gs_ev_jump, height_m, 3, 6),     NF(gs_ev_jump, jump_height_m, 3, 5),
            NF(gs_ev_jump, takeoff_velocity_m_s, 2, 6)};
        const gs_ev_jump *j = &ev->u.jump;
        w_lit(&w, "$GSJMP");
        n_fields(&w, j, k_jmp, sizeof k_jmp / sizeof k_jmp[0]);
        n_u32(&w, j->n_samples);
        w_lit(&w, j->accepted ? ",A" : ",R");
        w_raw(&w, ",", 1);
        if ((uint32_t)j->reason <= 9u) {
            char c = (char)('0' + (int)j->reason);
            w_raw(&w, &c, 1);
        }
        break;
    }
    case GS_EV_HEIGHT:
    case GS_EV_SUMMARY: {
        const gs_ev_height *h = &ev->u.height;
        static const nmea_field k_hgt[] = {NF(gs_ev_height, height_m, 4, 12), NF(gs_ev_height, ci95_lo_m, 4, 12),
                                           NF(gs_ev_height, ci95_hi_m, 4, 12)};
        w_lit(&w, ev->type == GS_EV_HEIGHT ? "$GSHGT" : "$GSSUM");
        n_fields(&w, h, k_hgt, 3);
        n_u32(&w, h->n_jumps);
        if (ev->type == GS_EV_SUMMARY) n_u32(&w, h->n_rejected);
        break;
    }
    case GS_EV_SESSION: {
        /* widths: 5+1+1+10+10+6+3+5+5+5 = 51 <= 82 - "$GSSES" - 10 commas - "*HH\r\n" */
        const gs_ev_session *e = &ev->u.session;
        w_lit(&w, "$GSSES");
        n_num(&w, (double)e->session, 0, 5);
        w_lit(&w, e->ended ? ",E," : ",S,");
        if (e->reason) {
            char c = (char)(e->reason[0] >= 'a' && e->reason[0] <= 'z' ? e->reason[0] - 'a' + 'A' : '_');
            w_raw(&w, &c, 1);  /* A absence, N new_body, E end_of_stream */
        }
        static const nmea_field k_ses_t[] = {NF(gs_ev_session, t_start_s, 3, 10), NF(gs_ev_session, t_end_s, 3, 10),
                                             NF(gs_ev_session, stature_m, 3, 6)};
        static const nmea_field k_ses_j[] = {NF(gs_ev_session, best_jump_m, 3, 5), NF(gs_ev_session, mean_jump_m, 3, 5),
                                             NF(gs_ev_session, mean_flight_s, 3, 5)};
        n_fields(&w, e, k_ses_t, 3);
        n_num(&w, (double)e->n_jumps, 0, 3);
        n_fields(&w, e, k_ses_j, 3);
        break;
    }
    case GS_EV_WARNING: {
        static const char hexd[] = "0123456789ABCDEF";
        uint32_t b = ev->u.warning.warnings & 0xFFu;
        char hx[2] = {hexd[b >> 4], hexd[b & 15u]};
        w_lit(&w, "$GSWRN");
        n_num(&w, ev->u.warning.t_s, 3, 10);
        w_raw(&w, ",", 1);
        w_raw(&w, hx, 2);  /* the GS_WARN_* bits in hex */
        break;
    }
    case GS_EV_START:
        w_lit(&w, "$GSSTA");
        n_text(&w, ev->u.start.version ? ev->u.start.version : GS_VERSION, 20);
        n_num(&w, ev->u.start.fps_source, 3, 10);
        break;
    default: w.ok = false; break; /* trace events have no sentence */
    }
    if (w.ok) {
        static const char hex[] = "0123456789ABCDEF";
        unsigned char x = 0;
        for (size_t i = 1; i < w.len; i++) x ^= (unsigned char)w.buf[i];
        char tail[5] = {'*', hex[x >> 4], hex[x & 15u], '\r', '\n'};
        w_raw(&w, tail, sizeof tail);
        if (w.len > NMEA_MAX) w.ok = false; /* cannot happen with the widths above */
    }
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
