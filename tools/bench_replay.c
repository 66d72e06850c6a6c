/* bench_replay.c - speed of the replay path: writes a synthetic COCO-17 CSV of
 * N frames (a person standing and jumping every 3 s, pixels with 2 decimals),
 * then times the CSV reader alone and the whole replay (reader + pipeline +
 * JSON emitter + writer to /dev/null) in this process.
 *   bench_replay [N] [--keep FILE]      (N default 200000) */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "gravscale/gravscale.h"
#include "gs_kpread.h"
#include "gs_out.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Standing pose offsets from the COM in pixels (y down), a 1.75 m person at ~2.3 mm/px. */
static const float k_pose[17][2] = {
    {0, -300},  {-8, -310}, {8, -310},  {-18, -305}, {18, -305}, {-45, -215},
    {45, -215}, {-55, -120}, {55, -120}, {-60, -40},  {60, -40},  {-25, 10},
    {25, 10},   {-27, 180}, {27, 180},  {-28, 345},  {28, 345}};

static int write_csv(const char *path, long frames)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "bench_replay: %s: %s\n", path, strerror(errno));
        return -1;
    }
    static char line[4096];
    int n = snprintf(line, sizeof line, "t");
    for (int k = 0; k < 17; k++)
        n += snprintf(line + n, sizeof line - (size_t)n, ",x%d,y%d,c%d", k, k, k);
    fprintf(f, "%s\n", line);
    const double fps = 30.0, a_px = 9.81 / 0.0023, v0 = 2.4 / 0.0023; /* 0.49 s flights */
    uint32_t rng = 1u;
    for (long i = 0; i < frames; i++) {
        double t = (double)i / fps;
        double phase = fmod(t, 3.0) - 2.0; /* airborne for 2 v0 / a after 2 s of standing */
        double lift = 0.0;
        if (phase > 0.0 && phase < 2.0 * v0 / a_px)
            lift = v0 * phase - 0.5 * a_px * phase * phase;
        double cx = 960.0 + 20.0 * sin(0.1 * t), cy = 560.0 - lift;
        n = snprintf(line, sizeof line, "%.6f", t);
        for (int k = 0; k < 17; k++) {
            rng = rng * 1664525u + 1013904223u;
            double nx = ((rng >> 9) / 8388608.0 - 0.5) * 1.5;
            rng = rng * 1664525u + 1013904223u;
            double ny = ((rng >> 9) / 8388608.0 - 0.5) * 1.5;
            double c = 0.6 + 0.39 * ((rng >> 20) / 4096.0);
            n += snprintf(line + n, sizeof line - (size_t)n, ",%.2f,%.2f,%.2f", cx + k_pose[k][0] + nx,
                          cy + k_pose[k][1] + ny, c);
        }
        line[n++] = '\n';
        if (fwrite(line, 1, (size_t)n, f) != (size_t)n) {
            fprintf(stderr, "bench_replay: writing %s failed\n", path);
            fclose(f);
            return -1;
        }
    }
    return fclose(f);
}

typedef struct {
    gs_out out;
    uint64_t events;
} sink;

static void on_event(void *ctx, const gs_event *ev)
{
    sink *s = ctx;
    char buf[GS_EMIT_MAX];
    size_t n = gs_emit_json(ev, buf, sizeof buf);
    if (n)
        gs_out_line(&s->out, buf, n);
    s->events++;
}

int main(int argc, char **argv)
{
    long frames = 200000;
    const char *keep = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--keep") == 0 && i + 1 < argc)
            keep = argv[++i];
        else if (atol(argv[i]) > 0)
            frames = atol(argv[i]);
        else {
            fprintf(stderr, "usage: bench_replay [N] [--keep FILE]\n");
            return 2;
        }
    }
    char path[256];
    if (keep) {
        snprintf(path, sizeof path, "%s", keep);
    } else {
        snprintf(path, sizeof path, "/tmp/bench_replay_XXXXXX");
        int fd = mkstemp(path);
        if (fd < 0) {
            perror("mkstemp");
            return 1;
        }
        close(fd);
    }
    double t0 = now_s();
    if (write_csv(path, frames) != 0)
        return 1;
    struct stat sb;
    stat(path, &sb);
    printf("bench_replay: %ld COCO-17 frames, %.1f MB CSV written in %.2f s\n", frames,
           (double)sb.st_size / 1e6, now_s() - t0);

    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    gs_kpread_error err;
    gs_kpframe f;
    int rc = 0;

    /* 1. the reader alone (best of 3: the file is in the page cache after the first) */
    double best = INFINITY;
    for (int rep = 0; rep < 3; rep++) {
        gs_kpread *r = gs_kpread_open(path, &o, &err);
        if (!r) {
            fprintf(stderr, "bench_replay: %s\n", err.text);
            return 1;
        }
        long n = 0;
        double checksum = 0.0;
        t0 = now_s();
        gs_kpr_status st;
        while ((st = gs_kpread_next(r, &f, &err)) == GS_KPR_FRAME) {
            checksum += f.kp[n % 17].x_px;
            n++;
        }
        double dt = now_s() - t0;
        gs_kpread_close(r);
        if (st != GS_KPR_EOF || n != frames) {
            fprintf(stderr, "bench_replay: read %ld of %ld frames: %s\n", n, frames, err.text);
            return 1;
        }
        if (dt < best)
            best = dt;
        (void)checksum;
    }
    printf("reader alone:  %10.0f frames/s  %7.0f ns/frame  %6.1f MB/s\n", frames / best,
           1e9 * best / frames, (double)sb.st_size / 1e6 / best);

    /* 2. the whole replay: reader + pipeline + emitter + writer to /dev/null */
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    size_t bytes = gs_pipeline_storage_bytes(&cfg);
    void *store = malloc(bytes);
    gs_pipeline *pl = malloc(sizeof *pl);
    sink s;
    int devnull = open("/dev/null", O_WRONLY);
    best = INFINITY;
    uint64_t events = 0;
    for (int rep = 0; rep < 3 && store && pl && devnull >= 0; rep++) {
        memset(&s, 0, sizeof s);
        gs_out_open_fd(&s.out, devnull, 0);
        gs_kpread *r = gs_kpread_open(path, &o, &err);
        if (!r || gs_pipeline_init(pl, &cfg, gs_kpread_layout(r), store, bytes, on_event, &s) != GS_OK) {
            fprintf(stderr, "bench_replay: cannot start\n");
            return 1;
        }
        t0 = now_s();
        long n = 0;
        while (gs_kpread_next(r, &f, &err) == GS_KPR_FRAME) {
            gs_pipeline_push_keypoints(pl, f.t_s, f.kp);
            n++;
        }
        gs_pipeline_flush(pl);
        double dt = now_s() - t0;
        gs_kpread_close(r);
        gs_out_close(&s.out);
        if (n != frames)
            rc = 1;
        if (dt < best)
            best = dt;
        events = s.events;
    }
    printf("whole replay:  %10.0f frames/s  %7.0f ns/frame  (%llu events)\n", frames / best,
           1e9 * best / frames, (unsigned long long)events);
    printf("speed bar 300000 frames/s: %s\n", frames / best >= 300000.0 ? "met" : "NOT met");
    if (devnull >= 0)
        close(devnull);
    free(store);
    free(pl);
    if (!keep)
        unlink(path);
    return rc;
}
