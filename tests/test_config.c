/* test_config.c - the key = value parser, the [core] handler, normal gravity,
 * and the shipped firmware_cfg files read from disk. */
#include "gravscale/gs_config.h"
#include "unity.h"
#include "gs_profile.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef GS_SOURCE_DIR
#define GS_SOURCE_DIR "."
#endif

void setUp(void) {}
void tearDown(void) {}

/* a second section with its own handler, to test routing */
typedef struct {
    int n_calls;
    char last_key[40];
    char last_value[64];
} sink_ctx;

static gs_status sink_set(void *ctx, const char *key, size_t key_len, const char *value, size_t value_len,
                          char *msg, size_t cap)
{
    sink_ctx *s = ctx;
    if (!(key_len == 4 && memcmp(key, "path", 4) == 0)) return GS_ENOKEY; /* no msg: parser default */
    if (value_len == 0) {
        snprintf(msg, cap, "empty path");
        return GS_EINVAL;
    }
    s->n_calls++;
    snprintf(s->last_key, sizeof s->last_key, "%.*s", (int)key_len, key);
    snprintf(s->last_value, sizeof s->last_value, "%.*s", (int)value_len, value);
    return GS_OK;
}

static gs_core_config g_core;
static sink_ctx g_sink;
static gs_cfg_section g_sections[2];

static gs_status parse(const char *text, size_t len, gs_cfg_error *err)
{
    gs_core_config_default(&g_core);
    memset(&g_sink, 0, sizeof g_sink);
    g_sections[0] = (gs_cfg_section){"core", gs_core_config_set, &g_core};
    g_sections[1] = (gs_cfg_section){"sink", sink_set, &g_sink};
    return gs_cfg_parse(text, len, g_sections, 2, err);
}

static gs_status parse_str(const char *text, gs_cfg_error *err) { return parse(text, strlen(text), err); }

/* ------------------------------------------------------------- bad inputs */
typedef struct {
    const char *text;
    gs_status st;
    uint32_t line;
    const char *section;
    const char *key;
} bad_case;

static const bad_case k_bad[] = {
    {"[nosuch]\n", GS_ENOKEY, 1, "nosuch", ""},
    {"[core]\nnosuch = 1\n", GS_ENOKEY, 2, "core", "nosuch"},
    {"[core]\nmin_conf = 1.5x\n", GS_EINVAL, 2, "core", "min_conf"},
    {"[core]\nmin_conf =\n", GS_EINVAL, 2, "core", "min_conf"},
    {"[core]\nmin_conf = nan\n", GS_EINVAL, 2, "core", "min_conf"},
    {"[core]\nmin_conf = inf\n", GS_EINVAL, 2, "core", "min_conf"},
    {"[core]\nmin_conf = 1.0001\n", GS_ERANGE, 2, "core", "min_conf"},
    {"[core]\nmin_conf = -0.1\n", GS_ERANGE, 2, "core", "min_conf"},
    {"[core]\nmin_conf = 0.3\nmin_conf = 0.4\n", GS_EINVAL, 3, "core", "min_conf"},
    {"[core]\nmin_conf = 0.3\n[sink]\npath = a\n[core]\nmin_conf = 0.4\n", GS_EINVAL, 6, "core", "min_conf"},
    {"[core]\nmin_conf 0.3\n", GS_ESYNTAX, 2, "core", ""},
    {"min_conf = 0.3\n[core]\n", GS_ESYNTAX, 1, "", "min_conf"},
    {"# comment\n\n[core\n", GS_ESYNTAX, 3, "", ""},
    {"[core] x\n", GS_ESYNTAX, 1, "", ""},
    {"[]\n", GS_ESYNTAX, 1, "", ""},
    {"[core]\n = 3\n", GS_ESYNTAX, 2, "core", ""},
    {"[core]\nmin conf = 3\n", GS_ESYNTAX, 2, "core", ""},
    {"[core]\ng_m_s2 = 9.6\n", GS_ERANGE, 2, "core", "g_m_s2"},
    {"[core]\ng_m_s2 = 9.91\n", GS_ERANGE, 2, "core", "g_m_s2"},
    {"[core]\ng_m_s2 = Auto\n", GS_EINVAL, 2, "core", "g_m_s2"},
    {"[core]\nlatitude_deg = 90.5\n", GS_ERANGE, 2, "core", "latitude_deg"},
    {"[core]\naltitude_m = -501\n", GS_ERANGE, 2, "core", "altitude_m"},
    {"[core]\naltitude_m = auto\n", GS_EINVAL, 2, "core", "altitude_m"},
    {"[core]\nring_capacity = 500\n", GS_ERANGE, 2, "core", "ring_capacity"},
    {"[core]\nring_capacity = 32\n", GS_ERANGE, 2, "core", "ring_capacity"},
    {"[core]\nring_capacity = 131072\n", GS_ERANGE, 2, "core", "ring_capacity"},
    {"[core]\nring_capacity = 512.0\n", GS_EINVAL, 2, "core", "ring_capacity"},
    {"[core]\nmin_samples = 3\n", GS_ERANGE, 2, "core", "min_samples"},
    {"[core]\nmin_samples = 1001\n", GS_ERANGE, 2, "core", "min_samples"},
    {"[core]\nmin_samples = -99999999999999999999\n", GS_EINVAL, 2, "core", "min_samples"},
    {"[core]\nmin_flight_s = 0.04\n", GS_ERANGE, 2, "core", "min_flight_s"},
    {"[core]\nmax_flight_s = 5.01\n", GS_ERANGE, 2, "core", "max_flight_s"},
    {"[core]\nmax_rms_rel = 0\n", GS_ERANGE, 2, "core", "max_rms_rel"},
    {"[core]\nmax_a_se_rel = 2\n", GS_ERANGE, 2, "core", "max_a_se_rel"},
    {"[core]\nsize_max_m = 10.5\n", GS_ERANGE, 2, "core", "size_max_m"},
    {"[core]\nmax_gap_s = 0.001\n", GS_ERANGE, 2, "core", "max_gap_s"},
    {"[core]\nlanding_latency_s = 1e9\n", GS_ERANGE, 2, "core", "landing_latency_s"},
    {"[core]\nmass_table = zatsiorsky\n", GS_EINVAL, 2, "core", "mass_table"},
    {"[core]\nstature = nose_ankle\n", GS_EINVAL, 2, "core", "stature"},
    {"[core]\nfit = lsq\n", GS_EINVAL, 2, "core", "fit"},
    {"[core]\nformat = JSON\n", GS_EINVAL, 2, "core", "format"},
    {"[core]\nmin_conf = 0.3 0.4\n", GS_EINVAL, 2, "core", "min_conf"},
    {"[core]\nmin_conf = 0.3#x\n", GS_EINVAL, 2, "core", "min_conf"},
    {"[sink]\npath =\n", GS_EINVAL, 2, "sink", "path"},
    {"[sink]\nport = 3\n", GS_ENOKEY, 2, "sink", "port"},
};

void test_bad_inputs_table(void)
{
    for (size_t i = 0; i < sizeof k_bad / sizeof k_bad[0]; i++) {
        const bad_case *c = &k_bad[i];
        gs_cfg_error err;
        memset(&err, 0x7F, sizeof err);
        gs_status st = parse_str(c->text, &err);
        char m[200];
        snprintf(m, sizeof m, "case %zu: %s", i, c->text);
        TEST_ASSERT_EQUAL_INT_MESSAGE(c->st, st, m);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(c->line, err.line, m);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(c->section, err.section, m);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(c->key, err.key, m);
        TEST_ASSERT_TRUE_MESSAGE(err.msg[0] != '\0' && strlen(err.msg) < sizeof err.msg, m);
    }
    /* a handler's own message reaches the caller; the parser's default otherwise */
    gs_cfg_error err;
    parse_str("[core]\nmin_flight_s = 9\n", &err);
    TEST_ASSERT_EQUAL_STRING("must be within 0.05..2", err.msg);
    parse_str("[sink]\nport = 3\n", &err);
    TEST_ASSERT_EQUAL_STRING("unknown key", err.msg);
    parse_str("[core]\nring_capacity = 100\n", &err);
    TEST_ASSERT_EQUAL_STRING("must be a power of two in 64..65536", err.msg);
}

/* the first error stops the parse: later lines are not applied */
void test_error_stops_parse(void)
{
    gs_cfg_error err;
    TEST_ASSERT_EQUAL_INT(GS_ERANGE, parse_str("[core]\nmin_conf = 0.5\nmin_samples = 2\nmax_gap_s = 0.5\n", &err));
    TEST_ASSERT_EQUAL_FLOAT(0.5f, g_core.min_conf);
    TEST_ASSERT_EQUAL_FLOAT(0.2f, g_core.max_gap_s);
    TEST_ASSERT_EQUAL_UINT32(6, g_core.min_samples); /* the bad value left the default */
}

void test_nul_and_long_lines(void)
{
    gs_cfg_error err;
    static const char nul[] = "[core]\nmin_conf = 0.3\nfit = ir\0ls\n";
    TEST_ASSERT_EQUAL_INT(GS_ESYNTAX, parse(nul, sizeof nul - 1, &err));
    TEST_ASSERT_EQUAL_UINT32(3, err.line);
    TEST_ASSERT_EQUAL_STRING("core", err.section);

    char text[600];
    /* exactly 255 characters is allowed (a comment), 256 is not */
    for (int len = 255; len <= 256; len++) {
        size_t n = (size_t)snprintf(text, sizeof text, "[core]\n");
        text[n++] = '#';
        for (int i = 1; i < len; i++) text[n++] = 'x';
        n += (size_t)snprintf(text + n, sizeof text - n, "\r\nmin_conf = 0.5\n");
        gs_status st = parse(text, n, &err);
        if (len == 255) {
            TEST_ASSERT_EQUAL_INT(GS_OK, st);
            TEST_ASSERT_EQUAL_FLOAT(0.5f, g_core.min_conf);
        } else {
            TEST_ASSERT_EQUAL_INT(GS_ESYNTAX, st);
            TEST_ASSERT_EQUAL_UINT32(2, err.line);
        }
    }
    /* an over-long key is reported truncated, never overflowing err.key */
    size_t n = (size_t)snprintf(text, sizeof text, "[core]\n");
    for (int i = 0; i < 100; i++) text[n++] = 'k';
    n += (size_t)snprintf(text + n, sizeof text - n, " = 1\n");
    TEST_ASSERT_EQUAL_INT(GS_ENOKEY, parse(text, n, &err));
    TEST_ASSERT_EQUAL(sizeof err.key - 1, strlen(err.key));
}

/* ------------------------------------------------------------ good inputs */
void test_good_syntax_variants(void)
{
    gs_cfg_error err;
    static const char *const same_meaning[] = {
        "[core]\nmin_conf = 0.5\nfit = ransac\n",
        "[core]\r\nmin_conf = 0.5\r\nfit = ransac\r\n",               /* CRLF */
        "  [ core ]   # header comment\n\tmin_conf=0.5   \nfit\t=\transac\t\n", /* blanks everywhere */
        "# leading comment\n; another\n\n[core]\nmin_conf = 0.5 # inline\nfit = ransac ; inline\n",
        "[core]\nmin_conf = 0.5\nfit = ransac",                        /* no final newline */
        "[core]\nmin_conf = 0.5\nfit = ransac   ",                     /* trailing spaces, no newline */
        "[sink]\npath = x\n[core]\nmin_conf = 0.5\n[sink]\n[core]\nfit = ransac\n",
    };
    for (size_t i = 0; i < sizeof same_meaning / sizeof same_meaning[0]; i++) {
        TEST_ASSERT_EQUAL_INT_MESSAGE(GS_OK, parse_str(same_meaning[i], &err), same_meaning[i]);
        TEST_ASSERT_EQUAL_FLOAT(0.5f, g_core.min_conf);
        TEST_ASSERT_EQUAL_INT(GS_FIT_RANSAC, g_core.fit_method);
        TEST_ASSERT_EQUAL_UINT32(0, err.line);
    }
    /* empty text and only comments: defaults untouched */
    TEST_ASSERT_EQUAL_INT(GS_OK, parse("", 0, &err));
    TEST_ASSERT_EQUAL_INT(GS_OK, parse(NULL, 0, &err));
    TEST_ASSERT_EQUAL_INT(GS_OK, parse_str("\n\n# x\n   \n\r\n", &err));
    TEST_ASSERT_EQUAL_FLOAT(0.1f, g_core.min_conf);
    /* routing to the other section's handler, value with '#' not after a blank */
    TEST_ASSERT_EQUAL_INT(GS_OK, parse_str("[sink]\npath = /tmp/a#b.jsonl  # out\n", &err));
    TEST_ASSERT_EQUAL_INT(1, g_sink.n_calls);
    TEST_ASSERT_EQUAL_STRING("/tmp/a#b.jsonl", g_sink.last_value);
    /* err may be NULL */
    TEST_ASSERT_EQUAL_INT(GS_ENOKEY, parse_str("[x]\n", NULL));
}

void test_every_core_key(void)
{
    gs_cfg_error err;
    static const char text[] = "[core]\n"
                               "g_m_s2 = 9.80665\n"
                               "latitude_deg = -33.9\n"
                               "altitude_m = 1500\n"
                               "mass_table = clauser\n"
                               "stature = nose_ankle_1.17\n"
                               "min_conf = 1\n"
                               "fit = plain\n"
                               "ring_capacity = 65536\n"
                               "min_flight_s = 0.05\n"
                               "max_flight_s = 5\n"
                               "min_samples = 1000\n"
                               "max_rms_rel = 0.001\n"
                               "max_a_se_rel = 1\n"
                               "size_min_m = 0\n"
                               "size_max_m = 10\n"
                               "max_gap_s = 2\n"
                               "landing_latency_s = 0.02\n"
                               "format = nmea\n";
    TEST_ASSERT_EQUAL_INT(GS_OK, parse_str(text, &err));
    TEST_ASSERT_EQUAL_DOUBLE(9.80665, g_core.g_m_s2);
    TEST_ASSERT_EQUAL_DOUBLE(-33.9, g_core.latitude_deg);
    TEST_ASSERT_EQUAL_DOUBLE(1500.0, g_core.altitude_m);
    TEST_ASSERT_EQUAL_INT(GS_MASS_CLAUSER, g_core.mass_table);
    TEST_ASSERT_EQUAL_INT(GS_STATURE_NOSE_ANKLE_117, g_core.stature);
    TEST_ASSERT_EQUAL_FLOAT(1.0f, g_core.min_conf);
    TEST_ASSERT_EQUAL_INT(GS_FIT_PLAIN, g_core.fit_method);
    TEST_ASSERT_EQUAL_UINT32(65536, g_core.ring_capacity);
    TEST_ASSERT_EQUAL_FLOAT(0.05f, g_core.min_flight_s);
    TEST_ASSERT_EQUAL_FLOAT(5.0f, g_core.max_flight_s);
    TEST_ASSERT_EQUAL_UINT32(1000, g_core.min_samples);
    TEST_ASSERT_EQUAL_FLOAT(0.001f, g_core.max_rms_rel);
    TEST_ASSERT_EQUAL_FLOAT(1.0f, g_core.max_a_se_rel);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, g_core.size_min_m);
    TEST_ASSERT_EQUAL_FLOAT(10.0f, g_core.size_max_m);
    TEST_ASSERT_EQUAL_FLOAT(2.0f, g_core.max_gap_s);
    TEST_ASSERT_EQUAL_FLOAT(0.02f, g_core.landing_latency_s);
    TEST_ASSERT_EQUAL_INT(GS_FMT_NMEA, g_core.format);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_core_config_check(&g_core, &err));
    /* g_m_s2 set wins over latitude */
    TEST_ASSERT_EQUAL_DOUBLE(9.80665, gs_core_config_g(&g_core));
    /* "auto" resets to unset */
    TEST_ASSERT_EQUAL_INT(GS_OK, parse_str("[core]\ng_m_s2 = auto\nlatitude_deg = auto\n", &err));
    TEST_ASSERT_TRUE(isnan(g_core.g_m_s2) && isnan(g_core.latitude_deg));
}

void test_defaults_and_check(void)
{
    gs_core_config c;
    gs_cfg_error err;
    gs_core_config_default(&c);
    TEST_ASSERT_TRUE(isnan(c.g_m_s2));
    TEST_ASSERT_TRUE(isnan(c.latitude_deg));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, c.altitude_m);
    TEST_ASSERT_EQUAL_INT(GS_MASS_DELEVA, c.mass_table);
    TEST_ASSERT_EQUAL_INT(GS_STATURE_ANTHRO, c.stature);
    TEST_ASSERT_EQUAL_FLOAT(0.1f, c.min_conf);
    TEST_ASSERT_EQUAL_INT(GS_FIT_IRLS, c.fit_method);
    TEST_ASSERT_EQUAL_UINT32(512, c.ring_capacity);
    TEST_ASSERT_EQUAL_FLOAT(0.12f, c.min_flight_s);
    TEST_ASSERT_EQUAL_FLOAT(1.5f, c.max_flight_s);
    TEST_ASSERT_EQUAL_UINT32(6, c.min_samples);
    TEST_ASSERT_EQUAL_FLOAT(0.03f, c.max_rms_rel);
    TEST_ASSERT_EQUAL_FLOAT(0.15f, c.max_a_se_rel);
    TEST_ASSERT_EQUAL_FLOAT(0.3f, c.size_min_m);
    TEST_ASSERT_EQUAL_FLOAT(2.6f, c.size_max_m);
    TEST_ASSERT_EQUAL_FLOAT(0.2f, c.max_gap_s);
    TEST_ASSERT_EQUAL_FLOAT(0.2f, c.landing_latency_s);
    TEST_ASSERT_EQUAL_INT(GS_FMT_JSON, c.format);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_core_config_check(&c, &err));
    TEST_ASSERT_EQUAL_DOUBLE(9.81, gs_core_config_g(&c));

    /* cross-field and code-filled values */
    static const struct {
        const char *key;
        gs_status st;
    } want[] = {{"max_flight_s", GS_ERANGE}, {"size_max_m", GS_ERANGE}, {"ring_capacity", GS_ERANGE},
                {"min_conf", GS_ERANGE},     {"fit", GS_EINVAL},        {"g_m_s2", GS_ERANGE}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        gs_core_config_default(&c);
        switch (i) {
        case 0: c.min_flight_s = 0.5f; c.max_flight_s = 0.4f; break;
        case 1: c.size_min_m = 2.0f; c.size_max_m = 1.0f; break;
        case 2: c.ring_capacity = 1000; break;
        case 3: c.min_conf = NAN; break;
        case 4: c.fit_method = (gs_fit_method)9; break;
        default: c.g_m_s2 = 9.0; break;
        }
        TEST_ASSERT_EQUAL_INT(want[i].st, gs_core_config_check(&c, &err));
        TEST_ASSERT_EQUAL_STRING(want[i].key, err.key);
        TEST_ASSERT_EQUAL_STRING("core", err.section);
        TEST_ASSERT_EQUAL_UINT32(0, err.line);
    }
}

void test_gravity(void)
{
    /* WGS-84 normal gravity: equator, pole, 45 degrees */
    TEST_ASSERT_DOUBLE_WITHIN(5e-5, 9.7803, gs_gravity_m_s2(0, 0));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 9.7803253359, gs_gravity_m_s2(0, 0));
    TEST_ASSERT_DOUBLE_WITHIN(5e-5, 9.8322, gs_gravity_m_s2(90, 0));
    TEST_ASSERT_DOUBLE_WITHIN(5e-5, 9.8322, gs_gravity_m_s2(-90, 0));
    TEST_ASSERT_DOUBLE_WITHIN(5e-5, 9.8062, gs_gravity_m_s2(45, 0));
    /* free-air: 1000 m up loses 3.086 mGal/m * 1000 m = 0.003086 m/s^2 */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.003086, gs_gravity_m_s2(45, 0) - gs_gravity_m_s2(45, 1000));
    /* monotonic in |latitude| */
    for (int lat = 0; lat < 90; lat++) TEST_ASSERT_TRUE(gs_gravity_m_s2(lat + 1, 0) > gs_gravity_m_s2(lat, 0));

    gs_core_config c;
    gs_core_config_default(&c);
    c.latitude_deg = 45.0;
    c.altitude_m = 1000.0;
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, gs_gravity_m_s2(45, 1000), gs_core_config_g(&c));
    c.g_m_s2 = 9.79;
    TEST_ASSERT_EQUAL_DOUBLE(9.79, gs_core_config_g(&c));
}

/* ------------------------------------------------------------- files on disk */
static size_t read_file(const char *rel, char *buf, size_t cap)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", GS_SOURCE_DIR, rel);
    FILE *f = fopen(path, "rb");
    if (!f) f = fopen(rel, "rb"); /* running from the repository root */
    TEST_ASSERT_NOT_NULL_MESSAGE(f, rel);
    size_t n = fread(buf, 1, cap, f);
    fclose(f);
    TEST_ASSERT_TRUE(n < cap);
    return n;
}

void test_firmware_default_cfg(void)
{
    static char text[16384];
    size_t n = read_file("firmware_cfg/default.cfg", text, sizeof text);
    gs_cfg_error err;
    TEST_ASSERT_EQUAL_INT_MESSAGE(GS_OK, parse(text, n, &err), err.msg);
    gs_core_config d;
    gs_core_config_default(&d);
    /* every key present, every value the default: the parsed struct equals the default struct
       (compared field by field: NaN != NaN) */
    TEST_ASSERT_TRUE(isnan(g_core.g_m_s2) && isnan(g_core.latitude_deg));
    TEST_ASSERT_EQUAL_DOUBLE(d.altitude_m, g_core.altitude_m);
    TEST_ASSERT_EQUAL_INT(d.mass_table, g_core.mass_table);
    TEST_ASSERT_EQUAL_INT(d.stature, g_core.stature);
    TEST_ASSERT_EQUAL_FLOAT(d.min_conf, g_core.min_conf);
    TEST_ASSERT_EQUAL_INT(d.fit_method, g_core.fit_method);
    TEST_ASSERT_EQUAL_UINT32(d.ring_capacity, g_core.ring_capacity);
    TEST_ASSERT_EQUAL_FLOAT(d.min_flight_s, g_core.min_flight_s);
    TEST_ASSERT_EQUAL_FLOAT(d.max_flight_s, g_core.max_flight_s);
    TEST_ASSERT_EQUAL_UINT32(d.min_samples, g_core.min_samples);
    TEST_ASSERT_EQUAL_FLOAT(d.max_rms_rel, g_core.max_rms_rel);
    TEST_ASSERT_EQUAL_FLOAT(d.max_a_se_rel, g_core.max_a_se_rel);
    TEST_ASSERT_EQUAL_FLOAT(d.size_min_m, g_core.size_min_m);
    TEST_ASSERT_EQUAL_FLOAT(d.size_max_m, g_core.size_max_m);
    TEST_ASSERT_EQUAL_FLOAT(d.max_gap_s, g_core.max_gap_s);
    TEST_ASSERT_EQUAL_FLOAT(d.landing_latency_s, g_core.landing_latency_s);
    TEST_ASSERT_EQUAL_INT(d.format, g_core.format);
    /* and it really lists every key: each one appears as "key =" exactly once */
    static const char *const keys[] = {"g_m_s2", "latitude_deg", "altitude_m", "mass_table", "stature",
                                       "min_conf", "fit", "ring_capacity", "min_flight_s", "max_flight_s",
                                       "min_samples", "max_rms_rel", "max_a_se_rel", "size_min_m",
                                       "size_max_m", "max_gap_s", "landing_latency_s", "format"};
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        char pat[64];
        snprintf(pat, sizeof pat, "\n%s = ", keys[i]);
        const char *hit = strstr(text, pat);
        TEST_ASSERT_NOT_NULL_MESSAGE(hit, keys[i]);
        TEST_ASSERT_NULL_MESSAGE(strstr(hit + 1, pat), keys[i]);
    }
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_core_config_check(&g_core, &err));
}

void test_firmware_kiosk_cfg(void)
{
    static char text[16384];
    size_t n = read_file("firmware_cfg/kiosk.cfg", text, sizeof text);
    gs_cfg_error err;
    /* as replay reads it: [core], the cam and sink sections skipped */
    gs_cfg_section sec[1 + GS_PROFILE_SECTIONS];
    static const char *const own[] = {"core"};
    gs_core_config_default(&g_core);
    sec[0] = (gs_cfg_section){"core", gs_core_config_set, &g_core};
    size_t ns = 1 + gs_profile_foreign_sections(own, 1, sec + 1, GS_PROFILE_SECTIONS);
    TEST_ASSERT_EQUAL_INT(GS_PROFILE_SECTIONS, (int)ns);
    TEST_ASSERT_EQUAL_INT_MESSAGE(GS_OK, gs_cfg_parse(text, n, sec, ns, &err), err.msg);
    /* a section nobody reads is still an error */
    TEST_ASSERT_EQUAL_INT(GS_ENOKEY, gs_cfg_parse("[camera]\nx = 1\n", 15, sec, ns, &err));
    TEST_ASSERT_EQUAL_UINT32(1, err.line);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_core_config_check(&g_core, &err));
    TEST_ASSERT_EQUAL_DOUBLE(52.52, g_core.latitude_deg);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, 9.8127, gs_core_config_g(&g_core)); /* Berlin, 34 m */
    TEST_ASSERT_EQUAL_UINT32(2048, g_core.ring_capacity);
    TEST_ASSERT_EQUAL_FLOAT(0.9f, g_core.size_min_m);
    TEST_ASSERT_EQUAL_FLOAT(2.3f, g_core.size_max_m);
    TEST_ASSERT_EQUAL_FLOAT(0.1f, g_core.max_gap_s);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_bad_inputs_table);
    RUN_TEST(test_error_stops_parse);
    RUN_TEST(test_nul_and_long_lines);
    RUN_TEST(test_good_syntax_variants);
    RUN_TEST(test_every_core_key);
    RUN_TEST(test_defaults_and_check);
    RUN_TEST(test_gravity);
    RUN_TEST(test_firmware_default_cfg);
    RUN_TEST(test_firmware_kiosk_cfg);
    return UNITY_END();
}
