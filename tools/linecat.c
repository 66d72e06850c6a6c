/* linecat.c - copy lines from stdin to the sinks of a profile ([sink.*] and
 * [status] sections; [core] is read and ignored), the way the daemon will:
 * one thread, a poll step every 10 ms, a status line on stderr every
 * [status] interval_s, a drain at end of input or on SIGINT/SIGTERM.
 *   build/gravscale replay --keypoints t.csv | build/linecat --config serial.cfg
 * Exit: 0 ok, 1 bad input (a line longer than the sinks take), 2 usage or
 * configuration (one line naming file, line, section, key), 3 a sink failed. */
#include "gs_sink_config.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define CONFIG_MAX_BYTES (256u * 1024u)

static volatile sig_atomic_t g_stop;
static void on_signal(int sig) { g_stop = sig; }

static void usage(FILE *f)
{
    fprintf(f, "usage: linecat --config PROFILE [--drain-s S]\n"
               "  Reads lines from stdin and writes each to every sink of the profile\n"
               "  ([sink.stdout] [sink.file] [sink.serial] [sink.tcp] [sink.tcp_client] [sink.udp],\n"
               "  [status] interval_s; docs/sinks.md). Status lines go to stderr. At end of\n"
               "  input or on SIGINT/SIGTERM it waits up to S seconds (default 2) for queued lines.\n");
}

static int load(const char *path, gs_core_config *core, gs_sinks_config *sinks)
{
    gs_core_config_default(core);
    gs_sinks_config_default(sinks);
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "linecat: %s: cannot open config: %s\n", path, strerror(errno));
        return 2;
    }
    char *text = malloc(CONFIG_MAX_BYTES + 1);
    size_t n = text ? fread(text, 1, CONFIG_MAX_BYTES + 1, f) : 0;
    fclose(f);
    if (!text || n > CONFIG_MAX_BYTES) {
        fprintf(stderr, "linecat: %s: cannot read config (at most %u bytes)\n", path, CONFIG_MAX_BYTES);
        free(text);
        return 2;
    }
    gs_cfg_section sec[1 + GS_SINKS_CONFIG_SECTIONS];
    sec[0] = (gs_cfg_section){"core", gs_core_config_set, core};
    size_t ns = 1 + gs_sinks_config_sections(sinks, sec + 1, GS_SINKS_CONFIG_SECTIONS);
    gs_cfg_error e;
    gs_status st = gs_cfg_parse(text, n, sec, ns, &e);
    free(text);
    if (st == GS_OK)
        st = gs_sinks_config_check(sinks, &e);
    if (st != GS_OK) {
        fprintf(stderr, "linecat: %s:", path);
        if (e.line > 0)
            fprintf(stderr, "%u:", (unsigned)e.line);
        if (e.section[0])
            fprintf(stderr, " [%s]", e.section);
        if (e.key[0])
            fprintf(stderr, " key '%s'", e.key);
        fprintf(stderr, "%s %s\n", (e.section[0] || e.key[0]) ? ":" : "", e.msg[0] ? e.msg : "invalid");
        return 2;
    }
    return 0;
}

static void status(const gs_sinkset *set, double now_s)
{
    static char buf[8192];
    if (gs_sinkset_status_json(set, buf, sizeof buf))
        fprintf(stderr, "{\"event\":\"status\",\"t_s\":%.3f,\"sinks\":%s}\n", now_s, buf);
}

int main(int argc, char **argv)
{
    const char *cfg_path = NULL;
    double drain_s = 2.0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(argv[i], "--config") && i + 1 < argc) {
            cfg_path = argv[++i];
        } else if (!strcmp(argv[i], "--drain-s") && i + 1 < argc) {
            drain_s = atof(argv[++i]);
        } else {
            usage(stderr);
            return 2;
        }
    }
    if (!cfg_path) {
        usage(stderr);
        return 2;
    }
    gs_core_config core;
    gs_sinks_config sc;
    int rc = load(cfg_path, &core, &sc);
    if (rc)
        return rc;
    gs_sink_ignore_sigpipe(); /* stdout to a closed pipe: an error, not a death */
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    gs_sinkset set;
    char err[256];
    double t0 = gs_sink_now_s();
    if (gs_sinkset_open_config(&set, &sc, t0, err, sizeof err) != 0) {
        fprintf(stderr, "linecat: %s: %s\n", cfg_path, err);
        return 2;
    }
    for (size_t i = 0; i < set.n; i++) {
        uint16_t port = gs_sink_tcp_port(&set.sinks[i]);
        if (port)
            fprintf(stderr, "linecat: tcp sink listening on port %u\n", (unsigned)port);
    }
    static char buf[2 * GS_SINK_LINE_MAX];
    size_t len = 0;
    uint64_t lineno = 0;
    double next_status = sc.status_interval_s > 0 ? sc.status_interval_s : -1.0;
    bool eof = false;
    while (!eof && !g_stop) {
        struct pollfd p = {STDIN_FILENO, POLLIN, 0};
        int r = poll(&p, 1, 10);
        if (r == 1) {
            ssize_t n = read(STDIN_FILENO, buf + len, sizeof buf - len);
            if (n <= 0) {
                if (n < 0 && errno == EINTR)
                    continue;
                eof = true;
            } else {
                len += (size_t)n;
            }
            size_t at = 0;
            for (;;) {
                char *nl = memchr(buf + at, '\n', len - at);
                if (!nl)
                    break;
                size_t ll = (size_t)(nl - (buf + at)) + 1u;
                lineno++;
                if (ll > GS_SINK_LINE_MAX) {
                    fprintf(stderr, "linecat: stdin:%llu: line longer than %u bytes\n",
                            (unsigned long long)lineno, GS_SINK_LINE_MAX);
                    gs_sinkset_close(&set);
                    return 1;
                }
                gs_sinkset_write(&set, buf + at, ll);
                at += ll;
            }
            memmove(buf, buf + at, len - at);
            len -= at;
            if (len == sizeof buf || (eof && len > 0)) {
                fprintf(stderr, "linecat: stdin:%llu: %s\n", (unsigned long long)lineno + 1,
                        eof ? "last line has no newline" : "line too long");
                gs_sinkset_close(&set);
                return 1;
            }
        }
        double now = gs_sink_now_s(); /* the clock gs_sinkset_drain uses too */
        gs_sinkset_poll(&set, now);
        if (next_status >= 0 && now - t0 >= next_status) {
            status(&set, now - t0);
            next_status = now - t0 + sc.status_interval_s;
        }
    }
    uint64_t left = gs_sinkset_drain(&set, drain_s);
    status(&set, gs_sink_now_s() - t0);
    bool failed = false;
    for (size_t i = 0; i < set.n; i++) {
        gs_sink_info in;
        set.sinks[i].info(set.sinks[i].state, &in);
        failed |= in.state == GS_SINK_FAILED;
    }
    gs_sinkset_close(&set);
    if (left)
        fprintf(stderr, "linecat: %llu lines still queued at exit\n", (unsigned long long)left);
    return failed ? 3 : 0;
}
