/* gs_config.c - "[section]" / "key = value" text parsed in place (no heap, no
 * copies), each key routed to its section's handler; the [core] handler.
 * Numbers are parsed and range-checked in double (once, at start-up) and stored as
 * their fields' types; g in gs_real (a device that bakes its profile links no double). */
#include "gravscale/gs_config.h"
#include "gravscale/gs_num.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "gs_dbits.h"

#define CFG_MAX_LINE 255u

/* ------------------------------------------------------------- utilities */

/* copy s[0..n) into dst[cap] always NUL-terminated (truncating) */
static void copy_text(char *dst, size_t cap, const char *s, size_t n)
{
    if (!dst || cap == 0) return;
    if (n >= cap) n = cap - 1u;
    if (n) memcpy(dst, s, n);
    dst[n] = '\0';
}

static void copy_cstr(char *dst, size_t cap, const char *s) { copy_text(dst, cap, s, s ? strlen(s) : 0u); }

/* append a C string to the NUL-terminated dst[cap] */
static void append(char *dst, size_t cap, const char *s)
{
    size_t n = strlen(dst);
    if (n < cap) copy_text(dst + n, cap - n, s, strlen(s));
}

static bool is_blank(char c) { return c == ' ' || c == '\t'; }

static bool key_char_ok(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
           c == '-';
}

static bool same(const char *a, size_t an, const char *b, size_t bn) { return an == bn && memcmp(a, b, an) == 0; }

static bool is_lit(const char *s, size_t n, const char *lit) { return same(s, n, lit, strlen(lit)); }

/* ------------------------------------------------------------ line lexer */

typedef enum { LN_EMPTY, LN_SECTION, LN_KEY, LN_ERROR } ln_kind;

typedef struct {
    ln_kind kind;
    const char *a; /* section name or key */
    size_t an;
    const char *b; /* value */
    size_t bn;
    const char *err; /* LN_ERROR: why */
} ln_tok;

static void trim(const char **s, size_t *n)
{
    while (*n && is_blank(**s)) {
        (*s)++;
        (*n)--;
    }
    while (*n && is_blank((*s)[*n - 1u])) (*n)--;
}

/* One line without its line ending into *t (kind, names, LN_ERROR's reason). */
static void lex_line(const char *s, size_t n, ln_tok *t)
{
    *t = (ln_tok){LN_EMPTY, NULL, 0, NULL, 0, NULL};
    trim(&s, &n);
    if (n == 0 || s[0] == '#' || s[0] == ';') return;
    t->kind = LN_ERROR;
    if (s[0] == '[') {
        size_t rb = 1;
        while (rb < n && s[rb] != ']') rb++;
        if (rb == n) {
            t->err = "section header without ']'";
            return;
        }
        /* after ']' only blanks or a comment */
        for (size_t i = rb + 1u; i < n && s[i] != '#' && s[i] != ';'; i++) {
            if (!is_blank(s[i])) {
                t->err = "text after section header";
                return;
            }
        }
        t->a = s + 1;
        t->an = rb - 1u;
        trim(&t->a, &t->an);
        if (t->an == 0) t->err = "empty section name";
        else t->kind = LN_SECTION;
        return;
    }
    size_t eq = 0;
    while (eq < n && s[eq] != '=') eq++;
    if (eq == n) {
        t->err = "expected 'key = value'";
        return;
    }
    t->a = s;
    t->an = eq;
    trim(&t->a, &t->an);
    if (t->an == 0) {
        t->err = "empty key";
        return;
    }
    for (size_t i = 0; i < t->an; i++) {
        if (!key_char_ok(t->a[i])) {
            t->err = "bad character in key";
            return;
        }
    }
    t->kind = LN_KEY;
    t->b = s + eq + 1u;
    t->bn = n - eq - 1u;
    /* an inline comment starts at # or ; preceded by a blank */
    for (size_t i = 1; i < t->bn; i++) {
        if ((t->b[i] == '#' || t->b[i] == ';') && is_blank(t->b[i - 1u])) {
            t->bn = i;
            break;
        }
    }
    trim(&t->b, &t->bn);
}

/* next line of text[pos..len): [*ls, *le) without CR/LF; returns the next pos */
static size_t next_line(const char *text, size_t len, size_t pos, size_t *ls, size_t *le)
{
    size_t e = pos;
    while (e < len && text[e] != '\n') e++;
    *ls = pos;
    *le = (e > pos && text[e - 1u] == '\r') ? e - 1u : e;
    return e < len ? e + 1u : e;
}

/* Was key already set in a section of this name before offset `upto`?
 * Rescanning keeps the parser free of per-key storage; config files are small. */
static bool seen_before(const char *text, size_t upto, const char *sec, size_t secn, const char *key, size_t keyn)
{
    const char *cur = NULL;
    size_t curn = 0;
    size_t pos = 0;
    while (pos < upto) {
        size_t ls, le;
        pos = next_line(text, upto, pos, &ls, &le);
        ln_tok t;
        lex_line(text + ls, le - ls, &t);
        if (t.kind == LN_SECTION) {
            cur = t.a;
            curn = t.an;
        } else if (t.kind == LN_KEY && cur && same(cur, curn, sec, secn) && same(t.a, t.an, key, keyn)) {
            return true;
        }
    }
    return false;
}

static gs_status fail(gs_cfg_error *err, gs_status st, uint32_t line, const char *sec, size_t secn,
                      const char *key, size_t keyn, const char *msg)
{
    err->line = line;
    copy_text(err->section, sizeof err->section, sec, secn); /* NULL only with length 0 */
    copy_text(err->key, sizeof err->key, key, keyn);
    if (msg) copy_cstr(err->msg, sizeof err->msg, msg);
    return st;
}

gs_status gs_cfg_parse(const char *text, size_t len, const gs_cfg_section *sections, size_t n_sections,
                       gs_cfg_error *err)
{
    gs_cfg_error dummy;
    if (!err) err = &dummy;
    memset(err, 0, sizeof *err);
    const gs_cfg_section *cur = NULL;
    const char *cur_name = NULL, *key = NULL; /* where an error is: section and key */
    size_t cur_n = 0, key_n = 0;
    gs_status st = GS_OK;
    const char *why = NULL; /* NULL: the handler's message */
    if (!text && len) {
        st = GS_EINVAL;
        why = "no text";
    }
    uint32_t line = 0;
    for (size_t pos = 0; pos < len && st == GS_OK;) {
        size_t ls, le, start = pos;
        pos = next_line(text, len, pos, &ls, &le);
        line++;
        key = NULL;
        key_n = 0;
        ln_tok t;
        lex_line(text + ls, le - ls, &t);
        st = GS_ESYNTAX;
        if (memchr(text + start, '\0', pos - start)) { /* the line with its CR LF */
            why = "NUL byte in text";
        } else if (le - ls > CFG_MAX_LINE) {
            why = "line longer than 255 characters";
        } else if (t.kind == LN_ERROR) {
            why = t.err;
        } else if (t.kind == LN_SECTION) {
            cur = NULL;
            for (size_t i = 0; sections && i < n_sections; i++) {
                if (sections[i].name && is_lit(t.a, t.an, sections[i].name)) {
                    cur = &sections[i];
                    break;
                }
            }
            cur_name = t.a;
            cur_n = t.an;
            st = cur ? GS_OK : GS_ENOKEY;
            why = "unknown section";
        } else if (t.kind == LN_KEY) {
            key = t.a;
            key_n = t.an;
            if (!cur) {
                why = "key before any [section]";
            } else if (seen_before(text, ls, cur_name, cur_n, t.a, t.an)) {
                st = GS_EINVAL;
                why = "duplicate key";
            } else {
                err->msg[0] = '\0';
                st = cur->fn ? cur->fn(cur->ctx, t.a, t.an, t.b, t.bn, err->msg, sizeof err->msg) : GS_ENOKEY;
                why = err->msg[0] ? NULL
                      : st == GS_ENOKEY ? "unknown key"
                      : st == GS_ERANGE ? "value out of range"
                                        : "bad value";
            }
        } else {
            st = GS_OK;
        }
    }
    if (st != GS_OK) return fail(err, st, line, cur_name, cur_n, key, key_n, why);
    err->msg[0] = '\0'; /* a handler may have left text on success */
    return GS_OK;
}

/* ------------------------------------------------------------------ [core] */

typedef enum { T_REAL, T_REAL_AUTO, T_FLT, T_U32, T_U32_POW2 } num_type;

/* A numeric key: its range in thousandths (milli / 1000.0, one correctly rounded
 * division, is the double nearest the decimal bound, as the literal would be:
 * 8 bytes a key instead of two doubles) and where it is stored. */
typedef struct {
    const char *key;
    int32_t lo_milli, hi_milli;
    uint8_t type; /* num_type; from T_U32 on an integer */
    uint8_t off;  /* offsetof in gs_core_config */
} num_key;

#define MILLI(x) ((int32_t)((x) * 1000 + ((x) < 0 ? -0.5 : 0.5)))
#define NK(name, type, lo, hi) {#name, MILLI(lo), MILLI(hi), type, offsetof(gs_core_config, name)}
_Static_assert(sizeof(gs_core_config) <= 256, "num_key.off is 8 bits");

/* every numeric [core] key with its range (docs/config.md lists the same) */
static const num_key k_num_keys[] = {
    NK(g_m_s2, T_REAL_AUTO, 9.7, 9.9),
    NK(latitude_deg, T_REAL_AUTO, -90, 90),
    NK(altitude_m, T_REAL, -500, 9000),
    NK(min_conf, T_FLT, 0, 1),
    NK(ring_capacity, T_U32_POW2, 64, 65536),
    NK(min_flight_s, T_FLT, 0.05, 2),
    NK(max_flight_s, T_FLT, 0.1, 5),
    NK(min_samples, T_U32, 4, 1000),
    NK(max_rms_rel, T_FLT, 0.001, 1),
    NK(max_a_se_rel, T_FLT, 0.001, 1),
    NK(size_min_m, T_FLT, 0, 10),
    NK(size_max_m, T_FLT, 0, 10),
    NK(max_gap_s, T_FLT, 0.01, 2),
    NK(landing_latency_s, T_FLT, 0.02, 1),
    NK(session_absence_s, T_FLT, 0.5, 600),
    NK(session_new_body_rel, T_FLT, 0.03, 0.5),
};

void gs_core_config_default(gs_core_config *c)
{
    static const gs_core_config k_default = {
        .g_m_s2 = NAN,
        .latitude_deg = NAN,
        .altitude_m = GS_R(0.0),
        .mass_table = GS_MASS_DELEVA,
        .stature = GS_STATURE_ANTHRO,
        .min_conf = 0.1f, /* blurred fast limbs come with low confidence but usable positions */
        .fit_method = GS_FIT_IRLS,
        .ring_capacity = 512u,
        .min_flight_s = 0.12f,
        .max_flight_s = 1.5f,
        .min_samples = 6u,
        .max_rms_rel = 0.03f,
        .max_a_se_rel = 0.15f,
        .size_min_m = 0.3f,
        .size_max_m = 2.6f,
        .max_gap_s = 0.2f,
        .landing_latency_s = 0.2f,
        .session_absence_s = 2.5f,
        .session_new_body_rel = 0.12f,
        .format = GS_WITH_JSON ? GS_FMT_JSON : GS_FMT_NMEA, /* the one built in (gs_features.h) */
    };
    if (c) *c = k_default;
}

static double bound(int32_t milli) { return (double)milli / 1000.0; }

/* a bound as gs_num_fmt_sig(.., 6) writes it: at most 3 decimals, trailing zeros cut */
static void append_bound(char *msg, size_t cap, int32_t milli)
{
    char t[32];
    size_t n = gs_num_fmt_fixed(t, sizeof t, bound(milli), 3);
    while (t[n - 1u] == '0') n--;
    if (t[n - 1u] == '.') n--;
    t[n] = '\0';
    append(msg, cap, t);
}

static void range_msg(char *msg, size_t cap, const num_key *k)
{
    copy_cstr(msg, cap, k->type == T_U32_POW2 ? "must be a power of two in " : "must be within ");
    append_bound(msg, cap, k->lo_milli);
    append(msg, cap, "..");
    append_bound(msg, cap, k->hi_milli);
}

static bool is_pow2(uint32_t v) { return v && !(v & (v - 1u)); }

/* an integer key's value within its (whole-number) range */
static bool int_ok(const num_key *k, int64_t x)
{
    return x >= k->lo_milli / 1000 && x <= k->hi_milli / 1000 && (k->type != T_U32_POW2 || is_pow2((uint32_t)x));
}

/* lo <= x <= hi; a float field holds the decimal bounds only as floats */
static bool dbl_ok(const num_key *k, double x, bool as_float)
{
    double lo = bound(k->lo_milli), hi = bound(k->hi_milli);
    if (as_float) {
        lo = (double)(float)lo;
        hi = (double)(float)hi;
    }
    return gs_dge(x, lo) && gs_dle(x, hi);
}

static gs_status set_num(gs_core_config *c, const num_key *k, const char *v, size_t n, char *msg, size_t cap)
{
    unsigned char *field = (unsigned char *)c + k->off;
    if (k->type >= T_U32) {
        long x;
        if (!gs_num_parse_int(v, n, &x)) {
            copy_cstr(msg, cap, "not an integer");
            return GS_EINVAL;
        }
        if (!int_ok(k, x)) {
            range_msg(msg, cap, k);
            return GS_ERANGE;
        }
        uint32_t u = (uint32_t)x;
        memcpy(field, &u, sizeof u);
        return GS_OK;
    }
    double x;
    if (k->type == T_REAL_AUTO && is_lit(v, n, "auto")) {
        x = NAN; /* explicit "unset" */
    } else {
        if (!gs_num_parse(v, n, &x)) {
            copy_cstr(msg, cap, k->type == T_REAL_AUTO ? "not a number (or auto)" : "not a number");
            return GS_EINVAL;
        }
        if (!dbl_ok(k, x, false)) {
            range_msg(msg, cap, k);
            return GS_ERANGE;
        }
    }
    if (k->type == T_FLT) {
        float f = (float)x;
        memcpy(field, &f, sizeof f);
    } else {
        gs_real r = (gs_real)x;
        memcpy(field, &r, sizeof r);
    }
    return GS_OK;
}

/* the [core] keys that take a name, in the order of set_name and name_value */
static const struct {
    const char *key, *expected;
    uint8_t max; /* the largest valid enum value */
} k_name_keys[] = {
    {"mass_table", "expected deleva, clauser or dempster", GS_MASS_DEMPSTER},
    {"stature", "expected anthro or nose_ankle_1.17", GS_STATURE_NOSE_ANKLE_117},
    {"fit", "expected irls, ransac or plain", GS_FIT_PLAIN},
    {"format", "expected json or nmea", GS_FMT_NMEA},
};

static bool set_name(gs_core_config *c, size_t i, const char *v, size_t n)
{
    switch (i) {
    case 0: return gs_mass_table_from_name(v, n, &c->mass_table);
    case 1: return gs_stature_method_from_name(v, n, &c->stature);
    case 2: return gs_fit_method_from_name(v, n, &c->fit_method);
    default: return gs_format_from_name(v, n, &c->format);
    }
}

/* The name key i's stored value and the check's message when it is out of range.
 * Literals here, not in k_name_keys: a build without gs_core_config_check drops them. */
static unsigned name_value(const gs_core_config *c, size_t i, const char **unknown)
{
    switch (i) {
    case 0: *unknown = "unknown mass table"; return (unsigned)c->mass_table;
    case 1: *unknown = "unknown stature method"; return (unsigned)c->stature;
    case 2: *unknown = "unknown fit method"; return (unsigned)c->fit_method;
    default: *unknown = "unknown format"; return (unsigned)c->format;
    }
}

gs_status gs_core_config_set(void *ctx, const char *key, size_t key_len, const char *value, size_t value_len,
                             char *msg, size_t cap)
{
    gs_core_config *c = (gs_core_config *)ctx;
    if (!c || !key || (!value && value_len)) return GS_EINVAL;
    if (!value) value = "";
    trim(&value, &value_len);
    for (size_t i = 0; i < sizeof k_num_keys / sizeof k_num_keys[0]; i++)
        if (is_lit(key, key_len, k_num_keys[i].key)) return set_num(c, &k_num_keys[i], value, value_len, msg, cap);
    for (size_t i = 0; i < sizeof k_name_keys / sizeof k_name_keys[0]; i++) {
        if (!is_lit(key, key_len, k_name_keys[i].key)) continue;
        if (set_name(c, i, value, value_len)) return GS_OK;
        copy_cstr(msg, cap, k_name_keys[i].expected);
        return GS_EINVAL;
    }
    copy_cstr(msg, cap, "unknown key");
    return GS_ENOKEY;
}

/* the name of the numeric key stored at this offset (the table's literal: the
 * check's own copy would keep its strings in a build without the check) */
static const char *key_at(size_t off)
{
    size_t i = 0;
    while (i + 1u < sizeof k_num_keys / sizeof k_num_keys[0] && k_num_keys[i].off != off) i++;
    return k_num_keys[i].key;
}

static gs_status check_fail(gs_cfg_error *err, gs_status st, const char *key, const char *msg)
{
    if (err) {
        memset(err, 0, sizeof *err);
        copy_cstr(err->section, sizeof err->section, "core");
        copy_cstr(err->key, sizeof err->key, key);
        copy_cstr(err->msg, sizeof err->msg, msg);
    }
    return st;
}

gs_status gs_core_config_check(const gs_core_config *c, gs_cfg_error *err)
{
    if (err) memset(err, 0, sizeof *err);
    if (!c) return check_fail(err, GS_EINVAL, "", "no config");
    /* a config filled in by code gets the same range checks as a parsed one */
    for (size_t i = 0; i < sizeof k_num_keys / sizeof k_num_keys[0]; i++) {
        const num_key *k = &k_num_keys[i];
        const unsigned char *field = (const unsigned char *)c + k->off;
        bool ok;
        if (k->type >= T_U32) {
            uint32_t u;
            memcpy(&u, field, sizeof u);
            ok = int_ok(k, u);
        } else {
            double x;
            bool as_float = k->type == T_FLT || GS_REAL_IS_FLOAT;  /* the field holds a float */
            if (k->type == T_FLT) {
                float f;
                memcpy(&f, field, sizeof f);
                x = (double)f;
            } else {
                gs_real r;
                memcpy(&r, field, sizeof r);
                x = (double)r;
            }
            ok = (k->type == T_REAL_AUTO && gs_disnan(x)) || dbl_ok(k, x, as_float);
        }
        if (!ok) {
            char msg[64];
            range_msg(msg, sizeof msg, k);
            return check_fail(err, GS_ERANGE, k->key, msg);
        }
    }
    for (size_t i = 0; i < sizeof k_name_keys / sizeof k_name_keys[0]; i++) {
        const char *unknown;
        if (name_value(c, i, &unknown) > k_name_keys[i].max) return check_fail(err, GS_EINVAL, k_name_keys[i].key, unknown);
    }
    if (!(c->min_flight_s < c->max_flight_s))
        return check_fail(err, GS_ERANGE, key_at(offsetof(gs_core_config, max_flight_s)),
                          "max_flight_s must exceed min_flight_s");
    if (!(c->size_min_m < c->size_max_m))
        return check_fail(err, GS_ERANGE, key_at(offsetof(gs_core_config, size_max_m)),
                          "size_max_m must exceed size_min_m");
    return GS_OK;
}

gs_real gs_gravity_m_s2(gs_real latitude_deg, gs_real altitude_m)
{
    /* WGS-84 normal gravity on the ellipsoid (Somigliana), then the free-air gradient */
    const gs_real deg = GS_R(3.14159265358979323846 / 180.0);
    /* float where gs_real is float: g to 1e-6 is 10x finer than any site needs */
    gs_real s = GS_REAL_IS_FLOAT ? (gs_real)gs_sinf((float)(latitude_deg * deg)) : (gs_real)sin((double)(latitude_deg * deg));
    gs_real s2 = s * s;
    gs_real g0 = GS_R(9.7803253359) * (GS_R(1.0) + GS_R(0.00193185265241) * s2) /
                 GS_SQRT(GS_R(1.0) - GS_R(0.00669437999013) * s2);
    return g0 - GS_R(3.086e-6) * altitude_m;
}

gs_real gs_core_config_g(const gs_core_config *c)
{
    if (!c) return GS_R(9.81);
    if (isfinite(c->g_m_s2)) return c->g_m_s2;
    if (isfinite(c->latitude_deg))
        return gs_gravity_m_s2(c->latitude_deg, isfinite(c->altitude_m) ? c->altitude_m : GS_R(0.0));
    return GS_R(9.81);
}
