/* cmd_replay.c - `gravscale replay`: recorded keypoints -> core pipeline ->
 * JSON Lines / NMEA on stdout (one write per line), optional trace file. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "gravscale/gravscale.h"
#include "app_common.h"
#include "ev_behind.h"
#include "gs_kpread.h"
#include "gs_out.h"
#include "gs_profile.h"
#include "kp_ahead.h"

/* Declared in main.c as well (no app header yet). */
int gs_cmd_replay(int argc, char **argv);

enum { EXIT_OK = GS_EXIT_OK, EXIT_DATA = GS_EXIT_DATA, EXIT_USAGE = GS_EXIT_USAGE, EXIT_IO = GS_EXIT_IO };

#define PREFETCH_FRAMES 32          /* frames whose intervals give fps_source */
#define TRACE_BUF_BYTES (1u << 16)

static const char REPLAY_HELP[] =
    "usage: gravscale replay --keypoints FILE [OPTIONS]\n"
    "\n"
    "Replay recorded keypoints through the gravscale core and print every jump,\n"
    "the running height and a final summary as JSON Lines (or NMEA sentences).\n"
    "\n"
    "  --keypoints FILE     input: a CSV file, an AlphaPose result list (.json) or an\n"
    "                       OpenPose output folder\n"
    "  --format F           csv | alphapose | openpose (default: csv; a folder means\n"
    "                       openpose and a *.json file alphapose)\n"
    "  --layout L           coco17 | blazepose33 | point: the CSV header must match it\n"
    "                       (default: taken from the header)\n"
    "  --fps N              frame rate: required for alphapose/openpose and for a CSV\n"
    "                       with a 'frame' column; refused for a CSV with 't'\n"
    "  --config FILE        key = value configuration, section [core]\n"
    "  --output-format F    json | nmea (default: json, or [core] format)\n"
    "  --trace FILE         also write every event, trace events included, as JSON\n"
    "                       Lines to FILE\n"
    "  --track N            alphapose/openpose: follow the person with this track id\n"
    "                       (default: the largest person of the first frames)\n"
    "  --help               this text\n"
    "\n"
    "CSV: header t,x0,y0,c0,...,x16,y16,c16 (COCO-17), the same with 33 points\n"
    "(BlazePose-33) or t,x,y,c[,size] (one point, size = object diameter in px).\n"
    "t in seconds, pixels with y down, c in 0..1 (0 = missing; then x,y may be\n"
    "empty). A missing frame is an absent row.\n"
    "\n"
    "Exit codes: 0 ok, 1 bad input data, 2 usage or config error, 3 I/O error\n"
    "writing output.\n";

typedef struct {
    gs_format fmt;
    gs_out out;
    gs_out trace;
    bool trace_on;
    uint32_t emit_fail;       /* events the emitter could not format */
    uint64_t refused;         /* frames the pipeline refused (not expected: times are checked) */
    gs_status first_refusal;
    ev_behind *behind;        /* events written in a second thread, NULL: here */
    atomic_bool out_failed;   /* out.err is set: the run stops (read while behind writes) */
} replay_app;

static bool is_trace_event(gs_event_type t)
{
    return t == GS_EV_STATE || t == GS_EV_SAMPLE || t == GS_EV_FIT;
}

static void on_event(void *ctx, const gs_event *ev)
{
    replay_app *a = ctx;
    char buf[GS_EMIT_MAX];
    if (a->trace_on) {
        size_t n = gs_emit_json(ev, buf, sizeof buf);
        if (n > 0)
            gs_out_line(&a->trace, buf, n);
        else
            a->emit_fail++;
    }
    if (is_trace_event(ev->type))
        return;
    size_t n = gs_emit(a->fmt, ev, buf, sizeof buf);
    if (n > 0)
        gs_out_line(&a->out, buf, n);
    else
        a->emit_fail++;
    if (a->out.err)
        atomic_store_explicit(&a->out_failed, true, memory_order_relaxed);
}

/* The pipeline's events: to the writer thread while there is one. */
static void route_event(void *ctx, const gs_event *ev)
{
    replay_app *a = ctx;
    if (a->behind)
        ev_behind_put(a->behind, ev);
    else
        on_event(a, ev);
}

static bool output_failed(const replay_app *a)
{
    return atomic_load_explicit(&a->out_failed, memory_order_relaxed);
}

/* ---- options ------------------------------------------------------------ */

typedef struct {
    const char *keypoints;
    const char *config;
    const char *trace;
    bool format_set;
    bool out_format_set;
    gs_format out_format;
    gs_kpread_opts kp;
} replay_opts;

static int usage_error(const char *fmt, const char *arg)
{
    return gs_app_usage_error("replay", fmt, arg);
}

/* Returns -1 to go on, else an exit code (help or usage error). */
static int parse_args(int argc, char **argv, replay_opts *o)
{
    memset(o, 0, sizeof *o);
    gs_kpread_opts_default(&o->kp);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(REPLAY_HELP, stdout);
            return fflush(stdout) == 0 ? EXIT_OK : EXIT_IO;
        }
        if (strncmp(a, "--", 2) != 0)
            return usage_error("unexpected argument '%s'", a);
        static const char *const known[] = {"--keypoints", "--format", "--layout",
                                            "--fps",       "--config", "--output-format",
                                            "--trace",     "--track"};
        char name[32];
        const char *val;
        int rc = gs_app_option("replay", argc, argv, &i, known, sizeof known / sizeof known[0], name,
                               sizeof name, &val);
        if (rc >= 0)
            return rc;
        if (strcmp(name, "--keypoints") == 0) {
            o->keypoints = val;
        } else if (strcmp(name, "--config") == 0) {
            o->config = val;
        } else if (strcmp(name, "--trace") == 0) {
            o->trace = val;
        } else if (strcmp(name, "--format") == 0) {
            if (!gs_kp_format_from_name(val, &o->kp.format))
                return usage_error("--format must be csv, alphapose or openpose, not '%s'", val);
            o->format_set = true;
        } else if (strcmp(name, "--layout") == 0) {
            if (!gs_layout_from_name(val, strlen(val), &o->kp.layout))
                return usage_error("--layout must be coco17, blazepose33 or point, not '%s'", val);
            o->kp.layout_set = true;
        } else if (strcmp(name, "--output-format") == 0) {
            if (!gs_format_from_name(val, strlen(val), &o->out_format))
                return usage_error("--output-format must be json or nmea, not '%s'", val);
            o->out_format_set = true;
        } else if (strcmp(name, "--fps") == 0) {
            double fps;
            if (!gs_num_parse(val, strlen(val), &fps) || !(fps > 0.0) || !(fps <= 100000.0))
                return usage_error("--fps must be a positive number of frames per second, not '%s'",
                                   val);
            o->kp.fps = fps;
        } else { /* --track */
            long tr;
            if (!gs_num_parse_int(val, strlen(val), &tr) || tr < 0)
                return usage_error("--track must be a track id >= 0, not '%s'", val);
            o->kp.track = tr;
        }
    }
    if (!o->keypoints)
        return usage_error("%s", "--keypoints FILE is required");
    if (!o->format_set) {
        /* a folder is OpenPose output, a .json file an AlphaPose result list */
        struct stat sb;
        size_t l = strlen(o->keypoints);
        if (stat(o->keypoints, &sb) == 0 && S_ISDIR(sb.st_mode))
            o->kp.format = GS_KPF_OPENPOSE;
        else if (l > 5 && strcmp(o->keypoints + l - 5, ".json") == 0)
            o->kp.format = GS_KPF_ALPHAPOSE;
    }
    if (o->kp.track >= 0 && o->kp.format == GS_KPF_CSV)
        return usage_error("%s", "--track applies to alphapose/openpose input only");
    return -1;
}

/* ---- config ------------------------------------------------------------- */

static int load_config(const char *path, gs_core_config *cfg)
{
    gs_core_config_default(cfg);
    if (!path)
        return EXIT_OK;
    size_t n;
    char *text = gs_profile_read("gravscale", path, &n);
    if (!text)
        return EXIT_USAGE;
    /* [core]; the other sections of a profile belong to video and cam (gs_profile.h) */
    gs_cfg_section sections[1 + GS_PROFILE_SECTIONS];
    static const char *const own[] = {"core"};
    sections[0] = (gs_cfg_section){"core", gs_core_config_set, cfg};
    size_t n_sections = 1 + gs_profile_foreign_sections(own, 1, sections + 1, GS_PROFILE_SECTIONS);
    gs_cfg_error e;
    memset(&e, 0, sizeof e);
    gs_status st = gs_cfg_parse(text, n, sections, n_sections, &e);
    free(text);
    if (st == GS_OK) {
        memset(&e, 0, sizeof e);
        st = gs_core_config_check(cfg, &e);
    }
    if (st != GS_OK) {
        gs_profile_print_error("gravscale", path, &e);
        return EXIT_USAGE;
    }
    return EXIT_OK;
}

/* ---- progress (only on a terminal) -------------------------------------- */

typedef struct {
    bool on, shown;
    double next_s;
} progress;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void progress_tick(progress *pg, const gs_kpread *r, const kp_ahead *ahead, uint64_t frames)
{
    double t = now_s();
    if (t < pg->next_s)
        return;
    pg->next_s = t + 0.25; /* at most four updates a second */
    uint64_t done, total;
    if (ahead)
        kp_ahead_progress(ahead, &done, &total);
    else
        gs_kpread_progress(r, &done, &total);
    if (total > 0)
        fprintf(stderr, "\rgravscale: %llu frames (%3.0f%%)", (unsigned long long)frames,
                100.0 * (double)done / (double)total);
    else
        fprintf(stderr, "\rgravscale: %llu frames", (unsigned long long)frames);
    pg->shown = true;
}

static void progress_clear(progress *pg)
{
    if (pg->shown)
        fputs("\r                                        \r", stderr);
    pg->shown = false;
}

/* ---- the run ------------------------------------------------------------ */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Frame rate from the first frames: the median interval (robust to dropped
 * frames), then the mean of the intervals within 25 % of it (averages away the
 * rounding of printed timestamps). NaN with fewer than 2 frames. */
static double fps_from_times(const gs_kpframe *f, size_t n)
{
    double d[PREFETCH_FRAMES];
    size_t m = 0;
    for (size_t i = 1; i < n && m < PREFETCH_FRAMES; i++)
        d[m++] = f[i].t_s - f[i - 1].t_s;
    if (m == 0)
        return NAN;
    qsort(d, m, sizeof d[0], cmp_double);
    double med = m % 2 ? d[m / 2] : 0.5 * (d[m / 2 - 1] + d[m / 2]);
    if (!(med > 0.0))
        return NAN;
    double sum = 0.0;
    size_t k = 0;
    for (size_t i = 0; i < m; i++) {
        if (fabs(d[i] - med) <= 0.25 * med) {
            sum += d[i];
            k++;
        }
    }
    return (double)k / sum;
}

/* com: the frame's COM from the reader's thread, NULL to compute it here. */
static void push_frame(replay_app *a, gs_pipeline *p, gs_layout layout, const gs_kpframe *f,
                       const kp_ahead_com *com)
{
    gs_status st;
    if (layout == GS_LAYOUT_POINT)
        st = gs_pipeline_push_point(p, f->t_s, f->kp[0].x_px, f->kp[0].y_px, f->kp[0].c,
                                    f->size_px);
    else if (com)
        st = com->st != GS_OK ? com->st : gs_pipeline_push_com(p, f->t_s, f->kp, &com->out);
    else
        st = gs_pipeline_push_keypoints(p, f->t_s, f->kp);
    if (st != GS_OK && a->refused++ == 0)
        a->first_refusal = st;
}

static int output_status(const replay_app *a)
{
    if (a->out.err) {
        if (a->out.err != EPIPE) /* the reader went away: quietly */
            fprintf(stderr, "gravscale: writing output: %s\n", strerror(a->out.err));
        return EXIT_IO;
    }
    if (a->trace_on && a->trace.err) {
        fprintf(stderr, "gravscale: writing the trace: %s\n", strerror(a->trace.err));
        return EXIT_IO;
    }
    return EXIT_OK;
}

int gs_cmd_replay(int argc, char **argv)
{
    replay_opts o;
    int rc = parse_args(argc, argv, &o);
    if (rc >= 0)
        return rc;

    gs_core_config cfg;
    rc = load_config(o.config, &cfg);
    if (rc != EXIT_OK)
        return rc;

    signal(SIGPIPE, SIG_IGN); /* a closed pipe shows as EPIPE on write */

    gs_kpread_error kerr;
    memset(&kerr, 0, sizeof kerr);
    gs_kpread *rd = gs_kpread_open(o.keypoints, &o.kp, &kerr);
    if (!rd) {
        fprintf(stderr, "gravscale: %s\n", kerr.text);
        return kerr.status == GS_KPR_EUSAGE ? EXIT_USAGE : EXIT_DATA;
    }
    gs_layout layout = gs_kpread_layout(rd);

    replay_app app;
    memset(&app, 0, sizeof app);
    atomic_init(&app.out_failed, false);
    app.fmt = o.out_format_set ? o.out_format : cfg.format;
    gs_out_open_fd(&app.out, STDOUT_FILENO, 0);
    if (o.trace) {
        if (gs_out_open_path(&app.trace, o.trace, TRACE_BUF_BYTES) != 0) {
            fprintf(stderr, "gravscale: %s: cannot write the trace: %s\n", o.trace,
                    strerror(app.trace.err ? app.trace.err : errno));
            gs_kpread_close(rd);
            return EXIT_IO;
        }
        app.trace_on = true;
    }

    size_t store_bytes = gs_pipeline_storage_bytes(&cfg);
    void *store = malloc(store_bytes ? store_bytes : 1);
    gs_pipeline *pl = malloc(sizeof *pl);
    gs_kpframe *pre = malloc(PREFETCH_FRAMES * sizeof *pre);
    gs_status st = GS_ENOMEM;
    if (store && pl && pre)
        st = gs_pipeline_init(pl, &cfg, layout, store, store_bytes, route_event, &app);
    if (st != GS_OK) {
        fprintf(stderr, "gravscale: cannot start the pipeline: %s\n", gs_status_str(st));
        rc = EXIT_USAGE;
        goto done;
    }
    gs_pipeline_set_trace(pl, app.trace_on);

    /* the first frames give the source frame rate for the start event */
    size_t npre = 0;
    gs_kpr_status ks = GS_KPR_FRAME;
    while (npre < PREFETCH_FRAMES) {
        ks = gs_kpread_next(rd, &pre[npre], &kerr);
        if (ks != GS_KPR_FRAME)
            break;
        npre++;
    }
    const char *origin = gs_kpread_fps_origin(rd);
    gs_event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_START;
    ev.u.start.version = GS_VERSION;
    ev.u.start.config = o.config ? o.config : "default";
    ev.u.start.fps_source = strcmp(origin, "cli") == 0 ? o.kp.fps : fps_from_times(pre, npre);
    ev.u.start.fps_origin = origin;
    ev.u.start.layout = gs_layout_name(layout);
    on_event(&app, &ev);

    progress pg = {isatty(STDERR_FILENO) != 0, false, now_s() + 0.25};
    uint64_t frames = 0;
    for (size_t i = 0; i < npre && !output_failed(&app); i++, frames++)
        push_frame(&app, pl, layout, &pre[i], NULL);
    kp_ahead *ahead = NULL;
    if (ks == GS_KPR_FRAME) {
        /* a file is read ahead in a second thread, which computes the COM too, and its events
         * are written in a third; a pipe or a terminal is read frame by frame and its events
         * written here, so that each frame's events leave as soon as its line arrives */
        uint64_t done_bytes, total_bytes;
        gs_kpread_progress(rd, &done_bytes, &total_bytes);
        if (total_bytes > 0) {
            ahead = kp_ahead_start(rd, layout == GS_LAYOUT_POINT ? NULL : pl);
            if (ahead)
                app.behind = ev_behind_start(on_event, &app);
        }
        while (!output_failed(&app)) {
            const gs_kpframe *f = &pre[0];
            const kp_ahead_com *com = NULL;
            ks = ahead ? kp_ahead_next(ahead, &f, &com, &kerr) : gs_kpread_next(rd, &pre[0], &kerr);
            if (ks != GS_KPR_FRAME)
                break;
            push_frame(&app, pl, layout, f, com);
            frames++;
            if (pg.on && (frames & 4095u) == 0)
                progress_tick(&pg, rd, ahead, frames);
        }
    }
    kp_ahead_stop(ahead);
    ev_behind_stop(app.behind);
    app.behind = NULL;
    progress_clear(&pg);
    if (app.out.err) {
        rc = output_status(&app);
        goto done;
    }
    if (ks < 0) {
        /* bad input: report it, no summary (the pipeline is not flushed) */
        gs_out_flush(&app.trace);
        fprintf(stderr, "gravscale: %s\n", kerr.text);
        rc = output_status(&app);
        if (rc == EXIT_OK)
            rc = ks == GS_KPR_EUSAGE ? EXIT_USAGE : EXIT_DATA;
        goto done;
    }
    gs_pipeline_flush(pl);
    if (app.refused)
        fprintf(stderr, "gravscale: %llu frames refused by the pipeline (first: %s)\n",
                (unsigned long long)app.refused, gs_status_str(app.first_refusal));
    if (app.emit_fail)
        fprintf(stderr, "gravscale: %u events could not be formatted\n", (unsigned)app.emit_fail);
    rc = output_status(&app);

done:
    if (app.trace_on && gs_out_close(&app.trace) != 0 && rc == EXIT_OK) {
        fprintf(stderr, "gravscale: writing the trace: %s\n", strerror(app.trace.err));
        rc = EXIT_IO;
    }
    gs_out_close(&app.out);
    free(pre);
    free(pl);
    free(store);
    gs_kpread_close(rd);
    return rc;
}
