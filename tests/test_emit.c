/* test_emit.c - JSON Lines and NMEA output: exact lines for a table of events,
 * a strict little JSON reader that parses every field back, independent NMEA
 * checksums, worst-case lengths, canaries around the buffer. */
#include "gravscale/gs_emit.h"
#include "unity.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void setUp(void) {}
void tearDown(void) {}

static uint64_t g_rng = 12345;
static double rnd_unit(void)
{
    g_rng = g_rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(g_rng >> 11) * (1.0 / 9007199254740992.0);
}

/* ------------------------------------------------------- strict JSON reader */
enum { JV_NULL, JV_NUM, JV_STR, JV_BOOL, JV_ARR };
typedef struct {
    char key[40];
    int kind;
    double num;
    char str[160];
    bool b;
    int arr_n;          /* arrays: numbers, strings or nulls */
    int arr_kind[16];
    double arr_num[16];
    char arr_str[16][32];
} jv;

static const char *j_ws(const char *s) { return s; } /* our lines carry no whitespace */

static const char *j_str(const char *s, char *out, size_t cap)
{
    if (*s != '"') return NULL;
    s++;
    size_t n = 0;
    while (*s != '"') {
        unsigned char c = (unsigned char)*s;
        if (c == 0 || c < 0x20) return NULL; /* raw control characters are not JSON */
        if (c == '\\') {
            s++;
            switch (*s) {
            case '"': c = '"'; break;
            case '\\': c = '\\'; break;
            case '/': c = '/'; break;
            case 'n': c = '\n'; break;
            case 't': c = '\t'; break;
            case 'r': c = '\r'; break;
            case 'b': c = '\b'; break;
            case 'f': c = '\f'; break;
            case 'u': {
                unsigned v = 0;
                for (int i = 1; i <= 4; i++) {
                    char h = s[i];
                    v <<= 4;
                    if (h >= '0' && h <= '9') v |= (unsigned)(h - '0');
                    else if (h >= 'a' && h <= 'f') v |= (unsigned)(h - 'a' + 10);
                    else if (h >= 'A' && h <= 'F') v |= (unsigned)(h - 'A' + 10);
                    else return NULL;
                }
                if (v > 0x7f) {
                    /* U+0080..U+FFFF as UTF-8 (the emitter writes U+FFFD for bytes that are not UTF-8) */
                    if (v >= 0xD800 && v <= 0xDFFF) return NULL;
                    size_t k = v < 0x800 ? 2 : 3;
                    if (n + k >= cap) return NULL;
                    if (k == 2) {
                        out[n++] = (char)(0xC0 | (v >> 6));
                    } else {
                        out[n++] = (char)(0xE0 | (v >> 12));
                        out[n++] = (char)(0x80 | ((v >> 6) & 0x3F));
                    }
                    out[n++] = (char)(0x80 | (v & 0x3F));
                    s += 5;
                    continue;
                }
                c = (unsigned char)v;
                s += 4;
                break;
            }
            default: return NULL;
            }
        }
        if (n + 1 >= cap) return NULL;
        out[n++] = (char)c;
        s++;
    }
    out[n] = 0;
    return s + 1;
}

/* JSON number grammar, then strtod */
static const char *j_num(const char *s, double *out)
{
    const char *p = s;
    if (*p == '-') p++;
    if (*p == '0') p++;
    else if (*p >= '1' && *p <= '9') while (*p >= '0' && *p <= '9') p++;
    else return NULL;
    if (*p == '.') {
        p++;
        if (!(*p >= '0' && *p <= '9')) return NULL;
        while (*p >= '0' && *p <= '9') p++;
    }
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-') p++;
        if (!(*p >= '0' && *p <= '9')) return NULL;
        while (*p >= '0' && *p <= '9') p++;
    }
    char tmp[64];
    if ((size_t)(p - s) >= sizeof tmp) return NULL;
    memcpy(tmp, s, (size_t)(p - s));
    tmp[p - s] = 0;
    *out = strtod(tmp, NULL);
    return p;
}

static const char *j_scalar(const char *s, int *kind, double *num, char *str, size_t cap, bool *b)
{
    if (strncmp(s, "null", 4) == 0) {
        *kind = JV_NULL;
        return s + 4;
    }
    if (strncmp(s, "true", 4) == 0 || strncmp(s, "false", 5) == 0) {
        *kind = JV_BOOL;
        *b = s[0] == 't';
        return s + (*b ? 4 : 5);
    }
    if (*s == '"') {
        *kind = JV_STR;
        return j_str(s, str, cap);
    }
    *kind = JV_NUM;
    return j_num(s, num);
}

/* one object followed by exactly "\n"; returns the number of members or -1 */
static int json_line(const char *s, jv *out, int max)
{
    int n = 0;
    s = j_ws(s);
    if (*s++ != '{') return -1;
    if (*s == '}') {
        s++;
    } else {
        for (;;) {
            if (n == max) return -1;
            jv *v = &out[n++];
            memset(v, 0, sizeof *v);
            s = j_str(s, v->key, sizeof v->key);
            if (!s || *s++ != ':') return -1;
            if (*s == '[') {
                s++;
                v->kind = JV_ARR;
                if (*s != ']') {
                    for (;;) {
                        if (v->arr_n == 16) return -1;
                        bool bb;
                        int k = v->arr_n++;
                        s = j_scalar(s, &v->arr_kind[k], &v->arr_num[k], v->arr_str[k], 32, &bb);
                        if (!s) return -1;
                        if (*s == ',') {
                            s++;
                            continue;
                        }
                        break;
                    }
                }
                if (*s++ != ']') return -1;
            } else {
                s = j_scalar(s, &v->kind, &v->num, v->str, sizeof v->str, &v->b);
                if (!s) return -1;
            }
            if (*s == ',') {
                s++;
                continue;
            }
            if (*s++ != '}') return -1;
            break;
        }
    }
    if (strcmp(s, "\n") != 0) return -1;
    return n;
}

static const jv *find(const jv *v, int n, const char *key)
{
    for (int i = 0; i < n; i++)
        if (strcmp(v[i].key, key) == 0) return &v[i];
    return NULL;
}

/* a numeric field equals truth within the rounding of its format (null for NaN) */
static void check_num(const jv *v, int n, const char *key, double truth, double tol_abs, double tol_rel)
{
    const jv *f = find(v, n, key);
    TEST_ASSERT_NOT_NULL_MESSAGE(f, key);
    if (!isfinite(truth)) {
        TEST_ASSERT_EQUAL_INT_MESSAGE(JV_NULL, f->kind, key);
        return;
    }
    TEST_ASSERT_EQUAL_INT_MESSAGE(JV_NUM, f->kind, key);
    double tol = tol_abs + tol_rel * fabs(truth) + 1e-12 * fabs(truth);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(tol, truth, f->num, key);
}

/* ----------------------------------------------------------------- events */
static gs_event ev_start(void)
{
    gs_event e;
    memset(&e, 0, sizeof e);
    e.type = GS_EV_START;
    e.u.start.version = "0.1.0";
    e.u.start.config = "default";
    e.u.start.fps_source = 30.0;
    e.u.start.fps_origin = "timestamps";
    e.u.start.layout = "coco17";
    return e;
}

static gs_event ev_jump(void)
{
    gs_event e;
    memset(&e, 0, sizeof e);
    e.type = GS_EV_JUMP;
    gs_ev_jump *j = &e.u.jump;
    j->track = 0;
    j->index = 3;
    j->t_takeoff_us = 12345679;
    j->t_land_us = 12812300;
    j->flight_time_s = 0.46662;
    j->t_apex_us = 12579000;
    j->a_px_s2 = 2345.678912;
    j->a_px_se_s2 = 12.3456789;
    j->g_dir_deg = -1.234;
    j->q_m_per_px = 0.00418214;
    j->size_px = 412.345;
    j->height_m = 1.72446;
    j->height_se_m = 0.01234;
    j->jump_height_m = 0.26704;
    j->takeoff_velocity_m_s = 2.28876;
    j->com_rise_m = 0.26699;
    j->contact_time_s = NAN;
    j->rsi = NAN;
    j->n_samples = 14;
    j->n_outliers = 1;
    j->rms_px = 0.87651;
    j->accepted = true;
    j->reason = GS_REJ_NONE;
    j->warnings = 0;
    return e;
}

typedef struct {
    gs_event ev;
    const char *json;
} line_case;

static void check_exact(const gs_event *ev, const char *want)
{
    char buf[GS_EMIT_MAX];
    size_t n = gs_emit_json(ev, buf, sizeof buf);
    TEST_ASSERT_EQUAL_STRING(want, buf);
    TEST_ASSERT_EQUAL(strlen(want), n);
    jv v[32];
    TEST_ASSERT_TRUE_MESSAGE(json_line(buf, v, 32) > 0, buf);
}

void test_json_exact_lines(void)
{
    gs_event e = ev_start();
    check_exact(&e, "{\"event\":\"start\",\"version\":\"0.1.0\",\"config\":\"default\",\"fps_source\":30,"
                    "\"fps_origin\":\"timestamps\",\"layout\":\"coco17\"}\n");
    e.u.start.fps_source = NAN;
    e.u.start.fps_origin = NULL;
    e.u.start.layout = NULL;
    e.u.start.version = NULL; /* the library's own version */
    e.u.start.config = "my \"gym\"\\cam\n\x01.cfg";
    check_exact(&e, "{\"event\":\"start\",\"version\":\"" GS_VERSION "\",\"config\":\"my \\\"gym\\\"\\\\cam"
                    "\\u000a\\u0001.cfg\",\"fps_source\":null,\"fps_origin\":null,\"layout\":null}\n");

    /* JSON text is UTF-8: valid sequences pass, other bytes (a Latin-1 file name,
     * overlong forms, surrogates, a cut sequence) become U+FFFD (found by tests/fuzz/fuzz_emit.c) */
    e.u.start.config = "gr\xc3\xb6\xc3\x9f" "e \xe2\x82\xac \xf0\x9f\x98\x80 h\xf6he \xc0\xaf \xed\xa0\x80 \xf4\x90\x80\x80 \xe2\x82";
    check_exact(&e, "{\"event\":\"start\",\"version\":\"" GS_VERSION "\",\"config\":\"gr\xc3\xb6\xc3\x9f" "e \xe2\x82\xac "
                    "\xf0\x9f\x98\x80 h\\ufffdhe \\ufffd\\ufffd \\ufffd\\ufffd\\ufffd \\ufffd\\ufffd\\ufffd\\ufffd "
                    "\\ufffd\\ufffd\",\"fps_source\":null,\"fps_origin\":null,\"layout\":null}\n");

    e = ev_jump();
    check_exact(&e, "{\"event\":\"jump\",\"track\":0,\"index\":3,\"t_takeoff_s\":12.3457,\"t_land_s\":12.8123,"
                    "\"flight_time_s\":0.4666,\"t_apex_s\":12.5790,\"a_px_s2\":2345.68,\"a_px_se_s2\":12.3457,"
                    "\"g_dir_deg\":-1.23,\"q_m_per_px\":0.00418214,\"size_px\":412.35,\"height_m\":1.7245,"
                    "\"height_se_m\":0.0123,\"jump_height_m\":0.2670,\"takeoff_velocity_m_s\":2.289,"
                    "\"com_rise_m\":0.2670,\"contact_time_s\":null,\"rsi\":null,\"n_samples\":14,\"n_outliers\":1,\"rms_px\":0.877,\"accepted\":true,\"reason\":null,"
                    "\"warnings\":[]}\n");
    e.u.jump.accepted = false;
    e.u.jump.reason = GS_REJ_UNCERTAIN_A;
    e.u.jump.warnings = GS_WARN_FEW_SAMPLES | GS_WARN_OUTLIERS | GS_WARN_CLIPPED | 0x8000u; /* unknown bit */
    e.u.jump.height_m = NAN;
    e.u.jump.height_se_m = INFINITY;
    e.u.jump.q_m_per_px = 1.5e-05;
    e.u.jump.a_px_s2 = 654321.4;
    e.u.jump.t_takeoff_us = GS_T_NONE; /* unknown */
    e.u.jump.contact_time_s = 0.31249;
    e.u.jump.rsi = 0.85456;
    check_exact(&e, "{\"event\":\"jump\",\"track\":0,\"index\":3,\"t_takeoff_s\":null,\"t_land_s\":12.8123,"
                    "\"flight_time_s\":0.4666,\"t_apex_s\":12.5790,\"a_px_s2\":654321,\"a_px_se_s2\":12.3457,"
                    "\"g_dir_deg\":-1.23,\"q_m_per_px\":1.5e-05,\"size_px\":412.35,\"height_m\":null,"
                    "\"height_se_m\":null,\"jump_height_m\":0.2670,\"takeoff_velocity_m_s\":2.289,"
                    "\"com_rise_m\":0.2670,\"contact_time_s\":0.3125,\"rsi\":0.855,\"n_samples\":14,\"n_outliers\":1,\"rms_px\":0.877,\"accepted\":false,"
                    "\"reason\":\"uncertain_acceleration\",\"warnings\":[\"few_samples\",\"outliers\","
                    "\"edge_truncated\"]}\n");
    e.u.jump.warnings = 0x1FFFu;
    e.u.jump.reason = GS_REJ_GAP;
    char buf[GS_EMIT_MAX];
    gs_emit_json(&e, buf, sizeof buf);
    TEST_ASSERT_NOT_NULL(strstr(buf, "\"reason\":\"gap\",\"warnings\":[\"few_samples\",\"gravity_tilt\","
                                     "\"size_changed\",\"outliers\",\"edge_truncated\",\"camera_moved\","
                                     "\"left_frame\",\"out_of_plane\",\"other_motion\",\"no_size\",\"depth_changed\","
                                     "\"com_timed\",\"com_mismatch\"]}\n"));

    memset(&e, 0, sizeof e);
    e.type = GS_EV_HEIGHT;
    e.u.height.track = 1;
    e.u.height.height_m = 1.73456;
    e.u.height.ci95_lo_m = 1.70001;
    e.u.height.ci95_hi_m = 1.76999;
    e.u.height.n_jumps = 4;
    e.u.height.n_rejected = 2;
    check_exact(&e, "{\"event\":\"height\",\"track\":1,\"height_m\":1.7346,\"ci95_m\":[1.7000,1.7700],"
                    "\"n_jumps\":4,\"n_rejected\":2}\n");
    e.type = GS_EV_SUMMARY;
    e.u.height.height_m = NAN;
    e.u.height.ci95_lo_m = NAN;
    e.u.height.ci95_hi_m = NAN;
    e.u.height.n_jumps = 0;
    e.u.height.n_rejected = 5;
    check_exact(&e, "{\"event\":\"summary\",\"track\":1,\"height_m\":null,\"ci95_m\":null,\"n_jumps\":0,"
                    "\"n_rejected\":5}\n");

    memset(&e, 0, sizeof e);
    e.type = GS_EV_STATE;
    e.u.state.t_us = 3000060;
    e.u.state.from = "ground";
    e.u.state.to = "airborne";
    check_exact(&e, "{\"event\":\"state\",\"t_s\":3.0001,\"from\":\"ground\",\"to\":\"airborne\"}\n");

    memset(&e, 0, sizeof e);
    e.type = GS_EV_SAMPLE;
    e.u.sample.t_us = 33333;
    e.u.sample.x_px = 640.25f;
    e.u.sample.y_px = -12.5f;
    e.u.sample.w = 0.875f;
    e.u.sample.size_px = NAN;
    e.u.sample.upright = 1.0f;
    check_exact(&e, "{\"event\":\"sample\",\"t_s\":0.0333,\"x_px\":640.25,\"y_px\":-12.50,\"w\":0.875,"
                    "\"size_px\":null,\"upright\":1.000}\n");

    memset(&e, 0, sizeof e);
    e.type = GS_EV_FIT;
    e.u.fit.purpose = "final";
    e.u.fit.t_first_us = 1000000;
    e.u.fit.t_last_us = 1400000;
    e.u.fit.n = 13;
    e.u.fit.a_px_s2 = 2400.0;
    e.u.fit.g_dir_deg = 0.5;
    e.u.fit.rms_px = NAN;
    check_exact(&e, "{\"event\":\"fit\",\"purpose\":\"final\",\"t_first_s\":1.0000,\"t_last_s\":1.4000,\"n\":13,"
                    "\"a_px_s2\":2400,\"g_dir_deg\":0.50,\"rms_px\":null}\n");

    /* times: the field's decimals of the exact seconds, rounded half away from zero */
    static const struct { int64_t t_us; const char *want; } times[] = {
        {0, "0.0000"}, {50, "0.0001"}, {49, "0.0000"}, {-49, "0.0000"}, {-50, "-0.0001"},
        {-1234550, "-1.2346"}, {-1234549, "-1.2345"}, {1234550, "1.2346"}, {999999950, "1000.0000"},
        {-999999950, "-1000.0000"}, {GS_T_MAX_US, "4611686018427.3879"}, {-GS_T_MAX_US, "-4611686018427.3879"},
        {INT64_MAX, "9223372036854.7758"}, {INT64_MIN + 1, "-9223372036854.7758"}, {GS_T_NONE, "null"},
    };
    for (size_t k = 0; k < sizeof times / sizeof times[0]; k++) {
        char want[96];
        memset(&e, 0, sizeof e);
        e.type = GS_EV_WARNING;
        e.u.warning.t_us = times[k].t_us;
        snprintf(want, sizeof want, "{\"event\":\"warning\",\"track\":0,\"t_s\":%s,\"warnings\":[]}\n", times[k].want);
        check_exact(&e, want);
    }

    e.type = (gs_event_type)99;
    strcpy(buf, "junk");
    TEST_ASSERT_EQUAL(0, gs_emit_json(&e, buf, sizeof buf));
    TEST_ASSERT_EQUAL_STRING("", buf);
}

static const char *const k_jump_keys[] = {
    "event",     "track",    "index",       "t_takeoff_s", "t_land_s", "flight_time_s", "t_apex_s",
    "a_px_s2",   "a_px_se_s2", "g_dir_deg", "q_m_per_px",  "size_px",  "height_m",      "height_se_m",
    "jump_height_m", "takeoff_velocity_m_s", "com_rise_m", "contact_time_s", "rsi", "n_samples", "n_outliers",
    "rms_px", "accepted", "reason", "warnings"};

static double rnd_val(int i)
{
    switch (i % 5) {
    case 0: return NAN;
    case 1: return (rnd_unit() - 0.5) * 2e6;
    case 2: return rnd_unit() * 3.0;
    case 3: return ldexp(rnd_unit(), -(int)(rnd_unit() * 40));
    default: return -rnd_unit() * 1e9;
    }
}

/* a random time: unknown, near zero, a day-long stream, near the limits */
static int64_t rnd_time(int i)
{
    switch (i % 5) {
    case 0: return GS_T_NONE;
    case 1: return (int64_t)((rnd_unit() - 0.5) * 2e6);
    case 2: return (int64_t)(rnd_unit() * 86400e6);
    case 3: return (int64_t)((rnd_unit() - 0.5) * 2.0 * 4.6e18);
    default: return -(int64_t)(rnd_unit() * 1e13);
    }
}

/* random jumps: every field parses back to its truth within the format's rounding */
void test_json_jump_roundtrip_random(void)
{
    char buf[GS_EMIT_MAX];
    for (int it = 0; it < 5000; it++) {
        gs_event e = ev_jump();
        gs_ev_jump *j = &e.u.jump;
        gs_real *d[] = {&j->flight_time_s, &j->a_px_s2, &j->a_px_se_s2, &j->g_dir_deg, &j->q_m_per_px,
                        &j->size_px, &j->height_m, &j->height_se_m, &j->jump_height_m, &j->takeoff_velocity_m_s,
                        &j->com_rise_m, &j->contact_time_s, &j->rsi, &j->rms_px};
        for (size_t k = 0; k < sizeof d / sizeof d[0]; k++) *d[k] = rnd_val(it + (int)k * 3 + (int)(rnd_unit() * 5));
        int64_t *tm[] = {&j->t_takeoff_us, &j->t_land_us, &j->t_apex_us};
        for (size_t k = 0; k < 3; k++) *tm[k] = rnd_time(it + (int)k);
        j->track = (uint32_t)(rnd_unit() * 4);
        j->index = it % 7 == 0 ? UINT32_MAX : (uint32_t)it;
        j->n_samples = (uint32_t)(rnd_unit() * 4e9);
        j->n_outliers = (uint32_t)(rnd_unit() * 100);
        j->accepted = rnd_unit() < 0.5;
        j->reason = (gs_reject_reason)(rnd_unit() * 11);
        j->warnings = (uint32_t)(rnd_unit() * 8192);
        size_t n = gs_emit_json(&e, buf, sizeof buf);
        TEST_ASSERT_TRUE(n > 0 && n < GS_EMIT_MAX);
        jv v[32];
        int nv = json_line(buf, v, 32);
        TEST_ASSERT_EQUAL_INT_MESSAGE(25, nv, buf);
        for (int k = 0; k < 25; k++) TEST_ASSERT_EQUAL_STRING(k_jump_keys[k], v[k].key);
        TEST_ASSERT_EQUAL_DOUBLE((double)j->index, v[2].num);
        check_num(v, nv, "t_takeoff_s", gs_time_s_of_us(j->t_takeoff_us), 0.5e-4, 0);
        check_num(v, nv, "t_land_s", gs_time_s_of_us(j->t_land_us), 0.5e-4, 0);
        check_num(v, nv, "flight_time_s", j->flight_time_s, 0.5e-4, 0);
        check_num(v, nv, "t_apex_s", gs_time_s_of_us(j->t_apex_us), 0.5e-4, 0);
        check_num(v, nv, "a_px_s2", j->a_px_s2, 0, 0.5e-5);
        check_num(v, nv, "a_px_se_s2", j->a_px_se_s2, 0, 0.5e-5);
        check_num(v, nv, "g_dir_deg", j->g_dir_deg, 0.5e-2, 0);
        check_num(v, nv, "q_m_per_px", j->q_m_per_px, 0, 0.5e-5);
        check_num(v, nv, "size_px", j->size_px, 0.5e-2, 0);
        check_num(v, nv, "height_m", j->height_m, 0.5e-4, 0);
        check_num(v, nv, "height_se_m", j->height_se_m, 0.5e-4, 0);
        check_num(v, nv, "jump_height_m", j->jump_height_m, 0.5e-4, 0);
        check_num(v, nv, "takeoff_velocity_m_s", j->takeoff_velocity_m_s, 0.5e-3, 0);
        check_num(v, nv, "com_rise_m", j->com_rise_m, 0.5e-4, 0);
        check_num(v, nv, "contact_time_s", j->contact_time_s, 0.5e-4, 0);
        check_num(v, nv, "rsi", j->rsi, 0.5e-3, 0);
        check_num(v, nv, "rms_px", j->rms_px, 0.5e-3, 0);
        TEST_ASSERT_EQUAL_DOUBLE((double)j->n_samples, find(v, nv, "n_samples")->num);
        const jv *acc = find(v, nv, "accepted");
        TEST_ASSERT_EQUAL_INT(JV_BOOL, acc->kind);
        TEST_ASSERT_EQUAL(j->accepted, acc->b);
        const jv *rs = find(v, nv, "reason");
        if (j->accepted) {
            TEST_ASSERT_EQUAL_INT(JV_NULL, rs->kind);
        } else {
            TEST_ASSERT_EQUAL_STRING(gs_reject_reason_name(j->reason), rs->str);
        }
        const jv *wr = find(v, nv, "warnings");
        int bits = 0;
        for (uint32_t b = 0; b < 13; b++) bits += (j->warnings >> b) & 1u;
        TEST_ASSERT_EQUAL_INT(bits, wr->arr_n);
    }
}

/* never a byte past cap; too small -> 0 and "" */
void test_json_caps_canary(void)
{
    gs_event evs[3] = {ev_start(), ev_jump(), ev_jump()};
    evs[2].u.jump.warnings = 0x1F;
    evs[2].u.jump.accepted = false;
    evs[2].u.jump.reason = GS_REJ_IMPLAUSIBLE_A;
    for (int f = 0; f < 2; f++) {
        for (size_t k = 0; k < 3; k++) {
            char full[GS_EMIT_MAX];
            size_t need = gs_emit((gs_format)f, &evs[k], full, sizeof full);
            TEST_ASSERT_TRUE(need > 0);
            for (size_t cap = 0; cap <= need + 2; cap++) {
                char buf[GS_EMIT_MAX + 32];
                memset(buf, 0x5A, sizeof buf);
                size_t n = gs_emit((gs_format)f, &evs[k], buf + 16, cap);
                for (size_t i = 0; i < 16; i++) TEST_ASSERT_EQUAL_HEX8(0x5A, (uint8_t)buf[i]);
                for (size_t i = 16 + cap; i < sizeof buf; i++) TEST_ASSERT_EQUAL_HEX8(0x5A, (uint8_t)buf[i]);
                if (cap > need) {
                    TEST_ASSERT_EQUAL(need, n);
                    TEST_ASSERT_EQUAL_STRING(full, buf + 16);
                } else {
                    TEST_ASSERT_EQUAL(0, n);
                    if (cap) {
                        TEST_ASSERT_EQUAL_HEX8(0, (uint8_t)buf[16]);
                    }
                }
            }
        }
    }
    TEST_ASSERT_EQUAL(0, gs_emit_json(&evs[0], NULL, 0));
    char small[8] = "junk";
    TEST_ASSERT_EQUAL(0, gs_emit_json(NULL, small, sizeof small));
    TEST_ASSERT_EQUAL_STRING("", small);
}

/* ------------------------------------------------------------------ NMEA */
/* the checksum computed here, independently of the emitter */
static void check_sentence(const char *s, size_t n)
{
    TEST_ASSERT_EQUAL(strlen(s), n);
    TEST_ASSERT_TRUE_MESSAGE(n <= 82, s);
    TEST_ASSERT_EQUAL_INT('$', s[0]);
    TEST_ASSERT_EQUAL_STRING("\r\n", s + n - 2);
    const char *star = strchr(s, '*');
    TEST_ASSERT_NOT_NULL(star);
    TEST_ASSERT_EQUAL_PTR(s + n - 5, star);
    unsigned x = 0;
    for (const char *p = s + 1; p < star; p++) x ^= (unsigned char)*p;
    char hh[3];
    snprintf(hh, sizeof hh, "%02X", x);
    TEST_ASSERT_EQUAL_INT(hh[0], star[1]);
    TEST_ASSERT_EQUAL_INT(hh[1], star[2]);
    for (const char *p = s + 1; p < star; p++) TEST_ASSERT_TRUE(*p >= 0x20 && *p < 0x7f && *p != '$' && *p != '*');
}

/* split "$GSxxx,a,b,...*HH\r\n" into fields (0 = talker+type) */
static int nmea_fields(const char *s, char f[16][32])
{
    int n = 0;
    size_t k = 0;
    for (const char *p = s + 1; *p != '*'; p++) {
        if (*p == ',') {
            f[n][k] = 0;
            n++;
            k = 0;
        } else if (k < 31) {
            f[n][k++] = *p;
        }
    }
    f[n][k] = 0;
    return n + 1;
}

static void check_field(const char *f, double truth, double tol)
{
    if (!isfinite(truth)) {
        TEST_ASSERT_EQUAL_STRING("", f);
        return;
    }
    if (f[0] == 0) return; /* allowed only when the value cannot fit its width: checked by the caller */
    char *end;
    double v = strtod(f, &end);
    TEST_ASSERT_EQUAL_INT(0, *end);
    TEST_ASSERT_DOUBLE_WITHIN(tol + 1e-12 * fabs(truth), truth, v);
}

void test_nmea_exact(void)
{
    char buf[GS_EMIT_MAX];
    gs_event e = ev_jump();
    size_t n = gs_emit_nmea(&e, buf, sizeof buf);
    /* checksum of "GSJMP,12.346,0.467,2345.7,0.0041821,1.724,0.267,2.29,14,A,0" */
    TEST_ASSERT_EQUAL_STRING("$GSJMP,12.346,0.467,2345.7,0.0041821,1.724,0.267,2.29,14,A,0*2D\r\n", buf);
    check_sentence(buf, n);
    e.u.jump.accepted = false;
    e.u.jump.reason = GS_REJ_LARGE_RESIDUAL;
    e.u.jump.height_m = NAN;
    e.u.jump.q_m_per_px = NAN;
    n = gs_emit_nmea(&e, buf, sizeof buf);
    check_sentence(buf, n);
    TEST_ASSERT_EQUAL_STRING_LEN("$GSJMP,12.346,0.467,2345.7,,,0.267,2.29,14,R,2*", buf, n - 4);

    memset(&e, 0, sizeof e);
    e.type = GS_EV_HEIGHT;
    e.u.height.height_m = 1.73456;
    e.u.height.ci95_lo_m = 1.70001;
    e.u.height.ci95_hi_m = 1.76999;
    e.u.height.n_jumps = 4;
    n = gs_emit_nmea(&e, buf, sizeof buf);
    check_sentence(buf, n);
    TEST_ASSERT_EQUAL_STRING_LEN("$GSHGT,1.7346,1.7000,1.7700,4*", buf, n - 4);
    e.type = GS_EV_SUMMARY;
    e.u.height.height_m = NAN;
    e.u.height.ci95_lo_m = NAN;
    e.u.height.ci95_hi_m = NAN;
    e.u.height.n_jumps = 0;
    e.u.height.n_rejected = 3;
    n = gs_emit_nmea(&e, buf, sizeof buf);
    check_sentence(buf, n);
    TEST_ASSERT_EQUAL_STRING_LEN("$GSSUM,,,,0,3*", buf, n - 4);

    e = ev_start();
    e.u.start.fps_source = 29.97;
    n = gs_emit_nmea(&e, buf, sizeof buf);
    check_sentence(buf, n);
    TEST_ASSERT_EQUAL_STRING_LEN("$GSSTA,0.1.0,29.970*", buf, n - 4);
    e.u.start.version = "1,2*$\n";
    n = gs_emit_nmea(&e, buf, sizeof buf);
    check_sentence(buf, n);
    TEST_ASSERT_EQUAL_STRING_LEN("$GSSTA,1_2___,29.970*", buf, n - 4);

    /* trace events have no sentence */
    const gs_event_type trace[] = {GS_EV_STATE, GS_EV_SAMPLE, GS_EV_FIT};
    for (size_t i = 0; i < 3; i++) {
        memset(&e, 0, sizeof e);
        e.type = trace[i];
        strcpy(buf, "junk");
        TEST_ASSERT_EQUAL(0, gs_emit_nmea(&e, buf, sizeof buf));
        TEST_ASSERT_EQUAL_STRING("", buf);
    }
    strcpy(buf, "junk");
    TEST_ASSERT_EQUAL(0, gs_emit((gs_format)7, &e, buf, sizeof buf));
    TEST_ASSERT_EQUAL_STRING("", buf);
}

/* worst case: large negative values and maximum counters still fit 82 chars */
void test_nmea_worst_case(void)
{
    char buf[GS_EMIT_MAX];
    gs_event e = ev_jump();
    gs_ev_jump *j = &e.u.jump;
    j->t_takeoff_us = -99999999000;
    j->flight_time_s = -9.99;
    j->a_px_s2 = -99999.9;
    j->q_m_per_px = -1.2345678;
    j->height_m = -9.999;
    j->jump_height_m = -9.99;
    j->takeoff_velocity_m_s = -99.99;
    j->n_samples = UINT32_MAX;
    j->accepted = false;
    j->reason = GS_REJ_GAP;
    size_t n = gs_emit_nmea(&e, buf, sizeof buf);
    check_sentence(buf, n);
    TEST_ASSERT_EQUAL(82, n); /* every field at its full width */
    TEST_ASSERT_EQUAL_STRING_LEN(
        "$GSJMP,-99999.999,-9.99,-99999.9,-1.234568,-9.999,-9.99,-99.99,4294967295,R,6*", buf, n - 4);
    /* far larger values lose decimals, then become empty: never longer */
    for (int it = 0; it < 20000; it++) {
        gs_real *d[] = {NULL, &j->flight_time_s, &j->a_px_s2, &j->q_m_per_px, &j->height_m,
                        &j->jump_height_m, &j->takeoff_velocity_m_s};
        double truth[7];
        for (size_t k = 0; k < 7; k++) {
            double mag = pow(10.0, rnd_unit() * 24 - 8);
            double v = (rnd_unit() < 0.6 ? -1 : 1) * mag;
            if (rnd_unit() < 0.05) v = NAN;
            if (k == 0) { /* the time: whole microseconds up to 10^16 s (beyond the range: any int64) */
                j->t_takeoff_us = isnan(v) ? GS_T_NONE : fabs(v) < 9.2e12 ? (int64_t)llround(v * 1e6)
                                                                          : v < 0 ? -INT64_MAX : INT64_MAX;
                v = gs_time_s_of_us(j->t_takeoff_us);
            } else {
                *d[k] = v;
            }
            truth[k] = v;
        }
        j->n_samples = rnd_unit() < 0.3 ? UINT32_MAX : (uint32_t)(rnd_unit() * 1000);
        n = gs_emit_nmea(&e, buf, sizeof buf);
        check_sentence(buf, n);
        char f[16][32];
        TEST_ASSERT_EQUAL_INT(11, nmea_fields(buf, f));
        TEST_ASSERT_EQUAL_STRING("GSJMP", f[0]);
        static const double width[7] = {10, 5, 8, 9, 6, 5, 6};
        static const int dec[7] = {3, 3, 1, 7, 3, 3, 2};
        for (int k = 0; k < 7; k++) {
            /* the decimals shown set the tolerance; empty only when even 0 decimals is too wide */
            const char *dot = strchr(f[k + 1], '.');
            int shown = dot ? (int)strlen(dot + 1) : 0;
            TEST_ASSERT_TRUE(shown <= dec[k]);
            check_field(f[k + 1], truth[k], 0.5 * pow(10, -shown));
            if (isfinite(truth[k]) && f[k + 1][0] == 0) {
                char t[64];
                snprintf(t, sizeof t, "%.0f", truth[k]);
                TEST_ASSERT_TRUE_MESSAGE(strlen(t) > width[k] || fabs(truth[k]) >= 1e15, t);
            }
        }
        char u[16];
        snprintf(u, sizeof u, "%u", (unsigned)j->n_samples);
        TEST_ASSERT_EQUAL_STRING(u, f[8]);
    }
    memset(&e, 0, sizeof e);
    e.type = GS_EV_SUMMARY;
    e.u.height.height_m = -999999.9999;
    e.u.height.ci95_lo_m = -999999.9999;
    e.u.height.ci95_hi_m = -999999.9999;
    e.u.height.n_jumps = UINT32_MAX;
    e.u.height.n_rejected = UINT32_MAX;
    n = gs_emit_nmea(&e, buf, sizeof buf);
    check_sentence(buf, n);
    TEST_ASSERT_EQUAL_STRING_LEN("$GSSUM,-999999.9999,-999999.9999,-999999.9999,4294967295,4294967295*",
                                 buf, n - 4);
}

/* The widest lines: every number at its widest text, every warning, the
 * longest reason. GS_EMIT_MAX must hold them (640 did not: fuzz_emit found a
 * 744-byte jump line). */
void test_json_widest_events_fit(void)
{
    const double F = -999999999999999.9; /* the widest fixed-notation value */
    const double S = -1.23456789e-300;   /* the widest 6-significant-digit value */
    char buf[GS_EMIT_MAX];
    gs_event e;
    memset(&e, 0, sizeof e);
    e.type = GS_EV_JUMP;
    gs_ev_jump *j = &e.u.jump;
    j->track = j->index = j->n_samples = j->n_outliers = UINT32_MAX;
    j->t_takeoff_us = j->t_land_us = j->t_apex_us = INT64_MIN + 1; /* the widest time */
    j->flight_time_s = F;
    j->a_px_s2 = j->a_px_se_s2 = j->q_m_per_px = S;
    j->g_dir_deg = j->size_px = j->height_m = j->height_se_m = j->jump_height_m = F;
    j->takeoff_velocity_m_s = j->com_rise_m = j->contact_time_s = j->rsi = j->rms_px = F;
    j->accepted = false;
    j->reason = GS_REJ_IMPLAUSIBLE_A;
    j->warnings = 0x1FFFu;
    size_t n = gs_emit_json(&e, buf, sizeof buf);
    TEST_ASSERT_EQUAL_UINT64(907, n); /* its three times at their widest are 2 characters narrower than F */
    jv v[32];
    TEST_ASSERT_TRUE_MESSAGE(json_line(buf, v, 32) > 0, buf);

    memset(&e, 0, sizeof e);
    e.type = GS_EV_SESSION;
    gs_ev_session *s = &e.u.session;
    s->track = s->session = s->n_jumps = s->n_rejected = UINT32_MAX;
    s->ended = true;
    s->reason = "end_of_stream";
    s->t_start_us = s->t_end_us = INT64_MIN + 1;
    s->stature_m = s->ci95_lo_m = s->ci95_hi_m = F;
    s->best_jump_m = s->mean_jump_m = s->best_flight_s = s->mean_flight_s = s->mean_takeoff_velocity_m_s = F;
    n = gs_emit_json(&e, buf, sizeof buf);
    TEST_ASSERT_TRUE(n > 0 && n < GS_EMIT_MAX);

    /* a JSON string on its own, as the sinks' status lines use it */
    TEST_ASSERT_EQUAL_UINT64(4, gs_emit_json_str(NULL, buf, sizeof buf));
    TEST_ASSERT_EQUAL_STRING("null", buf);
    TEST_ASSERT_EQUAL_UINT64(17, gs_emit_json_str("a\"\x01\xff", buf, sizeof buf));
    TEST_ASSERT_EQUAL_STRING("\"a\\\"\\u0001\\ufffd\"", buf);
    TEST_ASSERT_EQUAL_UINT64(0, gs_emit_json_str("a\"\x01\xff", buf, 17)); /* no room for the NUL */
    TEST_ASSERT_EQUAL_STRING("", buf);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_json_exact_lines);
    RUN_TEST(test_json_jump_roundtrip_random);
    RUN_TEST(test_json_caps_canary);
    RUN_TEST(test_nmea_exact);
    RUN_TEST(test_nmea_worst_case);
    RUN_TEST(test_json_widest_events_fit);
    return UNITY_END();
}
