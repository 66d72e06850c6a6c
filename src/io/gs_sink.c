/* gs_sink.c - the sink set (fan-out, poll, drain, status), the stdout/file sink
 * over gs_out, SIGPIPE and the clock. */
#include "gs_sink.h"
#include "gs_out.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

const char *gs_sink_state_name(gs_sink_state s)
{
    switch (s) {
    case GS_SINK_UP: return "up";
    case GS_SINK_CONNECTING: return "connecting";
    case GS_SINK_RETRYING: return "retrying";
    case GS_SINK_FAILED: return "failed";
    }
    return "unknown";
}

double gs_sink_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int gs_sink_ignore_sigpipe(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = SIG_IGN;
    sigemptyset(&sa.sa_mask);
    return sigaction(SIGPIPE, &sa, NULL);
}

/* ------------------------------------------------------- stdout / file sink */

typedef struct {
    gs_out out;
    char name[96];
    const char *kind;
    uint64_t in, dropped;
} fd_sink;

static int fd_write_line(void *state, const char *line, size_t len)
{
    fd_sink *f = state;
    f->in++;
    if (len == 0 || line[len - 1] != '\n' || len > GS_SINK_LINE_MAX || f->out.err) {
        f->dropped++;
        return -1;
    }
    /* a reader that stopped (a full pipe, a paused terminal) costs lines, never a stall;
     * a pipe with room takes a line of up to PIPE_BUF whole */
    struct pollfd p = {f->out.fd, POLLOUT, 0};
    int r;
    do
        r = poll(&p, 1, 0);
    while (r < 0 && errno == EINTR);
    if (r == 1 && (p.revents & POLLNVAL)) {
        f->out.err = EBADF;
        f->dropped++;
        return -1;
    }
    if (r == 1 && (p.revents & POLLOUT) == 0 && (p.revents & (POLLERR | POLLHUP))) {
        f->out.err = EPIPE;
        f->dropped++;
        return -1;
    }
    if (r != 1) {
        f->dropped++;
        return -1;
    }
    if (gs_out_line(&f->out, line, len) != 0) {
        if (f->out.err == EAGAIN || f->out.err == EWOULDBLOCK)
            f->out.err = 0; /* someone made the descriptor non-blocking: a drop, not a failure */
        f->dropped++;
        return -1;
    }
    return 0;
}

static void fd_poll(void *state, double now_s)
{
    (void)state;
    (void)now_s;
}

static void fd_info(const void *state, gs_sink_info *o)
{
    const fd_sink *f = state;
    memset(o, 0, sizeof *o);
    o->kind = f->kind;
    snprintf(o->target, sizeof o->target, "%s", f->name);
    o->state = f->out.err ? GS_SINK_FAILED : GS_SINK_UP;
    o->last_errno = f->out.err;
    o->c.lines_in = f->in;
    o->c.lines_sent = f->in - f->dropped;
    o->c.lines_dropped = f->dropped;
    o->c.bytes_sent = f->out.bytes;
}

void gs_sink_counters_fill(gs_sink_counters *c, const gs_lineq *q, const gs_lineq_reader *r)
{
    c->lines_in = q->taken;
    c->lines_sent = r->sent;
    c->lines_dropped = r->dropped + gs_lineq_reader_lost(r, q) + q->refused;
    c->bytes_sent = r->bytes;
    c->lines_queued = gs_lineq_reader_pending(r, q);
}

static void fd_close(void *state)
{
    fd_sink *f = state;
    gs_out_close(&f->out);
    free(f);
}

static int fd_make(gs_sink *s, fd_sink *f)
{
    s->state = f;
    s->write_line = fd_write_line;
    s->poll = fd_poll;
    s->info = fd_info;
    s->close = fd_close;
    return 0;
}

int gs_sink_fd_open(gs_sink *s, int fd, const char *name, char *err, size_t cap)
{
    memset(s, 0, sizeof *s);
    fd_sink *f = calloc(1, sizeof *f);
    if (!f || gs_out_open_fd(&f->out, fd, 0) != 0) {
        free(f);
        snprintf(err, cap, "%s: out of memory", name);
        return -1;
    }
    f->kind = "stdout";
    snprintf(f->name, sizeof f->name, "%s", name);
    return fd_make(s, f);
}

int gs_sink_file_open(gs_sink *s, const char *path, char *err, size_t cap)
{
    memset(s, 0, sizeof *s);
    fd_sink *f = calloc(1, sizeof *f);
    if (!f) {
        snprintf(err, cap, "%s: out of memory", path);
        return -1;
    }
    if (gs_out_open_path(&f->out, path, 0) != 0) {
        snprintf(err, cap, "%s: cannot create: %s", path, strerror(errno));
        free(f);
        return -1;
    }
    f->kind = "file";
    snprintf(f->name, sizeof f->name, "%s", path);
    return fd_make(s, f);
}

/* ------------------------------------------------------------------- the set */

void gs_sinkset_init(gs_sinkset *set) { memset(set, 0, sizeof *set); }

int gs_sinkset_add(gs_sinkset *set, const gs_sink *s)
{
    if (set->n >= GS_SINKSET_MAX) {
        s->close(s->state);
        return -1;
    }
    set->sinks[set->n++] = *s;
    return 0;
}

size_t gs_sinkset_write_pair(gs_sinkset *set, const char *line, size_t len, const char *json, size_t json_len)
{
    size_t dropped = 0;
    for (size_t i = 0; i < set->n; i++) {
        bool j = json && set->sinks[i].json_only;
        if (set->sinks[i].write_line(set->sinks[i].state, j ? json : line, j ? json_len : len) != 0)
            dropped++;
    }
    return dropped;
}

size_t gs_sinkset_write(gs_sinkset *set, const char *line, size_t len)
{
    return gs_sinkset_write_pair(set, line, len, NULL, 0);
}

bool gs_sinkset_wants_json(const gs_sinkset *set)
{
    for (size_t i = 0; i < set->n; i++)
        if (set->sinks[i].json_only)
            return true;
    return false;
}

size_t gs_sinkset_write_event(gs_sinkset *set, gs_format fmt, const gs_event *ev)
{
    char line[GS_EMIT_MAX];
    size_t n = gs_emit(fmt, ev, line, sizeof line);
    return n ? gs_sinkset_write(set, line, n) : 0;
}

void gs_sinkset_poll(gs_sinkset *set, double now_s)
{
    for (size_t i = 0; i < set->n; i++)
        set->sinks[i].poll(set->sinks[i].state, now_s);
}

uint64_t gs_sinkset_pending(const gs_sinkset *set)
{
    uint64_t n = 0;
    for (size_t i = 0; i < set->n; i++) {
        gs_sink_info in;
        set->sinks[i].info(set->sinks[i].state, &in);
        if (in.state != GS_SINK_FAILED)
            n += in.c.lines_queued;
    }
    return n;
}

uint64_t gs_sinkset_drain(gs_sinkset *set, double timeout_s)
{
    double t0 = gs_sink_now_s();
    for (;;) {
        double now = gs_sink_now_s();
        gs_sinkset_poll(set, now);
        uint64_t left = gs_sinkset_pending(set);
        if (left == 0 || now - t0 >= timeout_s)
            return left;
        poll(NULL, 0, 5); /* let peers read */
    }
}

size_t gs_sink_status_text(const gs_sink *s, char *buf, size_t cap)
{
    gs_sink_info in;
    s->info(s->state, &in);
    char why[80] = "";
    if (in.last_errno)
        snprintf(why, sizeof why, " (%s)", strerror(in.last_errno));
    int w = snprintf(buf, cap, "%s %s %s%s: %llu sent, %llu dropped, %llu queued, %llu bytes", in.kind, in.target,
                     gs_sink_state_name(in.state), why, (unsigned long long)in.c.lines_sent,
                     (unsigned long long)in.c.lines_dropped, (unsigned long long)in.c.lines_queued,
                     (unsigned long long)in.c.bytes_sent);
    if (w < 0 || (size_t)w >= cap) {
        if (cap)
            buf[0] = '\0';
        return 0;
    }
    return (size_t)w;
}

/* append printf text at *n; false once it no longer fits */
static bool put(char *buf, size_t cap, size_t *n, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static bool put(char *buf, size_t cap, size_t *n, const char *fmt, ...)
{
    if (*n >= cap)
        return false;
    va_list ap;
    va_start(ap, fmt);
    int w = vsnprintf(buf + *n, cap - *n, fmt, ap);
    va_end(ap);
    if (w < 0 || (size_t)w >= cap - *n)
        return false;
    *n += (size_t)w;
    return true;
}

/* the emitter's string rules, so a device or host name that is not UTF-8
 * (found by tests/fuzz/fuzz_sink_config.c) still gives a valid JSON line */
static bool put_json_str(char *buf, size_t cap, size_t *n, const char *s)
{
    size_t m = *n < cap ? gs_emit_json_str(s, buf + *n, cap - *n) : 0;
    *n += m;
    return m > 0;
}

size_t gs_sinkset_status_json(const gs_sinkset *set, char *buf, size_t cap)
{
    size_t n = 0;
    bool ok = cap > 0 && put(buf, cap, &n, "[");
    for (size_t i = 0; ok && i < set->n; i++) {
        gs_sink_info in;
        set->sinks[i].info(set->sinks[i].state, &in);
        ok = put(buf, cap, &n, "%s{\"sink\":\"%s\",\"target\":", i ? "," : "", in.kind) &&
             put_json_str(buf, cap, &n, in.target) &&
             put(buf, cap, &n, ",\"state\":\"%s\",\"error\":", gs_sink_state_name(in.state)) &&
             (in.last_errno ? put_json_str(buf, cap, &n, strerror(in.last_errno)) : put(buf, cap, &n, "null")) &&
             put(buf, cap, &n,
                 ",\"lines_in\":%llu,\"lines_sent\":%llu,\"lines_dropped\":%llu,\"bytes_sent\":%llu,"
                 "\"lines_queued\":%llu,\"clients\":%u,\"reopens\":%llu,\"refused\":%llu}",
                 (unsigned long long)in.c.lines_in, (unsigned long long)in.c.lines_sent,
                 (unsigned long long)in.c.lines_dropped, (unsigned long long)in.c.bytes_sent,
                 (unsigned long long)in.c.lines_queued, (unsigned)in.c.clients,
                 (unsigned long long)in.c.reopens, (unsigned long long)in.c.refused);
    }
    ok = ok && put(buf, cap, &n, "]");
    if (!ok) {
        if (cap)
            buf[0] = '\0';
        return 0;
    }
    return n;
}

void gs_sinkset_close(gs_sinkset *set)
{
    for (size_t i = 0; i < set->n; i++)
        set->sinks[i].close(set->sinks[i].state);
    set->n = 0;
}
