/* bench_soak.c - a long run of the whole daemon: synthetic jumping at 120 fps
 * (a COCO-17 person, noisy keypoints, a countermovement jump every 2.5 s, the
 * model of bench_core) is written as a keypoint CSV and replayed as fast as it
 * goes through `gravscale cam` (keypoints backend: core + emit + sinks, with a
 * file sink and a TCP client sink connected to this program). Reports the daemon's
 * RSS early and at the end (flat = no growth), every jump emitted against the
 * truth, and CPU per frame (user + system of the child, from wait4).
 *   bench_soak [--minutes M] [--fps F] [--program PATH] [--dir DIR] [--keep]
 * Exit 0 when every flight was emitted and accepted, RSS grew < 1 MB and the
 * daemon exited 0; 1 otherwise; 2 usage. */
#define _DEFAULT_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* ASan's quarantine and its fake stacks (detect_stack_use_after_return) grow the RSS of a
 * sanitized daemon while its own memory stays flat; there LeakSanitizer checks for leaks */
#if defined(__SANITIZE_ADDRESS__)
#define RSS_FLAT_KB 16384
#else
#define RSS_FLAT_KB 1024
#endif

#define PI 3.14159265358979323846

static uint64_t rng = 88172645463325252ull;
static double urand(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}
static double nrand(void)
{
    double a = urand(), b = urand();
    return sqrt(-2.0 * log(a + 1e-300)) * cos(2.0 * PI * b);
}

/* standing COCO-17 skeleton (bench_core): height fractions above the floor, lateral offsets */
static const double kp_h[17] = {0.91, 0.936, 0.936, 0.93, 0.93, 0.818, 0.818, 0.63, 0.63,
                                0.485, 0.485, 0.53, 0.53, 0.285, 0.285, 0.039, 0.039};
static const double kp_x[17] = {0.0, -0.02, 0.02, -0.045, 0.045, -0.11, 0.11, -0.13, 0.13,
                                -0.14, 0.14, -0.06, 0.06, -0.06, 0.06, -0.06, 0.06};

/* COM rise (m): countermovement, a 0.5 s flight from 1.4 s, landing, every 2.5 s */
static double com_rise(double t)
{
    double ph = fmod(t, 2.5);
    if (ph < 1.0) return 0.0;
    if (ph < 1.4) return -0.12 * sin(PI * (ph - 1.0) / 0.4);
    if (ph < 1.9) {
        double x = ph - 1.4;
        return 2.45 * x - 4.905 * x * x;
    }
    if (ph < 2.2) return -0.08 * sin(PI * (ph - 1.9) / 0.3);
    return 0.0;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Returns the number of complete flights (landing + 0.5 s before the end). */
static long write_csv(const char *path, long frames, double fps, double stature_m)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "bench_soak: %s: %s\n", path, strerror(errno));
        exit(1);
    }
    static char buf[1 << 20];
    setvbuf(f, buf, _IOFBF, sizeof buf);
    fputs("t", f);
    for (int k = 0; k < 17; k++) fprintf(f, ",x%d,y%d,c%d", k, k, k);
    fputc('\n', f);
    const double stature_px = 600.0, q = stature_m / stature_px;
    for (long i = 0; i < frames; i++) {
        double t = (double)i / fps, rise = com_rise(t);
        fprintf(f, "%.6f", t);
        for (int k = 0; k < 17; k++)
            fprintf(f, ",%.2f,%.2f,0.9", 960.0 + kp_x[k] * stature_px + 1.5 * nrand(),
                    900.0 - (kp_h[k] * stature_m + rise) / q + 1.5 * nrand());
        fputc('\n', f);
    }
    if (fclose(f) != 0) {
        fprintf(stderr, "bench_soak: writing %s failed\n", path);
        exit(1);
    }
    double dur = (double)frames / fps;
    long n = 0;
    for (double land = 1.9; land + 0.5 < dur; land += 2.5) n++;
    return n;
}

static long rss_kb(pid_t pid, const char *field)
{
    char p[64], line[256];
    snprintf(p, sizeof p, "/proc/%d/status", (int)pid);
    FILE *f = fopen(p, "r");
    if (!f) return -1;
    long v = -1;
    size_t n = strlen(field);
    while (fgets(line, sizeof line, f))
        if (strncmp(line, field, n) == 0) v = atol(line + n);
    fclose(f);
    return v;
}

static size_t count(const char *s, size_t len, const char *pat)
{
    size_t n = 0, pl = strlen(pat);
    if (!s) return 0;
    for (size_t i = 0; i + pl <= len; i++)
        if (s[i] == pat[0] && memcmp(s + i, pat, pl) == 0) n++, i += pl - 1;
    return n;
}

int main(int argc, char **argv)
{
    double minutes = 60.0, fps = 120.0;
    const char *program = "build/gravscale", *dir = NULL;
    bool keep = false;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--minutes") && i + 1 < argc) minutes = atof(argv[++i]);
        else if (!strcmp(argv[i], "--fps") && i + 1 < argc) fps = atof(argv[++i]);
        else if (!strcmp(argv[i], "--program") && i + 1 < argc) program = argv[++i];
        else if (!strcmp(argv[i], "--dir") && i + 1 < argc) dir = argv[++i];
        else if (!strcmp(argv[i], "--keep")) keep = true;
        else if (!strcmp(argv[i], "--help")) {
            printf("usage: bench_soak [--minutes M (60)] [--fps F (120)] [--program build/gravscale] [--dir DIR] [--keep]\n");
            return 0;
        } else {
            fprintf(stderr, "bench_soak: unknown argument '%s' (see --help)\n", argv[i]);
            return 2;
        }
    }
    if (!(minutes > 0.05 && minutes <= 600 && fps >= 10 && fps <= 1000)) {
        fprintf(stderr, "bench_soak: --minutes 0.05..600, --fps 10..1000\n");
        return 2;
    }
    char tmpl[] = "/tmp/gs_soak_XXXXXX";
    if (!dir && !(dir = mkdtemp(tmpl))) {
        perror("bench_soak: mkdtemp");
        return 1;
    }
    char csv[512], cfg[512], log[512], out[512];
    snprintf(csv, sizeof csv, "%s/soak.csv", dir);
    snprintf(cfg, sizeof cfg, "%s/soak.cfg", dir);
    snprintf(log, sizeof log, "%s/soak.jsonl", dir);
    snprintf(out, sizeof out, "%s/soak.stdout", dir);
    const long frames = (long)(minutes * 60.0 * fps);
    double t_gen = now_s();
    const long truth = write_csv(csv, frames, fps, 1.75);
    t_gen = now_s() - t_gen;
    /* this program is the TCP server the daemon's tcp_client sink connects to
     * (its queue holds the lines until the connection is up: none is lost) */
    int lsock = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in la;
    memset(&la, 0, sizeof la);
    la.sin_family = AF_INET;
    la.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t lal = sizeof la;
    if (lsock < 0 || bind(lsock, (struct sockaddr *)&la, sizeof la) != 0 || listen(lsock, 1) != 0 ||
        getsockname(lsock, (struct sockaddr *)&la, &lal) != 0) {
        perror("bench_soak: listen");
        return 1;
    }
    FILE *c = fopen(cfg, "w");
    if (!c) return 1;
    fprintf(c, "[cam]\nbackend = keypoints\ndevice = %s\nrealtime = no\ndrain_s = 5\n"
               "[core]\nring_capacity = 1024\n"
               "[sink.stdout]\nenabled = no\n[sink.file]\npath = %s\n"
               "[sink.tcp_client]\nhost = 127.0.0.1\nport = %u\nqueue_lines = 256\nbackoff_min_s = 0.05\n"
               "[status]\ninterval_s = 1\n",
            csv, log, (unsigned)ntohs(la.sin_port));
    fclose(c);
    printf("bench_soak: %ld frames (%.1f min at %.0f fps, %ld flights) written in %.1f s\n", frames, minutes, fps, truth,
           t_gen);

    int ep[2];
    if (pipe(ep) != 0) return 1;
    pid_t pid = fork();
    if (pid == 0) {
        dup2(ep[1], STDERR_FILENO);
        int o = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (o >= 0) dup2(o, STDOUT_FILENO);
        close(ep[0]);
        execl(program, program, "cam", "--config", cfg, (char *)NULL);
        fprintf(stderr, "exec %s: %s\n", program, strerror(errno));
        _exit(127);
    }
    close(ep[1]);
    fcntl(ep[0], F_SETFL, O_NONBLOCK);
    static char err[65536];
    size_t elen = 0;
    int sock = -1;
    size_t cap = 1 << 20, tlen = 0;
    char *tcp = malloc(cap);
    /* RSS every 5 ms, so that a run of a fraction of a second still has samples
     * after its first tenth; a full table is halved and the interval doubled */
    double t0 = now_s(), next_sample = t0, sample_s = 0.005;
    enum { MAX_SAMPLES = 100000 };
    static long rss_at[MAX_SAMPLES];
    static double t_at[MAX_SAMPLES];
    size_t n_rss = 0;
    double t_started = -1.0, t_summary = -1.0;
    size_t scanned = 0;
    long rss_early = -1, rss_mid = -1, rss_last = -1, hwm = -1;
    double t_early = 0;
    int status = 0;
    struct rusage ru;
    bool done = false, stderr_open = true;
    while (!done) {
        struct pollfd p[3] = {{stderr_open ? ep[0] : -1, POLLIN, 0}, {sock, POLLIN, 0}, {sock < 0 ? lsock : -1, POLLIN, 0}};
        poll(p, 3, 100);
        if (stderr_open) {
            ssize_t n = read(ep[0], err + elen, sizeof err - 1 - elen);
            if (n > 0) elen += (size_t)n;
            else if (n == 0) stderr_open = false;
            err[elen] = 0;
        }
        if (sock < 0) {
            struct pollfd lp = {lsock, POLLIN, 0};
            if (poll(&lp, 1, 0) == 1) sock = accept(lsock, NULL, NULL);
        }
        if (sock >= 0) {
            for (;;) {
                if (cap - tlen < 65536) tcp = realloc(tcp, cap *= 2);
                ssize_t n = recv(sock, tcp + tlen, cap - tlen, MSG_DONTWAIT);
                if (n > 0) {
                    tlen += (size_t)n;
                    continue;
                }
                break;
            }
        }
        double now = now_s();
        if (now >= next_sample) {
            long r = rss_kb(pid, "VmRSS:"), h = rss_kb(pid, "VmHWM:");
            if (t_started < 0 && tlen > 0) t_started = now - t0;  /* the start line: set-up done */
            if (t_summary < 0 && count(tcp + scanned, tlen - scanned, "{\"event\":\"summary\"")) t_summary = now - t0; /* stream over */
            scanned = tlen > 32 ? tlen - 32 : 0;
            if (r > 0 && n_rss == MAX_SAMPLES) {
                for (size_t i = 0; i < MAX_SAMPLES / 2; i++) {
                    rss_at[i] = rss_at[2 * i];
                    t_at[i] = t_at[2 * i];
                }
                n_rss = MAX_SAMPLES / 2;
                sample_s *= 2.0;
            }
            if (r > 0) {
                rss_last = r;
                hwm = h;
                rss_at[n_rss] = r;
                t_at[n_rss++] = now - t0;
            }
            next_sample = now + sample_s;
        }
        pid_t w = wait4(pid, &status, WNOHANG, &ru);
        if (w == pid) done = true;
    }
    double wall = now_s() - t0;
    const double stream_end = t_summary >= 0 ? t_summary : wall;
    /* "before": the first sample after a tenth of the run (buffers warmed up, the
     * stream under way); "after": the last sample before the daemon exited */
    for (size_t i = 0; i < n_rss; i++)
        if (t_started >= 0 && t_at[i] >= t_started + 0.1 * (stream_end - t_started)) {
            rss_early = rss_at[i];
            t_early = t_at[i];
            break;
        }
    for (size_t i = 0; i < n_rss; i++)
        if (t_started >= 0 && t_at[i] >= t_started + 0.5 * (stream_end - t_started)) {
            rss_mid = rss_at[i];
            break;
        }
    /* "after": the last sample before the summary arrived (the end of the
     * stream; library teardown at exit is not the daemon's steady state) */
    for (size_t i = 0; i < n_rss; i++)
        if (t_summary < 0 || t_at[i] < t_summary) rss_last = rss_at[i];
    if (sock >= 0) {  /* what is left in the socket */
        ssize_t n;
        if (cap - tlen < 65536) tcp = realloc(tcp, cap *= 2);
        while ((n = recv(sock, tcp + tlen, cap - tlen, MSG_DONTWAIT)) > 0) {
            tlen += (size_t)n;
            if (cap - tlen < 65536) tcp = realloc(tcp, cap *= 2);
        }
        close(sock);
    }
    close(lsock);
    double cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
                 1e-6 * (double)ru.ru_stime.tv_usec;
    int rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);

    /* the file sink's lines */
    FILE *lf = fopen(log, "rb");
    size_t flen = 0;
    char *file = NULL;
    if (lf) {
        fseek(lf, 0, SEEK_END);
        flen = (size_t)ftell(lf);
        fseek(lf, 0, SEEK_SET);
        file = malloc(flen + 1);
        flen = fread(file, 1, flen, lf);
        fclose(lf);
    }
    size_t jumps = count(file, flen, "{\"event\":\"jump\""), acc = count(file, flen, "\"accepted\":true");
    /* match flights to the truth: take-off within 0.1 s of 1.4 + 2.5 k */
    long found = 0, extra = 0, extra_acc = 0, last_k = -1;
    double worst_h = 0.0;
    for (const char *q = file; q && (q = strstr(q, "{\"event\":\"jump\"")) != NULL; q++) {
        const char *tk = strstr(q, "\"t_takeoff_s\":"), *hm = strstr(q, "\"height_m\":");
        const char *eol = strchr(q, '\n');
        if (!tk || !eol || tk > eol) continue;
        double t = atof(tk + 14), h = hm && hm < eol ? atof(hm + 11) : NAN;
        bool accepted = strstr(q, "\"accepted\":true") && strstr(q, "\"accepted\":true") < eol;
        long k = lround((t - 1.4) / 2.5);
        if (fabs(t - (1.4 + 2.5 * (double)k)) <= 0.1 && k != last_k && k >= 0 && k < truth) {
            found++;
            last_k = k;
            if (accepted && fabs(h - 1.75) > worst_h) worst_h = fabs(h - 1.75);
        } else {
            extra++;
            extra_acc += accepted;
        }
    }
    size_t tjumps = count(tcp, tlen, "{\"event\":\"jump\"");
    size_t sums = count(file, flen, "{\"event\":\"summary\""), stats = count(file, flen, "{\"event\":\"status\"");
    printf("bench_soak: daemon exit %d after %.1f s wall (%.0f frames/s, %.1fx real time)\n", rc, wall, frames / wall,
           frames / fps / wall);
    printf("bench_soak: CPU %.2f s user+sys = %.2f us per frame\n", cpu, 1e6 * cpu / (double)frames);
    printf("bench_soak: RSS %ld kB at %.1f s (10 %% of the stream), %ld kB at half time, %ld kB at its end (%+ld kB), peak %ld kB\n",
           rss_early, t_early, rss_mid, rss_last, rss_last - rss_early, hwm);
    printf("bench_soak: flights: truth %ld, emitted %zu (file sink) / %zu (tcp_client sink), accepted %zu; %zu summary, %zu status lines; "
           "file %zu bytes, TCP %zu bytes\n",
           truth, jumps, tjumps, acc, sums, stats, flen, tlen);
    printf("bench_soak: true flights found %ld of %ld (take-off within 0.1 s; worst accepted height error %.1f cm); "
           "%ld other flights reported (%ld accepted)\n",
           found, truth, 100.0 * worst_h, extra, extra_acc);
    const char *sum = file ? strstr(file, "{\"event\":\"summary\"") : NULL;
    if (sum) printf("bench_soak: %.*s", (int)(strchr(sum, '\n') ? strchr(sum, '\n') - sum + 1 : 0), sum);
    if (elen) printf("bench_soak: daemon stderr:\n%s", err);
    /* OK: every true flight emitted, the TCP peer got every byte the file got,
     * one summary, memory flat; flights the core finds beyond the truth are
     * reported, not failed (the core's accuracy, not the daemon's path) */
    bool ok = rc == 0 && found == truth && tjumps == jumps && tlen == flen && sums == 1 && rss_early > 0 &&
              rss_last - rss_early < RSS_FLAT_KB;
    printf("bench_soak: %zu RSS samples every %.0f ms\n", n_rss, 1e3 * sample_s);
    if (!keep) {
        unlink(csv), unlink(cfg), unlink(log), unlink(out);
        if (dir == tmpl) rmdir(dir);
    }
    free(tcp);
    free(file);
    printf("bench_soak: %s\n", ok ? "OK" : "FAILED");
    return ok ? 0 : 1;
}
