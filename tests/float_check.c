/* float_check.c - the core built as on the Cortex-M4 (GS_REAL=float, CMake's
 * float_check test), on the host: the [core] section's gs_real fields parse,
 * check and bake as floats (the decimal bounds hold as floats); g from latitude
 * and altitude in float against the double formula; values are printed from the
 * float's exact value (gs_dwiden), times from their microseconds; a fit and a
 * bouncing ball on microsecond times far from zero. Exit 1 on a failure. */
#include "gravscale/gravscale.h"
#include "fw_profile.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

_Static_assert(sizeof(gs_real) == sizeof(float), "built with GS_REAL=float");

static int g_fail;
#define CHECK(c)                                                                          \
    do {                                                                                  \
        if (!(c)) {                                                                       \
            fprintf(stderr, "float_check: %s:%d: %s\n", __FILE__, __LINE__, #c);          \
            g_fail = 1;                                                                   \
        }                                                                                 \
    } while (0)

static gs_status parse_core(const char *text, gs_core_config *cfg, gs_cfg_error *err)
{
    const gs_cfg_section sec = {"core", gs_core_config_set, cfg};
    gs_core_config_default(cfg);
    return gs_cfg_parse(text, strlen(text), &sec, 1, err);
}

static void check_config(void)
{
    static const struct { const char *text; gs_status want; } rows[] = {
        {"[core]\ng_m_s2 = 9.7\n", GS_OK},        /* 9.7f < 9.7: the bound holds as a float */
        {"[core]\ng_m_s2 = 9.9\n", GS_OK},
        {"[core]\ng_m_s2 = 9.69\n", GS_ERANGE},
        {"[core]\ng_m_s2 = 9.900001\n", GS_ERANGE},
        {"[core]\ng_m_s2 = auto\n", GS_OK},
        {"[core]\nlatitude_deg = -90\naltitude_m = 9000\n", GS_OK},
        {"[core]\nlatitude_deg = 90.0001\n", GS_ERANGE},
        {"[core]\naltitude_m = -500.001\n", GS_ERANGE},
        {"[core]\naltitude_m = auto\n", GS_EINVAL},
        {"[core]\nlatitude_deg = x\n", GS_EINVAL},
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        gs_core_config c;
        gs_cfg_error err;
        gs_status st = parse_core(rows[k].text, &c, &err);
        CHECK(st == rows[k].want);
        if (st == GS_OK) CHECK(gs_core_config_check(&c, &err) == GS_OK);
    }
    gs_core_config c;
    gs_cfg_error err;
    CHECK(parse_core("[core]\ng_m_s2 = 9.7\nlatitude_deg = 47.3769\naltitude_m = 408.5\n", &c, &err) == GS_OK);
    CHECK(c.g_m_s2 == 9.7f && c.latitude_deg == 47.3769f && c.altitude_m == 408.5f);
    CHECK(gs_core_config_g(&c) == 9.7f);
    /* a config filled in by code gets the same checks */
    c.g_m_s2 = 9.95f;
    CHECK(gs_core_config_check(&c, &err) == GS_ERANGE && strcmp(err.key, "g_m_s2") == 0);
    c.g_m_s2 = NAN;
    CHECK(gs_core_config_check(&c, &err) == GS_OK);
    c.altitude_m = 9000.001f;
    CHECK(gs_core_config_check(&c, &err) == GS_ERANGE && strcmp(err.key, "altitude_m") == 0);
    c.altitude_m = NAN;
    CHECK(gs_core_config_check(&c, &err) == GS_ERANGE);
    /* the baked profile (tools/fw/fw_bake.c, run by this build's host compiler in
     * double) is what the firmware's parser makes of its text, field by field */
    static const gs_core_config k_baked = FW_PROFILE_CONFIG;
    gs_core_config parsed;
    CHECK(parse_core(FW_PROFILE_TEXT, &parsed, &err) == GS_OK);
    CHECK(memcmp(&k_baked.g_m_s2, &parsed.g_m_s2, sizeof parsed.g_m_s2) == 0);
    CHECK(memcmp(&k_baked.latitude_deg, &parsed.latitude_deg, sizeof parsed.latitude_deg) == 0);
    CHECK(memcmp(&k_baked.altitude_m, &parsed.altitude_m, sizeof parsed.altitude_m) == 0);
    CHECK(memcmp(&k_baked.session_absence_s, &parsed.session_absence_s, sizeof parsed.session_absence_s) == 0);
}

/* the double formula (WGS-84 Somigliana and the free-air gradient) */
static double gravity_ref(double lat_deg, double alt_m)
{
    double s = sin(lat_deg * 3.14159265358979323846 / 180.0), s2 = s * s;
    return 9.7803253359 * (1.0 + 0.00193185265241 * s2) / sqrt(1.0 - 0.00669437999013 * s2) - 3.086e-6 * alt_m;
}

static void check_gravity(void)
{
    double worst = 0.0;
    for (int lat = -90; lat <= 90; lat++)
        for (int alt = -500; alt <= 9000; alt += 500) {
            double d = fabs((double)gs_gravity_m_s2((gs_real)lat, (gs_real)alt) - gravity_ref(lat, alt));
            if (d > worst) worst = d;
        }
    CHECK(worst < 5e-6); /* 0.5 ppm: far finer than any site's g is known */
    gs_core_config c;
    gs_core_config_default(&c);
    CHECK(gs_core_config_g(&c) == 9.81f);
    c.latitude_deg = 45.0f;
    c.altitude_m = NAN;
    CHECK(fabs((double)gs_core_config_g(&c) - gravity_ref(45.0, 0.0)) < 5e-6);
    CHECK(gs_core_config_g(NULL) == 9.81f);
}

/* the JSON text of field `key` in line */
static const char *field(const char *line, const char *key, char *out, size_t cap)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = strstr(line, pat);
    if (!p) return "";
    p += strlen(pat);
    size_t n = strcspn(p, ",}");
    if (n >= cap) n = cap - 1;
    memcpy(out, p, n);
    out[n] = '\0';
    return out;
}

static void check_emit(void)
{
    static const float vals[] = {1.7245f, -0.00005f, 0.12345f, 1e-40f, -3.4e38f, 2345.678912f, 0.0f, -0.0f};
    for (size_t k = 0; k < sizeof vals / sizeof vals[0]; k++) {
        gs_event e;
        memset(&e, 0, sizeof e);
        e.type = GS_EV_JUMP;
        e.u.jump.t_takeoff_us = INT64_C(1000000000000) + 16667;
        e.u.jump.t_land_us = GS_T_NONE;
        e.u.jump.t_apex_us = -1234550;
        e.u.jump.height_m = vals[k];
        e.u.jump.a_px_s2 = vals[k];
        e.u.jump.flight_time_s = NAN;
        char line[GS_EMIT_MAX], want[64], got[64];
        CHECK(gs_emit_json(&e, line, sizeof line) > 0);
        /* the float's exact value, as the host's own conversion gives it */
        size_t n = gs_num_fmt_fixed(want, sizeof want, (double)vals[k], 4);
        CHECK(strcmp(field(line, "height_m", got, sizeof got), n ? want : "null") == 0);
        n = gs_num_fmt_sig(want, sizeof want, (double)vals[k], 6);
        CHECK(strcmp(field(line, "a_px_se_s2", got, sizeof got), "0") == 0);
        CHECK(strcmp(field(line, "a_px_s2", got, sizeof got), want) == 0 && n > 0);
        CHECK(strcmp(field(line, "t_takeoff_s", got, sizeof got), "1000000.0167") == 0);
        CHECK(strcmp(field(line, "t_land_s", got, sizeof got), "null") == 0);
        CHECK(strcmp(field(line, "t_apex_s", got, sizeof got), "-1.2346") == 0);
        CHECK(strcmp(field(line, "flight_time_s", got, sizeof got), "null") == 0);
    }
}

static void check_fit(void)
{
    /* a throw sampled at 120 fps, 11.6 days after the clock's zero */
    const int64_t t0 = INT64_C(1000000000000);
    gs_fit f;
    gs_fit_result r;
    gs_fit_init(&f, t0 + 250000, 500000);
    for (int i = 0; i < 61; i++) {
        int64_t t_us = t0 + ((int64_t)i * 1000000 + 60) / 120;
        float tt = (float)(t_us - t0) / 1e6f;
        gs_fit_add(&f, t_us, 300.0f + 20.0f * tt, 700.0f - 450.0f * tt + 490.0f * tt * tt, 1.0f);
    }
    CHECK(gs_fit_solve(&f, &r) == GS_OK);
    CHECK(r.t0_us == t0 + 250000 && r.n == 61);
    CHECK(fabsf(r.ay_px_s2 - 980.0f) < 0.05f && fabsf(r.vx_px_s - 20.0f) < 0.01f);
}

static unsigned g_jumps, g_accepted;

static void on_event(void *ctx, const gs_event *ev)
{
    (void)ctx;
    if (ev->type != GS_EV_JUMP) return;
    g_jumps++;
    /* 0.45 s in the air; the detected flight is 0.41-0.45 s (the double build's too) */
    if (ev->u.jump.accepted && ev->u.jump.flight_time_s > 0.40f && ev->u.jump.flight_time_s < 0.46f) g_accepted++;
}

/* the firmware's ball (tools/fw/fw_scenario.c) on a boot clock far from zero */
static void check_ball(void)
{
    static double storage[4096];
    static gs_pipeline pipe;
    gs_core_config cfg;
    gs_cfg_error err;
    CHECK(parse_core("[core]\nsize_min_m = 0.02\nsize_max_m = 2.5\n", &cfg, &err) == GS_OK);
    CHECK(gs_pipeline_init(&pipe, &cfg, GS_LAYOUT_POINT, storage, sizeof storage, on_event, NULL) == GS_OK);
    for (uint32_t i = 0; i < 6u * 60u; i++) {
        int64_t t_us = INT64_C(1000000000) + (int64_t)((i * 1000000u + 30u) / 60u);
        double x = fmod(i / 60.0, 0.6);
        double h = x > 0.45 ? 0.0 : 0.5 * 9.81 * 0.45 * x - 0.5 * 9.81 * x * x;
        CHECK(gs_pipeline_push_point_us(&pipe, t_us, 320.0f, (float)(400.0 - h / 0.002), 1.0f, 34.35f) == GS_OK);
    }
    CHECK(gs_pipeline_push_point_us(&pipe, GS_T_NONE, 1.0f, 1.0f, 1.0f, 1.0f) == GS_EINVAL);
    CHECK(gs_pipeline_push_point_us(&pipe, 0, 1.0f, 1.0f, 1.0f, 1.0f) == GS_EORDER);
    CHECK(gs_pipeline_push_point_us(&pipe, GS_T_MAX_US + 1, 1.0f, 1.0f, 1.0f, 1.0f) == GS_ERANGE);
    CHECK(gs_pipeline_flush(&pipe) == GS_OK);
    CHECK(g_jumps == 10 && g_accepted == 10);
}

int main(void)
{
    check_config();
    check_gravity();
    check_emit();
    check_fit();
    check_ball();
    if (!g_fail) fprintf(stderr, "float_check: GS_REAL=float: ok (%u jumps, %u accepted)\n", g_jumps, g_accepted);
    return g_fail;
}
