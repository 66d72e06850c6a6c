/* bench_core.c - cost per sample and memory of the core pipeline.
 * Feeds a synthetic COCO-17 person who jumps every 2.5 s (noisy keypoints)
 * through gs_pipeline at a given rate and reports ns per sample (mean and the
 * worst frame), the bytes of core state (pipeline struct + ring storage) and the
 * flights found; then instructions per frame, mean and worst, counted by
 * valgrind's callgrind on the first --instr-frames frames (the same stream): the
 * program runs itself under callgrind, which dumps its counts after every frame
 * (--dump-after=bench_frame_done) into a pipe read here. Instruction counts do
 * not depend on the machine's other load; ns do.
 *   bench_core [--frames N] [--fps F] [--ring CAP] [--instr-frames N (0: none)] */
#include "gravscale/gravscale.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define PI 3.14159265358979323846

static uint64_t rng = 88172645463325252ull;
static double urand(void)
{
    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}
static double nrand(void)
{
    double a = urand(), b = urand();
    return sqrt(-2.0 * log(a + 1e-300)) * cos(2.0 * PI * b);
}

/* standing COCO-17 skeleton: height fractions above the floor, lateral offsets (fractions of stature) */
static const double kp_h[17] = {0.91, 0.936, 0.936, 0.93, 0.93, 0.818, 0.818, 0.63, 0.63,
                                0.485, 0.485, 0.53, 0.53, 0.285, 0.285, 0.039, 0.039};
static const double kp_x[17] = {0.0, -0.02, 0.02, -0.045, 0.045, -0.11, 0.11, -0.13, 0.13,
                                -0.14, 0.14, -0.06, 0.06, -0.06, 0.06, -0.06, 0.06};

/* COM rise (m) of a jump every 2.5 s: countermovement, then a 0.5 s flight */
static double com_rise(double t, bool *air)
{
    double ph = fmod(t, 2.5);
    *air = false;
    if (ph < 1.0) return 0.0;
    if (ph < 1.4) return -0.12 * sin(PI * (ph - 1.0) / 0.4);
    if (ph < 1.9) { double x = ph - 1.4; *air = true; return 2.45 * x - 4.905 * x * x; }
    if (ph < 2.2) return -0.08 * sin(PI * (ph - 1.9) / 0.3);
    return 0.0;
}

typedef struct { uint64_t jumps, accepted, heights; } counts;
static void on_event(void *ctx, const gs_event *ev)
{
    counts *c = (counts *)ctx;
    if (ev->type == GS_EV_JUMP) { c->jumps++; c->accepted += ev->u.jump.accepted; }
    if (ev->type == GS_EV_HEIGHT) c->heights++;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Called after the set-up and after every frame: under callgrind each call ends
 * one dump, so dump k + 1 holds frame k's instructions. */
void bench_frame_done(void);
__attribute__((noinline)) void bench_frame_done(void)
{
    __asm__ volatile("" ::: "memory");
}

/* Runs this program under callgrind on `frames` frames and prints their
 * instructions per frame; false when valgrind cannot run. */
static bool count_instructions(const char *self, long frames, double fps, unsigned ring)
{
    int fd[2];
    if (pipe(fd) != 0) {
        return false;
    }
    pid_t pid = fork();
    if (pid < 0) {
        return false;
    }
    if (pid == 0) {
        char nf[32], fs[32], rs[32];
        snprintf(nf, sizeof nf, "%ld", frames);
        snprintf(fs, sizeof fs, "%.17g", fps);
        snprintf(rs, sizeof rs, "%u", ring);
        close(fd[0]);
        if (dup2(fd[1], 3) < 0) {
            _exit(127);
        }
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) {
            _exit(127);
        }
        execlp("valgrind", "valgrind", "--tool=callgrind", "--dump-after=bench_frame_done", "--combine-dumps=yes",
               "--dump-line=no", "--callgrind-out-file=/dev/fd/3", self, "--frames", nf, "--fps", fs, "--ring", rs,
               "--instr-frames", "0", "--marks", (char *)NULL);
        _exit(127);
    }
    close(fd[1]);
    FILE *in = fdopen(fd[0], "r");
    static char line[65536];
    long part = 0, worst_i = -1;
    double sum = 0.0, worst = 0.0;
    unsigned long long v;
    while (in && fgets(line, sizeof line, in)) {
        if (sscanf(line, "summary: %llu", &v) != 1) {
            continue;
        }
        /* dump 0: start-up and set-up; dumps 1..frames: the frames; frames + 1: the flush */
        if (part >= 1 && part <= frames + 1) {
            sum += (double)v;
            if ((double)v > worst) {
                worst = (double)v;
                worst_i = part - 1;
            }
        }
        part++;
    }
    if (in) {
        fclose(in);
    }
    int st = 0;
    waitpid(pid, &st, 0);
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0 || part < frames + 2) {
        return false;
    }
    printf("  instructions (callgrind, the first %ld frames, %.0f s of video): %.0f per frame on average, "
           "worst frame %.0f (frame %ld%s, t = %.3f s)\n",
           frames, frames / fps, sum / (double)(frames + 1), worst, worst_i, worst_i == frames ? ": the flush" : "",
           worst_i / fps);
    return true;
}

int main(int argc, char **argv)
{
    long frames = 1000000;
    double fps = 120.0;
    unsigned ring = 512;
    long instr_frames = 14400;  /* 2 min of video at 120 fps: 48 jumps */
    bool marks = false;         /* under callgrind (count_instructions): mark every frame */
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atol(argv[++i]);
        else if (!strcmp(argv[i], "--fps") && i + 1 < argc) fps = atof(argv[++i]);
        else if (!strcmp(argv[i], "--ring") && i + 1 < argc) ring = (unsigned)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--instr-frames") && i + 1 < argc) instr_frames = atol(argv[++i]);
        else if (!strcmp(argv[i], "--marks")) marks = true;
        else if (!strcmp(argv[i], "--help")) {
            printf("usage: bench_core [--frames N] [--fps F] [--ring CAP] [--instr-frames N]\n");
            return 0;
        } else {
            fprintf(stderr, "bench_core: unknown argument '%s'\n", argv[i]);
            return 2;
        }
    }
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.ring_capacity = ring;
    size_t bytes = gs_pipeline_storage_bytes(&cfg);
    double *storage = malloc(bytes);  /* the host bench owns the memory; the core never allocates */
    static gs_pipeline p;
    counts c = {0, 0, 0};
    if (!storage || gs_pipeline_init(&p, &cfg, GS_LAYOUT_COCO17, storage, bytes, on_event, &c) != GS_OK) {
        fprintf(stderr, "bench_core: init failed\n");
        return 1;
    }
    /* pre-generate one 10 s cycle of frames so only the core is timed */
    long cycle = (long)(fps * 10.0);
    gs_kp *kps = malloc(sizeof(gs_kp) * 17u * (size_t)cycle);
    const double stature_px = 600.0, q = 1.75 / stature_px;
    for (long i = 0; i < cycle; i++) {
        bool air;
        double rise = com_rise(i / fps, &air);
        for (int k = 0; k < 17; k++) {
            gs_kp *kp = &kps[i * 17 + k];
            kp->x_px = (float)(960.0 + kp_x[k] * stature_px + 1.5 * nrand());
            kp->y_px = (float)(900.0 - (kp_h[k] * 1.75 + rise) / q + 1.5 * nrand());
            kp->c = 0.9f;
        }
    }
    if (marks) {
        bench_frame_done();
    }
    double t0 = now_s(), worst_s = 0.0;
    long worst_i = 0;
    for (long i = 0; i < frames; i++) {
        double t = (double)i / fps, f0 = now_s();
        gs_pipeline_push_keypoints(&p, t, &kps[(i % cycle) * 17]);
        double df = now_s() - f0;
        if (df > worst_s) {
            worst_s = df;
            worst_i = i;
        }
        if (marks) {
            bench_frame_done();
        }
    }
    gs_pipeline_flush(&p);
    if (marks) {
        bench_frame_done();
    }
    double dt = now_s() - t0;
    printf("bench_core: %ld COCO-17 frames at %.0f fps (%.0f s of video) in %.3f s\n",
           frames, fps, frames / fps, dt);
    printf("  %.1f ns per sample on average (the clock read included), %.0f samples/s; worst frame %.1f us "
           "(frame %ld, t = %.3f s)\n",
           1e9 * dt / (double)frames, (double)frames / dt, 1e6 * worst_s, worst_i, worst_i / fps);
    printf("  core state: pipeline struct %zu B + ring/scratch storage %zu B (ring %u x %zu B + %u floats) = %zu B\n",
           sizeof(gs_pipeline), bytes, ring, sizeof(gs_sample), ring, sizeof(gs_pipeline) + bytes);
    printf("  flights: %llu reported, %llu accepted, %llu height events (expected about %ld)\n",
           (unsigned long long)c.jumps, (unsigned long long)c.accepted, (unsigned long long)c.heights,
           (long)(frames / fps / 2.5));
    free(kps);
    free(storage);
    if (instr_frames > 0 && !marks) {
        fflush(stdout);
        if (!count_instructions(argv[0], instr_frames < frames ? instr_frames : frames, fps, ring)) {
            printf("  instructions: valgrind's callgrind did not run (apt-get install valgrind; "
                   "tools/bootstrap.sh installs it)\n");
        }
    }
    return 0;
}
