/* fuzz_emit.c - libFuzzer harness for the core's emitter (src/core/gs_emit.c):
 * random events, any value bit pattern (gs_real), any int64 time (GS_T_NONE too), any counts, any caller strings, into
 * exact-size heap buffers of every interesting capacity. Properties: never a
 * byte past cap; all or nothing (0 and "" when it does not fit, else the same
 * line at every larger cap); JSON Lines always one valid JSON object in valid
 * UTF-8 ending in '\n'; NMEA always "$GS...*HH\r\n" with a correct checksum in
 * <= 82 characters; events with the core's own short strings always fit
 * GS_EMIT_MAX. Built by tests/fuzz/run.sh (clang), not by CMake. */
#include "gravscale/gravscale.h"
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define STR_MAX 48

/* emit at cap into an exact-size heap buffer (ASan sees any overrun) and compare with the reference line */
static void at_cap(gs_format fmt, const gs_event *ev, size_t cap, const char *ref, size_t ref_n)
{
    char *b = malloc(cap ? cap : 1);
    FZ_CHECK(b != NULL);
    if (cap) memset(b, 0x5a, cap);
    size_t n = gs_emit(fmt, ev, cap ? b : NULL, cap);
    if (ref_n > 0 && cap > ref_n) {
        FZ_CHECK(n == ref_n && memcmp(b, ref, n + 1) == 0);
    } else {
        FZ_CHECK(n == 0);
        if (cap) FZ_CHECK(b[0] == '\0');
    }
    free(b);
}

/* string check for the GS_EMIT_MAX property: the core's own strings are short ASCII names */
static const char *str_ok(const char *s, bool *short_strings)
{
    if (!s) return s;
    size_t n = strlen(s);
    if (n > 24) *short_strings = false;
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || (unsigned char)s[i] > 0x7e) *short_strings = false;
    return s;
}

/* any int64 microseconds: GS_T_NONE, the limits and beyond them, and everything between */
static int64_t fz_time(fz_in *in)
{
    static const int64_t edge[] = {GS_T_NONE, INT64_MIN + 1, INT64_MAX, GS_T_MAX_US, -GS_T_MAX_US, 0, -1, -500, 500};
    uint8_t sel = fz_u8(in);
    if (sel < sizeof edge / sizeof edge[0]) return edge[sel];
    uint64_t hi = fz_u32(in), lo = fz_u32(in);
    return (int64_t)(hi << 32 | lo);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in in = {data, size};
    static char str[8][STR_MAX + 1];
    gs_event ev;
    memset(&ev, 0, sizeof ev);
    /* every event type, and one past the last: not an event type */
    enum { N_TYPES = GS_EV_FIT + 1 };
    uint8_t type = (uint8_t)(fz_u8(&in) % (N_TYPES + 1u));
    ev.type = (gs_event_type)type;
    bool short_strings = true;      /* every string printable ASCII of <= 24 bytes, like the core's own */
#define STR(i) (str_ok(fz_str(&in, str[i], STR_MAX), &short_strings))
    switch (ev.type) {
    case GS_EV_START: {
        gs_ev_start *s = &ev.u.start;
        s->version = STR(0);
        s->config = STR(1);
        s->fps_source = (gs_real)fz_double(&in);
        s->fps_origin = STR(2);
        s->layout = STR(3);
        break;
    }
    case GS_EV_JUMP: {
        gs_ev_jump *j = &ev.u.jump;
        j->track = fz_u32(&in);
        j->index = fz_u32(&in);
        j->t_takeoff_us = fz_time(&in);
        j->t_land_us = fz_time(&in);
        j->t_apex_us = fz_time(&in);
        gs_real *d[] = {&j->flight_time_s, &j->a_px_s2, &j->a_px_se_s2, &j->g_dir_deg, &j->q_m_per_px,
                        &j->size_px, &j->height_m, &j->height_se_m, &j->jump_height_m, &j->takeoff_velocity_m_s,
                        &j->com_rise_m, &j->contact_time_s, &j->rsi, &j->rms_px};
        for (size_t i = 0; i < sizeof d / sizeof d[0]; i++) *d[i] = (gs_real)fz_double(&in);
        j->n_samples = fz_u32(&in);
        j->n_outliers = fz_u32(&in);
        j->accepted = fz_u8(&in) & 1u;
        j->reason = (gs_reject_reason)(fz_u8(&in) % 12u); /* beyond the enum too */
        j->warnings = fz_u32(&in);
        break;
    }
    case GS_EV_HEIGHT:
    case GS_EV_SUMMARY: {
        gs_ev_height *h = &ev.u.height;
        h->track = fz_u32(&in);
        h->height_m = (gs_real)fz_double(&in);
        h->ci95_lo_m = (gs_real)fz_double(&in);
        h->ci95_hi_m = (gs_real)fz_double(&in);
        h->n_jumps = fz_u32(&in);
        h->n_rejected = fz_u32(&in);
        break;
    }
    case GS_EV_SESSION: {
        gs_ev_session *e = &ev.u.session;
        e->track = fz_u32(&in);
        e->session = fz_u32(&in);
        e->ended = fz_u8(&in) & 1u;
        e->reason = STR(4);
        e->t_start_us = fz_time(&in);
        e->t_end_us = fz_time(&in);
        gs_real *d[] = {&e->stature_m, &e->ci95_lo_m, &e->ci95_hi_m, &e->best_jump_m, &e->mean_jump_m,
                        &e->best_flight_s, &e->mean_flight_s, &e->mean_takeoff_velocity_m_s};
        for (size_t i = 0; i < sizeof d / sizeof d[0]; i++) *d[i] = (gs_real)fz_double(&in);
        e->n_jumps = fz_u32(&in);
        e->n_rejected = fz_u32(&in);
        break;
    }
    case GS_EV_WARNING:
        ev.u.warning.track = fz_u32(&in);
        ev.u.warning.t_us = fz_time(&in);
        ev.u.warning.warnings = fz_u32(&in);
        break;
    case GS_EV_STATE:
        ev.u.state.t_us = fz_time(&in);
        ev.u.state.from = STR(5);
        ev.u.state.to = STR(6);
        break;
    case GS_EV_SAMPLE: {
        gs_ev_sample *s = &ev.u.sample;
        s->t_us = fz_time(&in);
        s->x_px = (float)fz_double(&in);
        s->y_px = (float)fz_double(&in);
        s->w = (float)fz_double(&in);
        s->size_px = (float)fz_double(&in);
        s->upright = (float)fz_double(&in);
        break;
    }
    case GS_EV_FIT: {
        gs_ev_fit *f = &ev.u.fit;
        f->t_first_us = fz_time(&in);
        f->t_last_us = fz_time(&in);
        f->n = fz_u32(&in);
        f->a_px_s2 = (gs_real)fz_double(&in);
        f->g_dir_deg = (gs_real)fz_double(&in);
        f->rms_px = (gs_real)fz_double(&in);
        f->purpose = STR(7);
        break;
    }
    default: break;
    }

    for (int fmt = 0; fmt < 2; fmt++) {
        static char ref[8192];
        size_t n = gs_emit((gs_format)fmt, &ev, ref, sizeof ref);
        if (type == N_TYPES) FZ_CHECK(n == 0 && ref[0] == '\0');
        if (getenv("FZ_PRINT")) fprintf(stderr, "%zu: %s", n, ref); /* to look at one input */
        bool has_nmea = type <= GS_EV_WARNING; /* trace events have no sentence */
        if (fmt == GS_FMT_JSON && type < N_TYPES) {
            FZ_CHECK(n > 0); /* any event fits a large buffer */
            fz_check_json_line(ref, n);
            if (short_strings) FZ_CHECK(n < GS_EMIT_MAX); /* the caller's buffer size is enough */
        }
        if (fmt == GS_FMT_NMEA && type < N_TYPES) {
            if (has_nmea) fz_check_nmea_line(ref, n);
            else FZ_CHECK(n == 0 && ref[0] == '\0');
        }
        /* all or nothing at every cap around the line's size, and a few small ones */
        size_t caps[] = {0, 1, 2, 7, n, n + 1, n + 2, GS_EMIT_MAX};
        for (size_t i = 0; i < sizeof caps / sizeof caps[0]; i++) at_cap((gs_format)fmt, &ev, caps[i], ref, n);
    }
    return 0;
}

