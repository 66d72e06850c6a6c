/* features_check.c - a device feature selection (include/gravscale/gs_features.h)
 * behaves as documented: what is left out is unsupported (unknown layout, format
 * or fit name; no trace events; gs_emit writes nothing), what is in gives the same
 * bytes. Built twice by CMake: features_full (every feature) and
 * features_ball_lab (the firmware's ball-lab selection). Each checks its own
 * selection (exit 1 on a failure); with --lines it prints the NMEA lines of a
 * bouncing ball, which must be identical for both builds (CTest compares them). */
#include "gravscale/gravscale.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static int g_fail;
#define CHECK(c)                                                                          \
    do {                                                                                  \
        if (!(c)) {                                                                       \
            fprintf(stderr, "features_check: %s:%d: %s\n", __FILE__, __LINE__, #c);       \
            g_fail = 1;                                                                   \
        }                                                                                 \
    } while (0)

static char g_lines[1 << 16];
static size_t g_len;
static unsigned g_trace;

static void on_event(void *ctx, const gs_event *ev)
{
    (void)ctx;
    if (ev->type == GS_EV_STATE || ev->type == GS_EV_SAMPLE || ev->type == GS_EV_FIT) {
        g_trace++;
        return;
    }
    char buf[GS_EMIT_MAX];
    size_t n = gs_emit(GS_FMT_NMEA, ev, buf, sizeof buf);
    if (n && g_len + n < sizeof g_lines) {
        memcpy(g_lines + g_len, buf, n);
        g_len += n;
    }
}

static gs_status parse_core(const char *text, gs_core_config *cfg)
{
    gs_cfg_error err;
    const gs_cfg_section sec = {"core", gs_core_config_set, cfg};
    gs_core_config_default(cfg);
    return gs_cfg_parse(text, strlen(text), &sec, 1, &err);
}

/* a ball bouncing with 0.45 s flights at 60 fps, 2 mm/px (as tools/fw/fw_scenario.c) */
static void run_ball(void)
{
    static double storage[4096];
    static gs_pipeline pipe;
    gs_core_config cfg;
    CHECK(parse_core("[core]\nformat = nmea\nsize_min_m = 0.02\nsize_max_m = 2.5\n", &cfg) == GS_OK);
    CHECK(gs_pipeline_storage_bytes(&cfg) <= sizeof storage);
    CHECK(gs_pipeline_init(&pipe, &cfg, GS_LAYOUT_POINT, storage, sizeof storage, on_event, NULL) == GS_OK);
    gs_pipeline_set_trace(&pipe, true);
    for (int i = 0; i < 6 * 60; i++) {
        /* microseconds as a device counts them (and as fw_scenario.c pushes them) */
        int64_t t_us = INT64_C(1000000000) + (int64_t)(((uint32_t)i * 1000000u + 30u) / 60u);
        double x = fmod(i / 60.0, 0.6);
        double h = x > 0.45 ? 0.0 : 0.5 * 9.81 * 0.45 * x - 0.5 * 9.81 * x * x;
        CHECK(gs_pipeline_push_point_us(&pipe, t_us, 320.0f, (float)(400.0 - h / 0.002), 1.0f, 34.35f) == GS_OK);
    }
    CHECK(gs_pipeline_flush(&pipe) == GS_OK);
    CHECK(g_len > 0);
    CHECK(GS_WITH_TRACE ? g_trace > 0 : g_trace == 0);
}

int main(int argc, char **argv)
{
    gs_core_config cfg;
    gs_format fmt;
    gs_fit_method fm;
    char buf[GS_EMIT_MAX];
    static double storage[4096];
    static gs_pipeline pipe;
    gs_event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_HEIGHT;
    ev.u.height.height_m = 1.75;

    /* layouts */
    CHECK(gs_layout_kp_count(GS_LAYOUT_POINT) == 1);
    CHECK(gs_layout_kp_count(GS_LAYOUT_COCO17) == (GS_WITH_COCO17 ? 17u : 0u));
    CHECK(gs_layout_kp_count(GS_LAYOUT_BLAZEPOSE33) == (GS_WITH_BLAZEPOSE33 ? 33u : 0u));
    gs_core_config_default(&cfg);
    CHECK((gs_pipeline_init(&pipe, &cfg, GS_LAYOUT_COCO17, storage, sizeof storage, on_event, NULL) == GS_OK) ==
          GS_WITH_COCO17);
    CHECK((gs_pipeline_init(&pipe, &cfg, GS_LAYOUT_BLAZEPOSE33, storage, sizeof storage, on_event, NULL) == GS_OK) ==
          GS_WITH_BLAZEPOSE33);
    /* formats: names, the default, the emitter, the profile */
    CHECK(gs_format_from_name("json", 4, &fmt) == GS_WITH_JSON);
    CHECK(gs_format_from_name("nmea", 4, &fmt) == GS_WITH_NMEA);
    CHECK(cfg.format == (GS_WITH_JSON ? GS_FMT_JSON : GS_FMT_NMEA));
    CHECK((gs_emit(GS_FMT_JSON, &ev, buf, sizeof buf) > 0) == GS_WITH_JSON);
    CHECK((gs_emit(GS_FMT_NMEA, &ev, buf, sizeof buf) > 0) == GS_WITH_NMEA);
    if (!GS_WITH_JSON) {
        strcpy(buf, "xx");
        CHECK(gs_emit(GS_FMT_JSON, &ev, buf, sizeof buf) == 0 && buf[0] == '\0');
    }
    CHECK((parse_core("[core]\nformat = json\n", &cfg) == GS_OK) == GS_WITH_JSON);
    CHECK((parse_core("[core]\nformat = nmea\n", &cfg) == GS_OK) == GS_WITH_NMEA);
    /* fit methods */
    CHECK(gs_fit_method_from_name("ransac", 6, &fm) == GS_WITH_RANSAC);
    CHECK(gs_fit_method_from_name("irls", 4, &fm) && fm == GS_FIT_IRLS);
    CHECK(gs_fit_method_from_name("plain", 5, &fm) && fm == GS_FIT_PLAIN);
    CHECK((parse_core("[core]\nfit = ransac\n", &cfg) == GS_OK) == GS_WITH_RANSAC);

    if (GS_WITH_NMEA) run_ball();
    if (argc > 1 && strcmp(argv[1], "--lines") == 0) fwrite(g_lines, 1, g_len, stdout);
    if (!g_fail) fprintf(stderr, "features_check: selection json %d nmea %d coco17 %d blazepose33 %d ransac %d trace %d: ok\n",
                         GS_WITH_JSON, GS_WITH_NMEA, GS_WITH_COCO17, GS_WITH_BLAZEPOSE33, GS_WITH_RANSAC, GS_WITH_TRACE);
    return g_fail;
}
