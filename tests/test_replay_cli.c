/* test_replay_cli.c - runs the built `gravscale` program (GS_PROGRAM) on small
 * files written by the test: exit codes, the one-line stderr message, valid
 * JSON Lines on stdout with no summary after an input error, NMEA checksums,
 * the trace file, EPIPE and a full disk, and the height of a simulated ball
 * (diameter 0.22 m at 0.005 m/px under g = 9.81) against its truth. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "unity.h"
#include "gs_json_tok.h"

#ifndef GS_PROGRAM
#error "GS_PROGRAM (path of the gravscale program) must be defined"
#endif

extern char **environ;

static char g_dir[128];
static char g_ball[256], g_cfg[256];
static int g_seq;

#define BALL_DIAMETER_M 0.22
#define Q_M_PER_PX 0.005
#define G_M_S2 9.81
#define FPS 60.0
#define N_THROWS 3

void setUp(void) {}
void tearDown(void) {}

typedef struct {
    int code;          /* exit code, or 128 + signal */
    char *out, *err;   /* NUL-terminated */
    size_t out_len, err_len;
} run_result;

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
    size_t cap = 1 << 16, n = 0;
    char *b = malloc(cap + 1);
    for (;;) {
        n += fread(b + n, 1, cap - n, f);
        if (n < cap)
            break;
        cap *= 2;
        b = realloc(b, cap + 1);
        TEST_ASSERT_NOT_NULL(b);
    }
    fclose(f);
    b[n] = '\0';
    *len = n;
    return b;
}

/* Run GS_PROGRAM with args (NULL-terminated, without argv[0]). stdout_fd >= 0:
 * that descriptor becomes the child's stdout instead of a capture file. */
static void run_io(const char *const *args, int stdin_fd, int stdout_fd, run_result *r)
{
    char outp[256], errp[256];
    snprintf(outp, sizeof outp, "%s/run%03d.out", g_dir, g_seq);
    snprintf(errp, sizeof errp, "%s/run%03d.err", g_dir, g_seq++);
    const char *argv[32];
    int n = 0;
    argv[n++] = GS_PROGRAM;
    for (int i = 0; args[i]; i++)
        argv[n++] = args[i];
    argv[n] = NULL;
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    if (stdin_fd >= 0)
        posix_spawn_file_actions_adddup2(&fa, stdin_fd, STDIN_FILENO);
    if (stdout_fd >= 0)
        posix_spawn_file_actions_adddup2(&fa, stdout_fd, STDOUT_FILENO);
    else
        posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, outp, O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
    posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, errp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid;
    int rc = posix_spawn(&pid, GS_PROGRAM, &fa, NULL, (char *const *)argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, rc, "posix_spawn " GS_PROGRAM);
    int status;
    TEST_ASSERT_EQUAL_INT(pid, waitpid(pid, &status, 0));
    r->code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (stdout_fd >= 0) {
        r->out = calloc(1, 1);
        r->out_len = 0;
    } else {
        r->out = slurp(outp, &r->out_len);
    }
    r->err = slurp(errp, &r->err_len);
}

static void run_fd(const char *const *args, int stdout_fd, run_result *r) { run_io(args, -1, stdout_fd, r); }

static void run(const char *const *args, run_result *r) { run_io(args, -1, -1, r); }

static void run_free(run_result *r)
{
    free(r->out);
    free(r->err);
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
    fputs(text, f);
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
}

/* ---- checks on the output ---------------------------------------------- */

/* Every line is one JSON object and ends in '\n'; returns the line count. */
static int assert_json_lines(const char *s, size_t len)
{
    if (len > 0)
        TEST_ASSERT_EQUAL_INT_MESSAGE('\n', s[len - 1], "output ends in a half-written line");
    int lines = 0;
    const char *p = s, *e = s + len;
    while (p < e) {
        const char *nl = memchr(p, '\n', (size_t)(e - p));
        TEST_ASSERT_NOT_NULL(nl);
        gs_jlex l;
        gs_jtok t;
        gs_jlex_init(&l, p, (size_t)(nl - p));
        TEST_ASSERT_EQUAL_INT_MESSAGE(GS_JT_OBJ, gs_jlex_next(&l, &t), p);
        TEST_ASSERT_TRUE_MESSAGE(gs_jlex_skip(&l, &t), p);
        TEST_ASSERT_EQUAL_INT_MESSAGE(GS_JT_EOF, gs_jlex_next(&l, &t), p);
        lines++;
        p = nl + 1;
    }
    return lines;
}

static int count_substr(const char *s, const char *sub)
{
    int n = 0;
    for (const char *p = strstr(s, sub); p; p = strstr(p + 1, sub))
        n++;
    return n;
}

/* The number after "key": in the last line containing `event`, NaN when null/absent. */
static double field_of_last(const char *out, const char *event, const char *key)
{
    const char *line = NULL;
    for (const char *p = strstr(out, event); p; p = strstr(p + 1, event))
        line = p;
    if (!line)
        return NAN;
    while (line > out && line[-1] != '\n')
        line--;
    const char *end = strchr(line, '\n');
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *k = strstr(line, pat);
    if (!k || (end && k > end))
        return NAN;
    k += strlen(pat);
    char *stop;
    double v = strtod(k, &stop);
    return stop == k ? NAN : v;
}

/* ---- test data ----------------------------------------------------------- */

/* A ball resting, thrown N_THROWS times (rising 2.5 m/s, drifting 0.2 m/s) and
 * resting again, seen at FPS with +-0.3 px of deterministic noise. bad_line > 0:
 * that line's y field becomes "oops". */
static void write_balls(const char *path, int bad_line, int n_throws)
{
    FILE *f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    fputs("t,x,y,c,size\n", f);
    const double a_px = G_M_S2 / Q_M_PER_PX, d_px = BALL_DIAMETER_M / Q_M_PER_PX;
    const double v_up = 2.5 / Q_M_PER_PX, v_x = 0.2 / Q_M_PER_PX;
    uint32_t rng = 12345u;
    int frame = 0, line = 2;
    double x = 400.0, y0 = 900.0;
    for (int throw_i = 0; throw_i <= n_throws; throw_i++) {
        double flight = throw_i < n_throws ? 2.0 * v_up / a_px : 0.0;
        double t_rest = 1.0, t0 = frame / FPS;
        for (;;) {
            double t = frame / FPS - t0, y = y0, xx = x;
            if (t >= t_rest + flight)
                break;
            if (t > t_rest) {
                double tf = t - t_rest;
                y = y0 - v_up * tf + 0.5 * a_px * tf * tf;
                xx = x + v_x * tf;
            }
            rng = rng * 1664525u + 1013904223u;
            double nx = ((rng >> 8) / 16777216.0 - 0.5) * 0.6;
            rng = rng * 1664525u + 1013904223u;
            double ny = ((rng >> 8) / 16777216.0 - 0.5) * 0.6;
            if (line == bad_line)
                fprintf(f, "%.6f,%.2f,oops,0.95,%.2f\n", frame / FPS, xx + nx, d_px);
            else
                fprintf(f, "%.6f,%.2f,%.2f,0.95,%.2f\n", frame / FPS, xx + nx, y + ny, d_px);
            frame++;
            line++;
        }
        x += v_x * flight;
    }
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
}

static void write_ball(const char *path, int bad_line) { write_balls(path, bad_line, N_THROWS); }

/* ---- tests -------------------------------------------------------------- */

void test_help_version_and_usage_errors(void)
{
    run_result r;
    run((const char *[]){"--help", NULL}, &r);
    TEST_ASSERT_EQUAL_INT(0, r.code);
    /* every command, and each says what it reads */
    TEST_ASSERT_NOT_NULL(strstr(r.out, "\n  replay "));
    TEST_ASSERT_NOT_NULL(strstr(r.out, "\n  video "));
    TEST_ASSERT_NOT_NULL(strstr(r.out, "\n  cam "));
    TEST_ASSERT_NOT_NULL(strstr(r.out, "find a person (BlazePose"));
    TEST_ASSERT_NOT_NULL(strstr(r.out, "kiosk"));
    run_free(&r);

    run((const char *[]){"replay", "--help", NULL}, &r);
    TEST_ASSERT_EQUAL_INT(0, r.code);
    TEST_ASSERT_NOT_NULL(strstr(r.out, "--keypoints FILE"));
    TEST_ASSERT_NOT_NULL(strstr(r.out, "Exit codes"));
    run_free(&r);

    run((const char *[]){"--version", NULL}, &r);
    TEST_ASSERT_EQUAL_INT(0, r.code);
    TEST_ASSERT_EQUAL_STRING("gravscale 0.1.0\n", r.out);
    run_free(&r);

    static const struct {
        const char *args[8];
        const char *msg;
    } bad[] = {
        {{"replay", "--bogus", NULL}, "unknown option '--bogus'"},
        {{"replay", NULL}, "--keypoints FILE is required"},
        {{"replay", "--keypoints", NULL}, "needs a value"},
        {{"replay", "--keypoints", "x.csv", "--fps", "-3", NULL}, "--fps must be"},
        {{"replay", "--keypoints", "x.csv", "--layout", "coco18", NULL}, "--layout must be"},
        {{"replay", "--keypoints", "x.csv", "--format", "xml", NULL}, "--format must be"},
        {{"replay", "--keypoints", "x.csv", "--output-format", "csv", NULL}, "--output-format"},
        {{"replay", "--keypoints", "x.csv", "--track", "1", NULL}, "--track applies"},
        {{"frobnicate", NULL}, "unknown command"},
        {{NULL}, "usage"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        run(bad[i].args, &r);
        TEST_ASSERT_EQUAL_INT_MESSAGE(2, r.code, bad[i].msg);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(r.err, bad[i].msg), r.err);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, (int)r.out_len, bad[i].msg);
        run_free(&r);
    }
}

void test_ball_height_against_truth(void)
{
    run_result r;
    run((const char *[]){"replay", "--keypoints", g_ball, "--config", g_cfg, NULL}, &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, r.code, r.err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, (int)r.err_len, r.err);
    int lines = assert_json_lines(r.out, r.out_len);
    TEST_ASSERT_TRUE(lines >= 2);
    /* the start event first, with the source's frame rate from its timestamps */
    TEST_ASSERT_EQUAL_INT(0, strncmp(r.out, "{\"event\":\"start\"", 16));
    const char *first_nl = strchr(r.out, '\n');
    char cfgkey[300];
    snprintf(cfgkey, sizeof cfgkey, "\"config\":\"%s\"", g_cfg);
    TEST_ASSERT_NOT_NULL(strstr(r.out, cfgkey));
    TEST_ASSERT_TRUE(strstr(r.out, "\"fps_origin\":\"timestamps\"") < first_nl);
    TEST_ASSERT_TRUE(strstr(r.out, "\"layout\":\"point\"") < first_nl);
    TEST_ASSERT_DOUBLE_WITHIN(0.01, FPS, field_of_last(r.out, "\"event\":\"start\"", "fps_source"));
    /* the summary last, once */
    TEST_ASSERT_EQUAL_INT(1, count_substr(r.out, "\"event\":\"summary\""));
    const char *last = r.out + r.out_len - 1;
    while (last > r.out && last[-1] != '\n')
        last--;
    TEST_ASSERT_EQUAL_INT(0, strncmp(last, "{\"event\":\"summary\"", 18));
    TEST_ASSERT_EQUAL_INT(N_THROWS, count_substr(r.out, "\"event\":\"jump\""));
    TEST_ASSERT_EQUAL_DOUBLE(N_THROWS, field_of_last(r.out, "\"summary\"", "n_jumps"));
    double h = field_of_last(r.out, "\"summary\"", "height_m");
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * BALL_DIAMETER_M, BALL_DIAMETER_M, h);
    double q = field_of_last(r.out, "\"jump\"", "q_m_per_px");
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * Q_M_PER_PX, Q_M_PER_PX, q);
    run_free(&r);
}

void test_bad_row_stops_without_summary(void)
{
    char path[256];
    snprintf(path, sizeof path, "%s/ball_bad.csv", g_dir);
    /* line 160: after the first throw (rest 60 frames + flight 31 frames), inside the second rest */
    write_ball(path, 160);
    run_result r;
    run((const char *[]){"replay", "--keypoints", path, "--config", g_cfg, NULL}, &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, r.code, r.err);
    char want[400];
    snprintf(want, sizeof want, "gravscale: %s:160: field 'y': not a number ('oops')\n", path);
    TEST_ASSERT_EQUAL_STRING(want, r.err);
    assert_json_lines(r.out, r.out_len);
    TEST_ASSERT_EQUAL_INT(0, strncmp(r.out, "{\"event\":\"start\"", 16));
    TEST_ASSERT_EQUAL_INT(0, count_substr(r.out, "\"summary\""));
    TEST_ASSERT_EQUAL_INT(1, count_substr(r.out, "\"event\":\"jump\"")); /* the throw before it */
    run_free(&r);
}

void test_input_errors_exit_1(void)
{
    char trunc[256], empty[256], missing[256], ap[256];
    snprintf(trunc, sizeof trunc, "%s/trunc.csv", g_dir);
    snprintf(empty, sizeof empty, "%s/empty.csv", g_dir);
    snprintf(missing, sizeof missing, "%s/missing.csv", g_dir);
    snprintf(ap, sizeof ap, "%s/bad_ap.json", g_dir);
    write_text(trunc, "t,x,y,c\n0,1,2,0.9\n0.1,1,");
    write_text(empty, "");
    write_text(ap, "[{\"image_id\": \"000001.jpg\",\n \"keypoints\": [1, 2, 3]}]");
    const struct {
        const char *file;
        const char *extra;
        int line;
        const char *msg;
    } cases[] = {
        {trunc, NULL, 3, "truncated last line"},
        {empty, NULL, 1, "empty file"},
        {missing, NULL, 0, "cannot open"},
        {ap, "30", 1, "field 'keypoints': 3 numbers, expected 51"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        run_result r;
        if (cases[i].extra)
            run((const char *[]){"replay", "--keypoints", cases[i].file, "--format", "alphapose",
                                 "--fps", cases[i].extra, NULL},
                &r);
        else
            run((const char *[]){"replay", "--keypoints", cases[i].file, NULL}, &r);
        TEST_ASSERT_EQUAL_INT_MESSAGE(1, r.code, r.err);
        char head[300];
        if (cases[i].line)
            snprintf(head, sizeof head, "gravscale: %s:%d: ", cases[i].file, cases[i].line);
        else
            snprintf(head, sizeof head, "gravscale: %s: ", cases[i].file);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(r.err, head, strlen(head)), r.err);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(r.err, cases[i].msg), r.err);
        TEST_ASSERT_EQUAL_INT_MESSAGE(1, count_substr(r.err, "\n"), r.err); /* one line */
        assert_json_lines(r.out, r.out_len);
        TEST_ASSERT_EQUAL_INT(0, count_substr(r.out, "\"summary\""));
        run_free(&r);
    }
}

void test_options_that_do_not_fit_exit_2(void)
{
    run_result r;
    run((const char *[]){"replay", "--keypoints", g_ball, "--fps", "30", NULL}, &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(2, r.code, r.err);
    TEST_ASSERT_NOT_NULL(strstr(r.err, "--fps is not allowed"));
    TEST_ASSERT_EQUAL_INT(0, (int)r.out_len);
    run_free(&r);

    run((const char *[]){"replay", "--keypoints", g_ball, "--layout", "coco17", NULL}, &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(2, r.code, r.err);
    run_free(&r);

    char ap[256];
    snprintf(ap, sizeof ap, "%s/some.json", g_dir);
    write_text(ap, "[]");
    run((const char *[]){"replay", "--keypoints", ap, NULL}, &r); /* .json: alphapose, needs --fps */
    TEST_ASSERT_EQUAL_INT_MESSAGE(2, r.code, r.err);
    TEST_ASSERT_NOT_NULL(strstr(r.err, "--fps is required"));
    run_free(&r);
}

void test_config_errors_exit_2(void)
{
    char c1[256], c2[256], c3[256];
    snprintf(c1, sizeof c1, "%s/unknown_key.cfg", g_dir);
    snprintf(c2, sizeof c2, "%s/other_section.cfg", g_dir);
    snprintf(c3, sizeof c3, "%s/no_such.cfg", g_dir);
    write_text(c1, "[core]\nbogus_key = 1\n");
    /* [ball], [cam], [sink.*] belong to other programs and are skipped (gs_profile.h); a section nobody reads is an error */
    write_text(c2, "# a typo\n[balls]\nmin_radius_px = 3\n");
    const struct {
        const char *cfg;
        const char *head;
        const char *msg;
    } cases[] = {
        {c1, ":2: [core] key 'bogus_key'", "bogus_key"},
        {c2, ":2:", "balls"},
        {c3, ":", "cannot open"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        run_result r;
        run((const char *[]){"replay", "--keypoints", g_ball, "--config", cases[i].cfg, NULL}, &r);
        TEST_ASSERT_EQUAL_INT_MESSAGE(2, r.code, r.err);
        char head[400];
        snprintf(head, sizeof head, "gravscale: %s%s", cases[i].cfg, cases[i].head);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(r.err, head, strlen(head)), r.err);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(r.err, cases[i].msg), r.err);
        TEST_ASSERT_EQUAL_INT(1, count_substr(r.err, "\n"));
        TEST_ASSERT_EQUAL_INT(0, (int)r.out_len);
        run_free(&r);
    }
}

void test_nmea_output_checksums(void)
{
    run_result r;
    run((const char *[]){"replay", "--keypoints", g_ball, "--config", g_cfg, "--output-format",
                         "nmea", NULL},
        &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, r.code, r.err);
    int lines = 0;
    const char *p = r.out, *e = r.out + r.out_len;
    while (p < e) {
        const char *nl = memchr(p, '\n', (size_t)(e - p));
        TEST_ASSERT_NOT_NULL(nl);
        size_t len = (size_t)(nl - p) + 1;
        TEST_ASSERT_TRUE(len <= 82);
        TEST_ASSERT_EQUAL_INT('$', p[0]);
        TEST_ASSERT_EQUAL_INT('\r', nl[-1]);
        const char *star = memchr(p, '*', len);
        TEST_ASSERT_NOT_NULL(star);
        unsigned x = 0;
        for (const char *q = p + 1; q < star; q++)
            x ^= (unsigned char)*q;
        char hh[3];
        snprintf(hh, sizeof hh, "%02X", x);
        TEST_ASSERT_EQUAL_INT(0, strncmp(star + 1, hh, 2));
        lines++;
        p = nl + 1;
    }
    /* start, 3 x (jump + height), summary */
    TEST_ASSERT_EQUAL_INT(2 + 2 * N_THROWS, lines);
    TEST_ASSERT_EQUAL_INT(0, strncmp(r.out, "$GSSTA,", 7));
    TEST_ASSERT_EQUAL_INT(1, count_substr(r.out, "$GSSUM,"));
    run_free(&r);
}

void test_trace_file(void)
{
    char trace[256];
    snprintf(trace, sizeof trace, "%s/trace.jsonl", g_dir);
    run_result r;
    run((const char *[]){"replay", "--keypoints", g_ball, "--config", g_cfg, "--trace", trace, NULL},
        &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, r.code, r.err);
    TEST_ASSERT_EQUAL_INT(0, count_substr(r.out, "\"event\":\"sample\""));
    size_t tl;
    char *t = slurp(trace, &tl);
    int lines = assert_json_lines(t, tl);
    /* every frame is a sample in the trace */
    size_t bl;
    char *ball = slurp(g_ball, &bl);
    int frames = count_substr(ball, "\n") - 1;
    free(ball);
    TEST_ASSERT_EQUAL_INT(frames, count_substr(t, "\"event\":\"sample\""));
    TEST_ASSERT_TRUE(count_substr(t, "\"event\":\"state\"") >= 2 * N_THROWS);
    /* and every stdout line too, in the trace */
    TEST_ASSERT_EQUAL_INT(count_substr(r.out, "\"event\":\"jump\""),
                          count_substr(t, "\"event\":\"jump\""));
    TEST_ASSERT_EQUAL_INT(1, count_substr(t, "\"event\":\"summary\""));
    TEST_ASSERT_TRUE(lines > frames);
    free(t);
    run_free(&r);
}

void test_closed_pipe_exits_3_quietly(void)
{
    int fds[2];
    TEST_ASSERT_EQUAL_INT(0, pipe(fds));
    close(fds[0]); /* nobody reads */
    run_result r;
    run_fd((const char *[]){"replay", "--keypoints", g_ball, "--config", g_cfg, NULL}, fds[1], &r);
    close(fds[1]);
    TEST_ASSERT_EQUAL_INT_MESSAGE(3, r.code, r.err);
    TEST_ASSERT_EQUAL_STRING("", r.err);
    run_free(&r);
}

void test_full_disk_exits_3(void)
{
    int fd = open("/dev/full", O_WRONLY);
    if (fd < 0)
        TEST_IGNORE_MESSAGE("no /dev/full here");
    run_result r;
    run_fd((const char *[]){"replay", "--keypoints", g_ball, "--config", g_cfg, NULL}, fd, &r);
    close(fd);
    TEST_ASSERT_EQUAL_INT_MESSAGE(3, r.code, r.err);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(r.err, "gravscale: writing output"), r.err);
    run_free(&r);
}

/* `replay --keypoints /dev/stdin` fed through a pipe by a child: read frame by frame */
static void run_piped(const char *path, run_result *r)
{
    int fds[2];
    TEST_ASSERT_EQUAL_INT(0, pipe(fds));
    pid_t feeder = fork();
    TEST_ASSERT_TRUE(feeder >= 0);
    if (feeder == 0) {
        close(fds[0]);
        int in = open(path, O_RDONLY);
        char buf[1 << 14];
        ssize_t n;
        while (in >= 0 && (n = read(in, buf, sizeof buf)) > 0)
            if (write(fds[1], buf, (size_t)n) != n)
                break;
        _exit(0);
    }
    close(fds[1]);
    run_io((const char *[]){"replay", "--keypoints", "/dev/stdin", "--config", g_cfg, NULL}, fds[0], -1, r);
    close(fds[0]);
    int status;
    TEST_ASSERT_EQUAL_INT(feeder, waitpid(feeder, &status, 0));
}

/* A file is read ahead in a second thread in batches, a pipe frame by frame: the
 * same events, the same first error (here after several batches), the same exits. */
void test_read_ahead_gives_what_a_pipe_gives(void)
{
    enum { THROWS = 24, BAD_LINE = 2000 }; /* ~91 frames a throw: past the read-ahead's slots twice */
    char good[256], bad[256];
    snprintf(good, sizeof good, "%s/balls_long.csv", g_dir);
    snprintf(bad, sizeof bad, "%s/balls_long_bad.csv", g_dir);
    write_balls(good, 0, THROWS);
    write_balls(bad, BAD_LINE, THROWS);

    run_result f, p;
    run((const char *[]){"replay", "--keypoints", good, "--config", g_cfg, NULL}, &f);
    run_piped(good, &p);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, f.code, f.err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, p.code, p.err);
    TEST_ASSERT_EQUAL_INT(THROWS, count_substr(f.out, "\"event\":\"jump\""));
    TEST_ASSERT_EQUAL_UINT64(p.out_len, f.out_len);
    TEST_ASSERT_EQUAL_MEMORY(p.out, f.out, f.out_len);
    run_free(&f);
    run_free(&p);

    run((const char *[]){"replay", "--keypoints", bad, "--config", g_cfg, NULL}, &f);
    run_piped(bad, &p);
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, f.code, f.err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, p.code, p.err);
    char want[400];
    snprintf(want, sizeof want, "gravscale: %s:%d: field 'y': not a number ('oops')\n", bad, BAD_LINE);
    TEST_ASSERT_EQUAL_STRING(want, f.err);
    snprintf(want, sizeof want, "gravscale: /dev/stdin:%d: field 'y': not a number ('oops')\n", BAD_LINE);
    TEST_ASSERT_EQUAL_STRING(want, p.err);
    int jumps = count_substr(f.out, "\"event\":\"jump\"");
    TEST_ASSERT_TRUE(jumps >= 20 && jumps < THROWS); /* the throws before line 2000, no summary */
    TEST_ASSERT_EQUAL_INT(0, count_substr(f.out, "\"summary\""));
    TEST_ASSERT_EQUAL_UINT64(p.out_len, f.out_len);
    TEST_ASSERT_EQUAL_MEMORY(p.out, f.out, f.out_len);
    run_free(&f);
    run_free(&p);

    /* the output closed while the reader is still ahead in the file: exit 3, quietly */
    int fds[2];
    TEST_ASSERT_EQUAL_INT(0, pipe(fds));
    close(fds[0]);
    run_fd((const char *[]){"replay", "--keypoints", good, "--config", g_cfg, NULL}, fds[1], &f);
    close(fds[1]);
    TEST_ASSERT_EQUAL_INT_MESSAGE(3, f.code, f.err);
    TEST_ASSERT_EQUAL_STRING("", f.err);
    run_free(&f);
}

/* AlphaPose (.json picked by its name) and an OpenPose folder: times from --fps */
void test_json_inputs_with_fps(void)
{
    char ap[256], dir[256], f0[300];
    snprintf(ap, sizeof ap, "%s/people.json", g_dir);
    FILE *f = fopen(ap, "wb");
    TEST_ASSERT_NOT_NULL(f);
    fputs("[", f);
    for (int i = 0; i < 40; i++) {
        fprintf(f, "%s{\"image_id\": \"%06d.jpg\", \"keypoints\": [", i ? ",\n" : "", 39 - i);
        for (int k = 0; k < 17; k++)
            fprintf(f, "%s%d, %d, 0.9", k ? ", " : "", 900 + k, 300 + 40 * k);
        fputs("], \"score\": 2.0}", f);
    }
    fputs("]\n", f);
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
    run_result r;
    run((const char *[]){"replay", "--keypoints", ap, "--fps", "25", NULL}, &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, r.code, r.err);
    assert_json_lines(r.out, r.out_len);
    TEST_ASSERT_NOT_NULL(strstr(r.out, "\"fps_origin\":\"cli\""));
    TEST_ASSERT_NOT_NULL(strstr(r.out, "\"layout\":\"coco17\""));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 25.0, field_of_last(r.out, "\"event\":\"start\"", "fps_source"));
    TEST_ASSERT_EQUAL_INT(1, count_substr(r.out, "\"event\":\"summary\""));
    run_free(&r);

    snprintf(dir, sizeof dir, "%s/openpose_out", g_dir);
    TEST_ASSERT_EQUAL_INT(0, mkdir(dir, 0755));
    snprintf(f0, sizeof f0, "%s/clip_000000000000_keypoints.json", dir);
    write_text(f0, "{\"version\":1.3,\"people\":[]}");
    run((const char *[]){"replay", "--keypoints", dir, "--fps", "30", NULL}, &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, r.code, r.err);
    assert_json_lines(r.out, r.out_len);
    TEST_ASSERT_EQUAL_INT(1, count_substr(r.out, "\"event\":\"summary\""));
    run_free(&r);
    /* a folder without --fps */
    run((const char *[]){"replay", "--keypoints", dir, NULL}, &r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(2, r.code, r.err);
    TEST_ASSERT_NOT_NULL(strstr(r.err, "--fps is required with --format openpose"));
    run_free(&r);
}

static void rm_tree(const char *dir)
{
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
}

int main(void)
{
    signal(SIGPIPE, SIG_IGN);
    snprintf(g_dir, sizeof g_dir, "/tmp/gs_test_cli_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(g_ball, sizeof g_ball, "%s/ball.csv", g_dir);
    snprintf(g_cfg, sizeof g_cfg, "%s/ball.cfg", g_dir);
    UNITY_BEGIN();
    write_ball(g_ball, 0);
    /* a 0.22 m ball is below the default plausible size range, made for people */
    write_text(g_cfg, "[core]\nsize_min_m = 0.05\n");
    RUN_TEST(test_help_version_and_usage_errors);
    RUN_TEST(test_ball_height_against_truth);
    RUN_TEST(test_bad_row_stops_without_summary);
    RUN_TEST(test_input_errors_exit_1);
    RUN_TEST(test_options_that_do_not_fit_exit_2);
    RUN_TEST(test_config_errors_exit_2);
    RUN_TEST(test_json_inputs_with_fps);
    RUN_TEST(test_nmea_output_checksums);
    RUN_TEST(test_trace_file);
    RUN_TEST(test_closed_pipe_exits_3_quietly);
    RUN_TEST(test_full_disk_exits_3);
    RUN_TEST(test_read_ahead_gives_what_a_pipe_gives);
    int fails = UNITY_END();
    rm_tree(g_dir);
    return fails;
}
