/* test_session.c - visits (sessions): the state machine on its own, table-driven,
 * and the pipeline on the bundled simulated track (tests/data/sample_jumps.csv,
 * a 1.734 m subject with three jumps) replayed as two people: the same track
 * again after a gap with the body 20 % smaller in the image (someone else,
 * farther away) must start a second visit with its own stature and jumps; the
 * same change while the body stays in view (walking back) must not. */
#include "unity.h"
#include "gravscale/gravscale.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef GS_SOURCE_DIR
#define GS_SOURCE_DIR "."
#endif

void setUp(void) {}
void tearDown(void) {}

/* ---- the state machine alone ------------------------------------------------ */

typedef struct {
    double t_s;
    bool present;
    double stand_px;     /* NaN: not a standing frame */
    uint32_t want_bits;
    const char *want_reason;
} frame_case;

static void run_cases_absence(const frame_case *c, size_t n, int64_t absence_us)
{
    gs_session s;
    gs_session_init(&s, absence_us, 0.12);
    for (size_t i = 0; i < n; i++) {
        const char *why = NULL, *why2 = NULL;
        int64_t t_us = gs_time_us_of_s(c[i].t_s);
        uint32_t r = gs_session_frame(&s, t_us, c[i].present, c[i].stand_px, &why);
        if (r & GS_SESSION_ENDED) {  /* as the pipeline does: close, and a body in view starts the next */
            gs_session_close(&s);
            if (c[i].present) r |= gs_session_frame(&s, t_us, true, NAN, &why2);
        }
        char msg[64];
        snprintf(msg, sizeof msg, "case row %u (t %.2f)", (unsigned)i, c[i].t_s);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(c[i].want_bits, r, msg);
        if (c[i].want_reason)
            TEST_ASSERT_EQUAL_STRING_MESSAGE(c[i].want_reason, why, msg);
        else
            TEST_ASSERT_NULL_MESSAGE(why, msg);
    }
}

static void run_cases(const frame_case *c, size_t n) { run_cases_absence(c, n, 2500000); }

void test_absence_ends_and_return_starts(void)
{
    const frame_case c[] = {
        {0.0, false, NAN, 0, NULL},
        {0.1, true, NAN, GS_SESSION_STARTED, NULL},
        {0.2, true, 400, 0, NULL},
        {1.0, false, NAN, 0, NULL},
        {2.6, false, NAN, 0, NULL},                      /* 2.4 s unseen: not yet */
        {2.8, false, NAN, GS_SESSION_ENDED, "absence"},  /* 2.6 s */
        {3.8, false, NAN, 0, NULL},                      /* nobody: nothing more */
        {4.0, true, NAN, GS_SESSION_STARTED, NULL},
    };
    run_cases(c, sizeof c / sizeof c[0]);
}

/* The limits are whole microseconds: an absence of exactly 2.5 s ends, 1 us less does not;
 * an unknown time is ignored. */
void test_absence_limit_exact(void)
{
    gs_session s;
    gs_session_init(&s, 2500000, 0.12);
    TEST_ASSERT_TRUE(s.gap_us == 500000);  /* a gap: 0.5 s, or the absence when shorter */
    TEST_ASSERT_EQUAL_UINT32(GS_SESSION_STARTED, gs_session_frame(&s, 200000, true, NAN, NULL));
    TEST_ASSERT_EQUAL_UINT32(0, gs_session_frame(&s, GS_T_NONE, false, NAN, NULL));
    const char *why = "junk";
    TEST_ASSERT_EQUAL_UINT32(0, gs_session_frame(&s, 2699999, false, NAN, &why));
    TEST_ASSERT_NULL(why);
    TEST_ASSERT_EQUAL_UINT32(GS_SESSION_ENDED, gs_session_frame(&s, 2700000, false, NAN, &why));
    TEST_ASSERT_EQUAL_STRING("absence", why);
    gs_session_close(&s);
    TEST_ASSERT_EQUAL_UINT32(GS_SESSION_STARTED, gs_session_frame(&s, -GS_T_MAX_US, true, NAN, NULL));
    TEST_ASSERT_TRUE(s.t_start_us == -GS_T_MAX_US);
    TEST_ASSERT_EQUAL_UINT32(GS_SESSION_ENDED, gs_session_frame(&s, GS_T_MAX_US, false, NAN, &why));
    static const struct { int64_t absence_us, gap_us; } gaps[] = {
        {0, 0}, {1, 1}, {300000, 300000}, {499999, 499999}, {500000, 500000}, {500001, 500000}, {600000000, 500000},
    };
    for (size_t k = 0; k < sizeof gaps / sizeof gaps[0]; k++) {
        gs_session_init(&s, gaps[k].absence_us, 0.12);
        TEST_ASSERT_TRUE_MESSAGE(s.gap_us == gaps[k].gap_us, "gap row");
        TEST_ASSERT_TRUE(s.t_start_us == GS_T_NONE && s.t_seen_us == GS_T_NONE && isnan(s.ref_px));
    }
}

/* With an absence shorter than 0.5 s the gap is the absence: a body seen again after
 * exactly 0.3 s (and a new size) is someone else; after 0.3 s - 1 us it is not. */
void test_gap_is_the_shorter_absence(void)
{
    for (int k = 0; k < 2; k++) {
        gs_session s;
        gs_session_init(&s, 300000, 0.12);
        int64_t t = 0;
        TEST_ASSERT_EQUAL_UINT32(GS_SESSION_STARTED, gs_session_frame(&s, t, true, NAN, NULL));
        for (int i = 0; i < (int)GS_SESSION_REF_N; i++) gs_session_frame(&s, t += 33333, true, 400.0, NULL);
        t += k ? 300000 : 299999;
        uint32_t r = 0;
        const char *why = NULL;
        for (int i = 0; i < 6; i++, t += 33333) r |= gs_session_frame(&s, t, true, 320.0, &why);
        TEST_ASSERT_EQUAL_UINT32(k ? GS_SESSION_ENDED : 0u, r);
        if (k) TEST_ASSERT_EQUAL_STRING("new_body", why);
    }
}

void test_other_size_after_gap_is_a_new_body(void)
{
    frame_case c[40];
    size_t n = 0;
    c[n++] = (frame_case){0.0, true, NAN, GS_SESSION_STARTED, NULL};
    for (int i = 1; i <= 10; i++) c[n++] = (frame_case){0.1 * i, true, 400.0 + (i % 3), 0, NULL};
    /* a 1 s gap, then 5 frames 20 % smaller: not yet (noise is single frames) ... */
    for (int i = 0; i < 5; i++) c[n++] = (frame_case){2.0 + 0.1 * i, true, 320.0, 0, NULL};
    /* ... the sixth decides */
    c[n++] = (frame_case){2.5, true, 321.0, GS_SESSION_ENDED | GS_SESSION_STARTED, "new_body"};
    run_cases(c, n);
}

void test_size_change_in_view_or_small_is_the_same_body(void)
{
    frame_case c[80];
    size_t n = 0;
    c[n++] = (frame_case){0.0, true, NAN, GS_SESSION_STARTED, NULL};
    for (int i = 1; i <= 10; i++) c[n++] = (frame_case){0.1 * i, true, 400.0, 0, NULL};
    /* walking back while seen: 400 -> 320 px over 3 s, then standing there */
    for (int i = 1; i <= 30; i++) c[n++] = (frame_case){1.0 + 0.1 * i, true, 400.0 - 80.0 * i / 30.0, 0, NULL};
    for (int i = 1; i <= 10; i++) c[n++] = (frame_case){4.0 + 0.1 * i, true, 320.0, 0, NULL};
    run_cases(c, n);

    /* after a gap, a size within 12 % is the same person coming back */
    frame_case d[30];
    n = 0;
    d[n++] = (frame_case){0.0, true, NAN, GS_SESSION_STARTED, NULL};
    for (int i = 1; i <= 10; i++) d[n++] = (frame_case){0.1 * i, true, 400.0, 0, NULL};
    for (int i = 0; i < 10; i++) d[n++] = (frame_case){2.0 + 0.1 * i, true, 365.0, 0, NULL};
    run_cases(d, n);
}

/* ---- through the pipeline ---------------------------------------------------- */

#define MAX_ROWS 1000
static double g_t[MAX_ROWS];
static gs_kp g_kp[MAX_ROWS][17];
static int g_rows;

static void load_sample(void)
{
    if (g_rows) return;
    char path[512];
    snprintf(path, sizeof path, "%s/tests/data/sample_jumps.csv", GS_SOURCE_DIR);
    FILE *f = fopen(path, "r");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
    char line[4096];
    TEST_ASSERT_NOT_NULL(fgets(line, sizeof line, f)); /* header */
    while (g_rows < MAX_ROWS && fgets(line, sizeof line, f)) {
        char *p = line, *end;
        g_t[g_rows] = strtod(p, &end);
        for (int k = 0; k < 17; k++) {
            p = end + 1;
            double x = strtod(p, &end);
            p = end + 1;
            double y = strtod(p, &end);
            p = end + 1;
            double c = strtod(p, &end);
            g_kp[g_rows][k] = (gs_kp){(float)x, (float)y, (float)c};
        }
        g_rows++;
    }
    fclose(f);
    TEST_ASSERT_TRUE(g_rows > 300);
}

typedef struct {
    gs_event ev[64];
    int n;
} ev_log;

static void on_ev(void *ctx, const gs_event *ev)
{
    ev_log *l = (ev_log *)ctx;
    if (ev->type == GS_EV_SESSION && l->n < 64) l->ev[l->n++] = *ev;
}

/* Push the track scaled by s about the feet's line (cx, 1000 px) from t0. */
static void push_track(gs_pipeline *p, double t0, double s0, double s1)
{
    for (int i = 0; i < g_rows; i++) {
        double s = s0 + (s1 - s0) * i / (g_rows - 1);
        gs_kp kp[17];
        for (int k = 0; k < 17; k++) {
            kp[k] = g_kp[i][k];
            kp[k].x_px = (float)(960.0 + s * (kp[k].x_px - 960.0));
            kp[k].y_px = (float)(1000.0 + s * (kp[k].y_px - 1000.0));
        }
        TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_keypoints(p, t0 + g_t[i], kp));
    }
}

static void push_nobody(gs_pipeline *p, double t0, double dur_s)
{
    gs_kp kp[17];
    memset(kp, 0, sizeof kp);
    for (double t = 0.0; t < dur_s; t += 1.0 / 30.0) TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_push_keypoints(p, t0 + t, kp));
}

static void check_visit(const gs_ev_session *e, uint32_t id, const char *reason)
{
    char msg[96];
    snprintf(msg, sizeof msg, "session %u: stature %.4f, jumps %u, best %.3f, mean flight %.3f", (unsigned)e->session,
             e->stature_m, (unsigned)e->n_jumps, e->best_jump_m, e->mean_flight_s);
    printf("%s (%s)\n", msg, e->reason);
    TEST_ASSERT_EQUAL_UINT32(id, e->session);
    TEST_ASSERT_TRUE(e->ended);
    TEST_ASSERT_EQUAL_STRING(reason, e->reason);
    /* truth: 1.734 m, jumps (g T^2 / 8) 0.264 / 0.465 / 0.359 m, flights 0.464 / 0.616 / 0.541 s */
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(3, e->n_jumps, msg);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.06, 1.734, e->stature_m, msg);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.05, 0.465, e->best_jump_m, msg);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.04, (0.264 + 0.465 + 0.359) / 3.0, e->mean_jump_m, msg);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.033, (0.464 + 0.616 + 0.541) / 3.0, e->mean_flight_s, msg);
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.033, 0.616, e->best_flight_s, msg);
    TEST_ASSERT_TRUE(isfinite(e->mean_takeoff_velocity_m_s));
}

void test_pipeline_two_people(void)
{
    load_sample();
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    static double storage[8192];
    TEST_ASSERT_TRUE(gs_pipeline_storage_bytes(&cfg) <= sizeof storage);
    static gs_pipeline p;
    static ev_log log;
    memset(&log, 0, sizeof log);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_COCO17, storage, sizeof storage, on_ev, &log));
    push_track(&p, 0.0, 1.0, 1.0);
    /* 1 s away (shorter than the absence), back 20 % smaller: someone else */
    push_track(&p, g_t[g_rows - 1] + 1.0, 0.8, 0.8);
    push_nobody(&p, 2.0 * g_t[g_rows - 1] + 1.1, 3.0);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_flush(&p));
    TEST_ASSERT_EQUAL_INT(4, log.n);
    TEST_ASSERT_FALSE(log.ev[0].u.session.ended);
    check_visit(&log.ev[1].u.session, 1, "new_body");
    TEST_ASSERT_FALSE(log.ev[2].u.session.ended);
    TEST_ASSERT_EQUAL_UINT32(2, log.ev[2].u.session.session);
    check_visit(&log.ev[3].u.session, 2, "absence");
}

void test_pipeline_walking_back_stays_one_visit(void)
{
    load_sample();
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    static double storage[8192];
    static gs_pipeline p;
    static ev_log log;
    memset(&log, 0, sizeof log);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_COCO17, storage, sizeof storage, on_ev, &log));
    push_track(&p, 0.0, 1.0, 0.8);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_flush(&p));
    TEST_ASSERT_EQUAL_INT(2, log.n);
    TEST_ASSERT_EQUAL_STRING("end_of_stream", log.ev[1].u.session.reason);
    TEST_ASSERT_EQUAL_UINT32(1, log.ev[1].u.session.session);
}

void test_ball_has_no_sessions(void)
{
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    static double storage[8192];
    static gs_pipeline p;
    static ev_log log;
    memset(&log, 0, sizeof log);
    TEST_ASSERT_EQUAL(GS_OK, gs_pipeline_init(&p, &cfg, GS_LAYOUT_POINT, storage, sizeof storage, on_ev, &log));
    for (int i = 0; i < 100; i++) gs_pipeline_push_point(&p, i / 30.0, 100.0f, 100.0f, 1.0f, 20.0f);
    gs_pipeline_flush(&p);
    TEST_ASSERT_EQUAL_INT(0, log.n);
}

void test_session_lines(void)
{
    gs_session s;
    gs_session_init(&s, 2500000, 0.12);
    gs_session_frame(&s, 1500000, true, NAN, NULL);
    gs_ev_jump j;
    memset(&j, 0, sizeof j);
    j.accepted = true;
    j.jump_height_m = 0.40;
    j.flight_time_s = 0.571;
    j.takeoff_velocity_m_s = 2.80;
    gs_session_jump(&s, &j);
    j.jump_height_m = 0.30;
    j.flight_time_s = 0.495;
    j.takeoff_velocity_m_s = 2.43;
    gs_session_jump(&s, &j);
    j.accepted = false;
    gs_session_jump(&s, &j);
    gs_session_frame(&s, 9250000, true, NAN, NULL);
    gs_ev_height h = {0, 1.7512, 1.7301, 1.7723, 2, 1};
    gs_event ev;
    gs_session_event(&s, true, "absence", &h, 0, &ev);
    char buf[GS_EMIT_MAX];
    gs_emit_json(&ev, buf, sizeof buf);
    TEST_ASSERT_EQUAL_STRING("{\"event\":\"session\",\"track\":0,\"session\":1,\"state\":\"end\",\"reason\":\"absence\","
                             "\"t_start_s\":1.5000,\"t_end_s\":9.2500,\"stature_m\":1.7512,\"ci95_m\":[1.7301,1.7723],"
                             "\"n_jumps\":2,\"n_rejected\":1,\"best_jump_m\":0.4000,\"mean_jump_m\":0.3500,"
                             "\"best_flight_s\":0.5710,\"mean_flight_s\":0.5330,\"mean_takeoff_velocity_m_s\":2.615}\n",
                             buf);
    size_t n = gs_emit_nmea(&ev, buf, sizeof buf);
    TEST_ASSERT_TRUE(n > 0 && n <= 82);
    TEST_ASSERT_EQUAL_STRING_LEN("$GSSES,1,E,A,1.500,9.250,1.751,2,0.400,0.350,0.533*", buf, n - 4);
    gs_session_event(&s, false, NULL, NULL, 3, &ev);
    gs_emit_json(&ev, buf, sizeof buf);
    TEST_ASSERT_NOT_NULL(strstr(buf, "\"track\":3,\"session\":1,\"state\":\"start\",\"reason\":null,\"t_start_s\":1.5000,\"t_end_s\":null"));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_absence_ends_and_return_starts);
    RUN_TEST(test_absence_limit_exact);
    RUN_TEST(test_gap_is_the_shorter_absence);
    RUN_TEST(test_other_size_after_gap_is_a_new_body);
    RUN_TEST(test_size_change_in_view_or_small_is_the_same_body);
    RUN_TEST(test_pipeline_two_people);
    RUN_TEST(test_pipeline_walking_back_stays_one_visit);
    RUN_TEST(test_ball_has_no_sessions);
    RUN_TEST(test_session_lines);
    return UNITY_END();
}
