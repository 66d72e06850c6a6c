/* bench_sinks.c - cost of the sinks per line: N real JSON jump lines (from the
 * emitter) written through each sink the way the daemon would (write_line per
 * line, a poll every 4 lines, a drain at the end), with readers in child
 * processes. Prints wall time, this process's CPU time per line, lines sent
 * and dropped, and checks that every reader got exactly the bytes counted sent.
 *   bench_sinks [N] [--clients K]      (N default 200000, K default 4) */
#define _XOPEN_SOURCE 700 /* posix_openpt for the pty */
#include "gs_sink.h"
#include "gravscale/gs_emit.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>


static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
    pid_t pid;
    int result_fd; /* the child writes its byte count here */
} reader;

/* child: read fd until EOF, report the byte count */
static reader spawn_reader(int fd, int close_in_child)
{
    int p[2];
    reader r = {-1, -1};
    if (pipe(p) != 0)
        return r;
    r.pid = fork();
    if (r.pid == 0) {
        close(p[0]);
        if (close_in_child >= 0)
            close(close_in_child);
        static char buf[1 << 16];
        unsigned long long total = 0;
        for (;;) {
            ssize_t n = read(fd, buf, sizeof buf);
            if (n <= 0)
                break;
            total += (unsigned long long)n;
        }
        if (write(p[1], &total, sizeof total) != (ssize_t)sizeof total)
            _exit(1);
        _exit(0);
    }
    close(p[1]);
    r.result_fd = p[0];
    return r;
}

static unsigned long long reader_done(reader r)
{
    unsigned long long total = 0;
    if (read(r.result_fd, &total, sizeof total) != (ssize_t)sizeof total)
        total = ~0ull;
    close(r.result_fd);
    waitpid(r.pid, NULL, 0);
    return total;
}

static size_t g_len;
static char g_line[GS_EMIT_MAX];

/* the daemon's loop: a line, a poll every 4 lines; then a drain */
static void run(const char *name, gs_sink *s, long n)
{
    double w0 = gs_sink_now_s(), c0 = cpu_s();
    for (long i = 0; i < n; i++) {
        s->write_line(s->state, g_line, g_len);
        if ((i & 3) == 3)
            s->poll(s->state, gs_sink_now_s());
    }
    double w1 = gs_sink_now_s(), c1 = cpu_s();
    gs_sinkset set;
    gs_sinkset_init(&set);
    gs_sinkset_add(&set, s);
    uint64_t left = gs_sinkset_drain(&set, 1.0); /* a stalled client never empties */
    gs_sink_info in;
    s->info(s->state, &in);
    printf("%-34s %8.3f s wall %8.3f us cpu/line %10.0f lines/s  sent %llu dropped %llu left %llu\n", name,
           w1 - w0, 1e6 * (c1 - c0) / (double)n, (double)n / (w1 - w0), (unsigned long long)in.c.lines_sent,
           (unsigned long long)in.c.lines_dropped, (unsigned long long)left);
}

static int connect_loopback(uint16_t port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        perror("bench_sinks: connect");
        exit(1);
    }
    return fd;
}

static int bench_tcp(long n, int k, bool with_stalled)
{
    gs_sink_tcp_cfg c;
    memset(&c, 0, sizeof c);
    snprintf(c.bind, sizeof c.bind, "127.0.0.1");
    c.max_clients = (uint32_t)k + 1;
    c.queue_lines = 256;
    gs_sink s;
    char err[256];
    if (gs_sink_tcp_open(&s, &c, err, sizeof err) != 0) {
        fprintf(stderr, "bench_sinks: %s\n", err);
        return 1;
    }
    reader r[64];
    int stalled = -1;
    for (int i = 0; i < k; i++) {
        int fd = connect_loopback(gs_sink_tcp_port(&s));
        r[i] = spawn_reader(fd, -1);
        close(fd);
    }
    if (with_stalled)
        stalled = connect_loopback(gs_sink_tcp_port(&s));
    for (int t = 0; t < 1000; t++) {
        gs_sink_info in;
        s.poll(s.state, 0.0);
        s.info(s.state, &in);
        if (in.c.clients == (uint32_t)k + (with_stalled ? 1u : 0u))
            break;
        poll(NULL, 0, 1);
    }
    char name[64];
    snprintf(name, sizeof name, "tcp server, %d readers%s", k, with_stalled ? " + 1 stalled" : "");
    gs_sink_info before;
    s.info(s.state, &before);
    run(name, &s, n);
    gs_sink_info in;
    s.info(s.state, &in);
    s.close(s.state); /* readers see EOF */
    int bad = 0;
    for (int i = 0; i < k; i++) {
        unsigned long long got = reader_done(r[i]);
        if (got != (unsigned long long)n * g_len) {
            fprintf(stderr, "bench_sinks: reader %d got %llu bytes, expected %llu\n", i, got,
                    (unsigned long long)n * g_len);
            bad = 1;
        }
    }
    if (stalled >= 0)
        close(stalled);
    return bad;
}

int main(int argc, char **argv)
{
    long n = 200000;
    int k = 4;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            printf("usage: bench_sinks [N] [--clients K]\n"
                   "  N lines (default 200000) through a file sink to /dev/null, a TCP server with K\n"
                   "  reading clients (default 4), the same plus one client that never reads, a pty\n"
                   "  serial line with a reader, and UDP to a reader; prints time and CPU per line.\n");
            return 0;
        } else if (!strcmp(argv[i], "--clients") && i + 1 < argc) {
            k = atoi(argv[++i]);
        } else {
            n = atol(argv[i]);
        }
    }
    if (n < 1 || k < 1 || k > 64) {
        fprintf(stderr, "bench_sinks: bad arguments (see --help)\n");
        return 2;
    }
    gs_sink_ignore_sigpipe();
    gs_event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_JUMP;
    gs_ev_jump *j = &ev.u.jump;
    j->t_takeoff_us = 2692600, j->t_land_us = 3341100, j->flight_time_s = 0.6485, j->t_apex_us = 3009900;
    j->a_px_s2 = 3109.01, j->a_px_se_s2 = 14.74, j->g_dir_deg = -0.31, j->q_m_per_px = 0.00315535;
    j->size_px = 549.86, j->height_m = 1.735, j->height_se_m = 0.0085, j->jump_height_m = 0.4938;
    j->takeoff_velocity_m_s = 3.113, j->n_samples = 19, j->n_outliers = 1, j->rms_px = 1.116;
    j->accepted = true;
    g_len = gs_emit_json(&ev, g_line, sizeof g_line);
    printf("bench_sinks: %ld lines of %zu bytes\n", n, g_len);

    int status = 0;
    gs_sink s;
    char err[256];
    if (gs_sink_file_open(&s, "/dev/null", err, sizeof err) == 0) {
        run("file /dev/null", &s, n);
        s.close(s.state);
    }
    status |= bench_tcp(n, k, false);
    status |= bench_tcp(n, k, true);

    /* serial: a pty at 921600 (a pty does not pace bytes: this is the sink's own cost) */
    int m = posix_openpt(O_RDWR | O_NOCTTY);
    if (m >= 0 && grantpt(m) == 0 && unlockpt(m) == 0) {
        gs_sink_serial_cfg sc;
        memset(&sc, 0, sizeof sc);
        snprintf(sc.device, sizeof sc.device, "%s", ptsname(m));
        sc.baud = 921600;
        sc.reopen_s = 1.0;
        sc.queue_lines = 256;
        reader r = spawn_reader(m, -1); /* before the slave is open, so the child does not hold it */
        if (gs_sink_serial_open(&s, &sc, gs_sink_now_s(), err, sizeof err) == 0) {
            run("serial (pty) 921600", &s, n);
            gs_sink_info in;
            s.info(s.state, &in);
            s.close(s.state); /* the slave's last close: the reader gets EIO and stops */
            close(m);
            unsigned long long got = reader_done(r);
            if (got != in.c.bytes_sent) {
                fprintf(stderr, "bench_sinks: pty reader got %llu bytes, sink sent %llu\n", got,
                        (unsigned long long)in.c.bytes_sent);
                status = 1;
            }
        } else {
            fprintf(stderr, "bench_sinks: %s\n", err);
            close(m);
            kill(r.pid, SIGTERM);
            reader_done(r);
        }
    }

    /* UDP to a local socket nobody drains quickly: drops are the kernel's, counted as sent */
    int u = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t al = sizeof a;
    if (bind(u, (struct sockaddr *)&a, sizeof a) == 0 && getsockname(u, (struct sockaddr *)&a, &al) == 0) {
        gs_sink_udp_cfg uc;
        memset(&uc, 0, sizeof uc);
        snprintf(uc.host, sizeof uc.host, "127.0.0.1");
        uc.port = ntohs(a.sin_port);
        if (gs_sink_udp_open(&s, &uc, err, sizeof err) == 0) {
            run("udp loopback", &s, n);
            s.close(s.state);
        }
    }
    close(u);
    return status;
}
