/* test_pipeline_com.c - the pipeline's two-step entry (gs_pipeline_com, then
 * gs_pipeline_push_com_us, as the replay runs it with the COM computed in its
 * reader thread) against the one-step gs_pipeline_push_keypoints_us as the
 * reference: table-driven over layouts, configs and awkward frames, every
 * status, sample, fit and event the same, byte for byte as JSON; and a pipeline whose
 * init failed refuses frames. */
#include "unity.h"
#include "gravscale/gravscale.h"
#include "gs_kpread.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef GS_SOURCE_DIR
#define GS_SOURCE_DIR "."
#endif

void setUp(void) {}
void tearDown(void) {}

#define MAX_FRAMES 1024

/* the bundled COCO-17 track (a 1.734 m subject, three jumps), as the replay reads it */
static gs_kpframe g_frames[MAX_FRAMES];
static size_t g_n;

static void load_sample(void)
{
    if (g_n) return;
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    gs_kpread_error err;
    gs_kpread *r = gs_kpread_open(GS_SOURCE_DIR "/tests/data/sample_jumps.csv", &o, &err);
    TEST_ASSERT_NOT_NULL_MESSAGE(r, err.text);
    while (g_n < MAX_FRAMES && gs_kpread_next(r, &g_frames[g_n], &err) == GS_KPR_FRAME) g_n++;
    gs_kpread_close(r);
    TEST_ASSERT_TRUE(g_n > 300);
}

/* every event as its JSON line, every push's status as a line of its own */
typedef struct {
    char *text;
    size_t len, cap;
} ev_log;

static void log_add(ev_log *l, const char *s, size_t n)
{
    if (l->len + n + 1 > l->cap) {
        l->cap = 2 * (l->len + n + 1);
        l->text = realloc(l->text, l->cap);
        TEST_ASSERT_NOT_NULL(l->text);
    }
    memcpy(l->text + l->len, s, n);
    l->len += n;
    l->text[l->len++] = '\n';
}

static void on_ev(void *ctx, const gs_event *ev)
{
    char buf[GS_EMIT_MAX];
    size_t n = gs_emit_json(ev, buf, sizeof buf);
    TEST_ASSERT_TRUE(n > 0);
    log_add(ctx, buf, n);
}

static void log_status(ev_log *l, size_t i, gs_status st)
{
    char buf[48];
    int n = snprintf(buf, sizeof buf, "push %u: %s", (unsigned)i, gs_status_str(st));
    log_add(l, buf, (size_t)n);
}

/* COCO-17 -> BlazePose-33 (heels and toes a few px either side of the ankles) */
static const int8_t k_bp33_of_coco[33] = {0,  1,  1,  2,  3,  3,  4,  3,  4,  -1, -1,
                                          5,  6,  7,  8,  9,  10, 9,  10, 9,  10, 9,
                                          10, 11, 12, 13, 14, 15, 16, 15, 16, 15, 16};

static void to_layout(gs_layout layout, const gs_kp *coco, gs_kp *out)
{
    if (layout == GS_LAYOUT_COCO17) {
        memcpy(out, coco, 17 * sizeof *out);
    } else if (layout == GS_LAYOUT_POINT) {  /* the hips' midpoint as a tracked point */
        out[0].x_px = 0.5f * (coco[11].x_px + coco[12].x_px);
        out[0].y_px = 0.5f * (coco[11].y_px + coco[12].y_px);
        out[0].c = coco[11].c < coco[12].c ? coco[11].c : coco[12].c;
    } else {
        for (int k = 0; k < 33; k++) {
            int src = k_bp33_of_coco[k];
            out[k] = src < 0 ? (gs_kp){NAN, NAN, 0.0f} : coco[src];
            if (k >= 29) out[k].x_px += k >= 31 ? 12.0f : -6.0f;  /* heels behind, toes ahead */
            if (k >= 31) out[k].y_px += 4.0f;
        }
    }
}

typedef enum {
    FRAMES_PLAIN = 0,
    FRAMES_AWKWARD,  /* repeats, a step back, an unknown time, nobody in view, a long gap */
} frames_kind;

typedef struct {
    const char *name;
    gs_layout layout;
    gs_mass_table mass;
    gs_stature_method stature;
    float min_conf;
    frames_kind frames;
    size_t min_jumps; /* the run must show this many jumps at least */
} com_case;

static const com_case k_cases[] = {
    {"coco17 default", GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, -1.0f, FRAMES_PLAIN, 3},
    {"coco17 clauser nose_ankle", GS_LAYOUT_COCO17, GS_MASS_CLAUSER, GS_STATURE_NOSE_ANKLE_117, -1.0f, FRAMES_PLAIN, 3},
    {"coco17 dempster min_conf 0.7", GS_LAYOUT_COCO17, GS_MASS_DEMPSTER, GS_STATURE_ANTHRO, 0.7f, FRAMES_PLAIN, 1},
    {"coco17 awkward frames", GS_LAYOUT_COCO17, GS_MASS_DELEVA, GS_STATURE_ANTHRO, 0.3f, FRAMES_AWKWARD, 3},
    {"blazepose33 default", GS_LAYOUT_BLAZEPOSE33, GS_MASS_DELEVA, GS_STATURE_ANTHRO, -1.0f, FRAMES_PLAIN, 3},
    {"blazepose33 clauser awkward", GS_LAYOUT_BLAZEPOSE33, GS_MASS_CLAUSER, GS_STATURE_NOSE_ANKLE_117, 0.5f, FRAMES_AWKWARD, 1},
    {"point", GS_LAYOUT_POINT, GS_MASS_DELEVA, GS_STATURE_ANTHRO, -1.0f, FRAMES_PLAIN, 3},
};

/* frame i of a case: its time (GS_T_NONE unknown) and keypoints */
static int64_t case_frame(const com_case *c, size_t i, gs_kp *kp)
{
    const gs_kpframe *f = &g_frames[i];
    int64_t t_us = gs_time_us_of_s(f->t_s);
    to_layout(c->layout, f->kp, kp);
    if (c->frames == FRAMES_AWKWARD) {
        if (i % 97 == 5) t_us = gs_time_us_of_s(g_frames[i - 1].t_s);  /* a repeat */
        if (i % 131 == 7) t_us = gs_time_us_of_s(g_frames[i - 3].t_s); /* a step back */
        if (i == 50) t_us = GS_T_NONE;
        if (i >= 200 && i < 215)  /* nobody in view */
            for (size_t k = 0; k < gs_layout_kp_count(c->layout); k++) kp[k] = (gs_kp){NAN, NAN, 0.0f};
        if (i >= 250) t_us += 3000000;  /* a gap of 3 s */
    }
    return t_us;
}

typedef enum { VIA_ONE_STEP, VIA_TWO_STEPS } entry;

static void run_case(const com_case *c, entry via, ev_log *log)
{
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.mass_table = c->mass;
    cfg.stature = c->stature;
    if (c->min_conf >= 0.0f) cfg.min_conf = c->min_conf;
    size_t bytes = gs_pipeline_storage_bytes(&cfg);
    void *store = malloc(bytes);
    gs_pipeline p;
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, c->layout, store, bytes, on_ev, log));
    gs_pipeline_set_trace(&p, true);  /* the samples and fits too */
    for (size_t i = 0; i < g_n; i++) {
        gs_kp kp[GS_KP_MAX];
        int64_t t_us = case_frame(c, i, kp);
        gs_status st;
        if (via == VIA_ONE_STEP) {
            st = gs_pipeline_push_keypoints_us(&p, t_us, kp);
        } else {
            gs_com_out com;
            st = gs_pipeline_com(&p, kp, &com);
            if (st == GS_OK) {
                /* exactly what the core's own COM gives for this config */
                gs_com_out ref;
                TEST_ASSERT_EQUAL(GS_OK, gs_com_compute(c->layout, cfg.mass_table, cfg.stature, cfg.min_conf, kp, &ref));
                TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&ref, &com, sizeof com, c->name);
                st = gs_pipeline_push_com_us(&p, t_us, kp, &com);
            }
        }
        log_status(log, i, st);
    }
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_flush(&p));
    gs_kp kp[GS_KP_MAX];
    int64_t t_end = case_frame(c, g_n - 1, kp) + 1000000;
    if (via == VIA_ONE_STEP) {
        log_status(log, g_n, gs_pipeline_push_keypoints_us(&p, t_end, kp));
    } else {
        gs_com_out com;
        TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_com(&p, kp, &com));
        log_status(log, g_n, gs_pipeline_push_com_us(&p, t_end, kp, &com));
    }
    free(store);
}

static size_t count_lines(const ev_log *l, const char *needle)
{
    size_t n = 0;
    for (const char *s = l->text; (s = strstr(s, needle)) != NULL; s++) n++;
    return n;
}

void test_two_steps_give_the_one_step_events(void)
{
    load_sample();
    for (size_t k = 0; k < sizeof k_cases / sizeof k_cases[0]; k++) {
        const com_case *c = &k_cases[k];
        ev_log one = {0}, two = {0};
        run_case(c, VIA_ONE_STEP, &one);
        run_case(c, VIA_TWO_STEPS, &two);
        /* the runs must have something to compare: samples, and jumps */
        TEST_ASSERT_TRUE_MESSAGE(count_lines(&one, "\"event\":\"sample\"") > 300, c->name);
        TEST_ASSERT_TRUE_MESSAGE(count_lines(&one, "\"event\":\"jump\"") >= c->min_jumps, c->name);
        if (c->frames == FRAMES_AWKWARD) {  /* the step back and the unknown time refused */
            TEST_ASSERT_TRUE_MESSAGE(count_lines(&one, gs_status_str(GS_EORDER)) >= 2, c->name);
            TEST_ASSERT_TRUE_MESSAGE(count_lines(&one, gs_status_str(GS_EINVAL)) == 1, c->name);
        }
        TEST_ASSERT_TRUE_MESSAGE(strstr(one.text, "\"event\":\"summary\"") != NULL, c->name);
        TEST_ASSERT_EQUAL_UINT64_MESSAGE(one.len, two.len, c->name);
        TEST_ASSERT_EQUAL_MEMORY_MESSAGE(one.text, two.text, one.len, c->name);
        free(one.text);
        free(two.text);
    }
}

/* The second step takes the COM it is given (it does not compute its own):
 * a COM moved by 10 px gives samples moved by 10 px. */
void test_push_com_uses_the_given_com(void)
{
    load_sample();
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    size_t bytes = gs_pipeline_storage_bytes(&cfg);
    void *store = malloc(bytes);
    gs_pipeline p;
    ev_log log = {0};
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_COCO17, store, bytes, on_ev, &log));
    gs_pipeline_set_trace(&p, true);
    gs_com_out com;
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_com(&p, g_frames[0].kp, &com));
    TEST_ASSERT_TRUE(isfinite(com.x_px) && com.w > 0.0f);
    gs_com_out moved = com;
    moved.x_px += 10.0f;
    log.len = 0;
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_com_us(&p, 1000, g_frames[0].kp, &moved));
    TEST_ASSERT_TRUE(log.len > 0);
    log.text[log.len - 1] = '\0';
    char want[64];
    snprintf(want, sizeof want, "\"x_px\":%.2f", (double)moved.x_px);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(log.text, want), log.text);
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_push_com_us(&p, 2000, g_frames[1].kp, NULL));
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_com(&p, NULL, &com));
    free(log.text);
    free(store);
}

/* A ring capacity the ring refuses (not a power of two) fails the init; the pipeline then
 * refuses every frame and the flush instead of using a ring it does not have. */
void test_failed_init_refuses_frames(void)
{
    load_sample();
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.ring_capacity = 100;
    size_t bytes = gs_pipeline_storage_bytes(&cfg);
    void *store = malloc(bytes);
    gs_pipeline p;
    ev_log log = {0};
    TEST_ASSERT_EQUAL(GS_EINVAL, gs_pipeline_init(&p, &cfg, GS_LAYOUT_COCO17, store, bytes, on_ev, &log));
    TEST_ASSERT_EQUAL(GS_ESTATE, gs_pipeline_push_keypoints_us(&p, 1000, g_frames[0].kp));
    TEST_ASSERT_EQUAL(GS_ESTATE, gs_pipeline_push_point_us(&p, 2000, 320.0f, 400.0f, 1.0f, 34.0f));
    TEST_ASSERT_EQUAL(GS_ESTATE, gs_pipeline_flush(&p));
    TEST_ASSERT_EQUAL(0, (int)log.len);
    free(log.text);
    free(store);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_two_steps_give_the_one_step_events);
    RUN_TEST(test_push_com_uses_the_given_com);
    RUN_TEST(test_failed_init_refuses_frames);
    return UNITY_END();
}
