/* test_sink_config.c - the [sink.*] and [status] sections through gs_cfg_parse
 * (values, errors naming line, section and key, checks after parsing), a sink
 * set opened from a profile fanning the same bytes out to a file, a TCP client
 * and a UDP socket, its status JSON, drain, and the stdout sink on a pipe that
 * fills up or loses its reader. */
#include "gs_sink_config.h"
#include "unity.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#define EQ_SZ(a, b) TEST_ASSERT_EQUAL_UINT64((uint64_t)(a), (uint64_t)(b))

void setUp(void) {}
void tearDown(void) {}

static gs_core_config g_core;
static gs_sinks_config g_sinks;

static gs_status parse(const char *text, gs_cfg_error *err)
{
    gs_core_config_default(&g_core);
    gs_sinks_config_default(&g_sinks);
    gs_cfg_section sec[1 + GS_SINKS_CONFIG_SECTIONS];
    sec[0] = (gs_cfg_section){"core", gs_core_config_set, &g_core};
    size_t n = gs_sinks_config_sections(&g_sinks, sec + 1, GS_SINKS_CONFIG_SECTIONS);
    TEST_ASSERT_EQUAL_UINT(GS_SINKS_CONFIG_SECTIONS, n);
    memset(err, 0, sizeof *err);
    gs_status st = gs_cfg_parse(text, strlen(text), sec, 1 + n, err);
    if (st == GS_OK)
        st = gs_sinks_config_check(&g_sinks, err);
    return st;
}

void test_defaults(void)
{
    gs_cfg_error e;
    TEST_ASSERT_EQUAL_INT(GS_OK, parse("", &e));
    TEST_ASSERT_TRUE(gs_sinks_config_on(&g_sinks.stdout_sw, true));
    TEST_ASSERT_FALSE(gs_sinks_config_on(&g_sinks.serial_sw, false));
    TEST_ASSERT_FALSE(gs_sinks_config_on(&g_sinks.tcp_sw, false));
    TEST_ASSERT_EQUAL_STRING("127.0.0.1", g_sinks.tcp.bind);
    TEST_ASSERT_FALSE(g_sinks.tcp.allow_remote);
    TEST_ASSERT_EQUAL_UINT(7878, g_sinks.tcp.port);
    TEST_ASSERT_EQUAL_UINT(115200, g_sinks.serial.baud);
    TEST_ASSERT_EQUAL_DOUBLE(1.0, g_sinks.status_interval_s);
}

void test_every_key(void)
{
    const char *text = "[core]\nfit = irls\n"
                       "[sink.stdout]\nenabled = no\n"
                       "[sink.file]\npath = /tmp/x#1.jsonl\n"
                       "[sink.serial]\ndevice = /dev/ttyUSB0\nbaud = 921600\nreopen_s = 2.5\nqueue_lines = 32\n"
                       "[sink.tcp]\nbind = 0.0.0.0  # written out: remote clients are meant\nport = 0\n"
                       "max_clients = 3\nqueue_lines = 100\nsndbuf_bytes = 8192\n"
                       "[sink.tcp_client]\nhost = collector.local\nport = 9000\nbackoff_min_s = 0.25\n"
                       "backoff_max_s = 8\nqueue_lines = 500\n"
                       "[sink.udp]\nhost = ::1\nport = 5005\n"
                       "[status]\ninterval_s = 0.5\n";
    gs_cfg_error e;
    TEST_ASSERT_EQUAL_INT_MESSAGE(GS_OK, parse(text, &e), e.msg);
    TEST_ASSERT_FALSE(gs_sinks_config_on(&g_sinks.stdout_sw, true));
    TEST_ASSERT_TRUE(gs_sinks_config_on(&g_sinks.file_sw, false));
    TEST_ASSERT_EQUAL_STRING("/tmp/x#1.jsonl", g_sinks.file_path);
    TEST_ASSERT_TRUE(gs_sinks_config_on(&g_sinks.serial_sw, false));
    TEST_ASSERT_EQUAL_STRING("/dev/ttyUSB0", g_sinks.serial.device);
    TEST_ASSERT_EQUAL_UINT(921600, g_sinks.serial.baud);
    TEST_ASSERT_EQUAL_DOUBLE(2.5, g_sinks.serial.reopen_s);
    TEST_ASSERT_EQUAL_UINT(32, g_sinks.serial.queue_lines);
    TEST_ASSERT_EQUAL_STRING("0.0.0.0", g_sinks.tcp.bind);
    TEST_ASSERT_TRUE(g_sinks.tcp.allow_remote);
    TEST_ASSERT_EQUAL_UINT(0, g_sinks.tcp.port);
    TEST_ASSERT_EQUAL_UINT(3, g_sinks.tcp.max_clients);
    TEST_ASSERT_EQUAL_UINT(100, g_sinks.tcp.queue_lines);
    TEST_ASSERT_EQUAL_UINT(8192, g_sinks.tcp.sndbuf_bytes);
    TEST_ASSERT_EQUAL_STRING("collector.local", g_sinks.tcp_client.host);
    TEST_ASSERT_EQUAL_UINT(9000, g_sinks.tcp_client.port);
    TEST_ASSERT_EQUAL_DOUBLE(0.25, g_sinks.tcp_client.backoff_min_s);
    TEST_ASSERT_EQUAL_DOUBLE(8.0, g_sinks.tcp_client.backoff_max_s);
    TEST_ASSERT_EQUAL_UINT(500, g_sinks.tcp_client.queue_lines);
    TEST_ASSERT_EQUAL_STRING("::1", g_sinks.udp.host);
    TEST_ASSERT_EQUAL_UINT(5005, g_sinks.udp.port);
    TEST_ASSERT_EQUAL_DOUBLE(0.5, g_sinks.status_interval_s);
    /* a section switched off keeps its keys but is off */
    TEST_ASSERT_EQUAL_INT(GS_OK, parse("[sink.serial]\ndevice = /dev/ttyS1\nenabled = no\n", &e));
    TEST_ASSERT_FALSE(gs_sinks_config_on(&g_sinks.serial_sw, false));
}

typedef struct {
    const char *text;
    gs_status st;
    uint32_t line;
    const char *section, *key, *msg_part;
} bad_case;

void test_bad_files_name_line_section_and_key(void)
{
    static const bad_case cases[] = {
        {"[sink.serial]\ndevice = /dev/ttyS0\nspeed = 9600\n", GS_ENOKEY, 3, "sink.serial", "speed", "unknown key"},
        {"[sink.serial]\nbaud = 12345\n", GS_ERANGE, 2, "sink.serial", "baud", "unsupported baud"},
        {"[sink.serial]\nbaud = 96OO\n", GS_EINVAL, 2, "sink.serial", "baud", "not an integer"},
        {"[sink.serial]\ndevice =\n", GS_EINVAL, 2, "sink.serial", "device", "empty"},
        {"[sink.serial]\nreopen_s = 0\n", GS_ERANGE, 2, "sink.serial", "reopen_s", "out of range"},
        {"[sink.serial]\nqueue_lines = 0\n", GS_ERANGE, 2, "sink.serial", "queue_lines", "out of range"},
        {"[sink.tcp]\nport = 70000\n", GS_ERANGE, 2, "sink.tcp", "port", "out of range"},
        {"[sink.tcp]\nport = -1\n", GS_ERANGE, 2, "sink.tcp", "port", "out of range"},
        {"[sink.tcp]\nbind = localhost\n", GS_EINVAL, 2, "sink.tcp", "bind", "numeric"},
        {"[sink.tcp]\nbind = 127.0.0.1:80\n", GS_EINVAL, 2, "sink.tcp", "bind", "numeric"},
        {"[sink.tcp]\nmax_clients = 0\n", GS_ERANGE, 2, "sink.tcp", "max_clients", "out of range"},
        {"[sink.tcp]\nenabled = maybe\n", GS_EINVAL, 2, "sink.tcp", "enabled", "yes or no"},
        {"[sink.tcp]\nport = 1\nport = 2\n", GS_EINVAL, 3, "sink.tcp", "port", "duplicate"},
        {"[sink.tcp_client]\nport = 0\n", GS_ERANGE, 2, "sink.tcp_client", "port", "out of range"},
        {"[sink.tcp_client]\nbackoff_min_s = nan\n", GS_EINVAL, 2, "sink.tcp_client", "backoff_min_s", "number"},
        {"[sink.udp]\nhost = 127.0.0.1\nport = 1e3\n", GS_EINVAL, 3, "sink.udp", "port", "not an integer"},
        {"[status]\ninterval_s = -1\n", GS_ERANGE, 2, "status", "interval_s", "out of range"},
        {"[status]\nformat = json\n", GS_ENOKEY, 2, "status", "format", "unknown key"},
        {"[sink.pigeon]\nport = 1\n", GS_ENOKEY, 1, "sink.pigeon", "", "unknown section"},
        /* checks after parsing: line 0, the missing key named */
        {"[sink.serial]\nbaud = 9600\n", GS_EINVAL, 0, "sink.serial", "device", "needs a device"},
        {"[sink.file]\nenabled = yes\n", GS_EINVAL, 0, "sink.file", "path", "needs a path"},
        {"[sink.tcp_client]\nport = 9\n", GS_EINVAL, 0, "sink.tcp_client", "host", "needs a host"},
        {"[sink.tcp_client]\nhost = a\n", GS_EINVAL, 0, "sink.tcp_client", "port", "needs a port"},
        {"[sink.tcp_client]\nhost = a\nport = 9\nbackoff_min_s = 5\nbackoff_max_s = 1\n", GS_ERANGE, 0,
         "sink.tcp_client", "backoff_max_s", "below"},
        {"[sink.udp]\nport = 9\n", GS_EINVAL, 0, "sink.udp", "host", "needs a host"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gs_cfg_error e;
        char label[160];
        snprintf(label, sizeof label, "case %u: %s", (unsigned)i, cases[i].text);
        TEST_ASSERT_EQUAL_INT_MESSAGE(cases[i].st, parse(cases[i].text, &e), label);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(cases[i].line, e.line, label);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(cases[i].section, e.section, label);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(cases[i].key, e.key, label);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(e.msg, cases[i].msg_part), label);
    }
}

/* ------------------------------------------------------------ a whole set */

static uint16_t bound_port(int fd)
{
    struct sockaddr_in a;
    socklen_t l = sizeof a;
    TEST_ASSERT_EQUAL_INT(0, getsockname(fd, (struct sockaddr *)&a, &l));
    return ntohs(a.sin_port);
}

static int udp_receiver(void)
{
    int r = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    TEST_ASSERT_EQUAL_INT(0, bind(r, (struct sockaddr *)&a, sizeof a));
    return r;
}

static size_t recv_all(int fd, char *buf, size_t cap, int wait_ms)
{
    size_t n = 0;
    for (;;) {
        struct pollfd p = {fd, POLLIN, 0};
        if (poll(&p, 1, wait_ms) != 1)
            break;
        ssize_t r = recv(fd, buf + n, cap - n, 0);
        if (r <= 0)
            break;
        n += (size_t)r;
    }
    return n;
}

void test_sinkset_from_profile_fans_out_the_same_bytes(void)
{
    char path[] = "/tmp/gs_sinkset_XXXXXX";
    int tmpfd = mkstemp(path);
    TEST_ASSERT_TRUE(tmpfd >= 0);
    close(tmpfd);
    int ur = udp_receiver();
    char text[512];
    snprintf(text, sizeof text,
             "[sink.stdout]\nenabled = no\n[sink.file]\npath = %s\n[sink.tcp]\nport = 0\n"
             "[sink.udp]\nhost = 127.0.0.1\nport = %u\n",
             path, (unsigned)bound_port(ur));
    gs_cfg_error e;
    TEST_ASSERT_EQUAL_INT_MESSAGE(GS_OK, parse(text, &e), e.msg);
    gs_sinkset set;
    char err[256] = "";
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sinkset_open_config(&set, &g_sinks, 0.0, err, sizeof err), err);
    EQ_SZ(3, set.n);
    uint16_t port = gs_sink_tcp_port(&set.sinks[1]);
    TEST_ASSERT_TRUE(port > 0);
    int c = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    TEST_ASSERT_EQUAL_INT(0, connect(c, (struct sockaddr *)&a, sizeof a));
    for (int k = 0; k < 100; k++) {
        gs_sinkset_poll(&set, 0.0);
        gs_sink_info in;
        set.sinks[1].info(set.sinks[1].state, &in);
        if (in.c.clients == 1)
            break;
        poll(NULL, 0, 2);
    }

    /* real events through the emitter, both formats */
    gs_event ev;
    memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_START;
    ev.u.start.version = "0.1.0";
    ev.u.start.config = "test";
    ev.u.start.fps_source = 30.0;
    ev.u.start.fps_origin = "timestamps";
    ev.u.start.layout = "coco17";
    char want[4 * GS_EMIT_MAX];
    size_t wn = 0;
    EQ_SZ(0, gs_sinkset_write_event(&set, GS_FMT_JSON, &ev));
    wn += gs_emit(GS_FMT_JSON, &ev, want + wn, sizeof want - wn);
    EQ_SZ(0, gs_sinkset_write_event(&set, GS_FMT_NMEA, &ev));
    size_t nmea_at = wn;
    wn += gs_emit(GS_FMT_NMEA, &ev, want + wn, sizeof want - wn);
    memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_HEIGHT;
    ev.u.height.height_m = 1.735;
    ev.u.height.ci95_lo_m = 1.63;
    ev.u.height.ci95_hi_m = NAN;
    ev.u.height.n_jumps = 1;
    EQ_SZ(0, gs_sinkset_write_event(&set, GS_FMT_JSON, &ev));
    size_t h_at = wn;
    wn += gs_emit(GS_FMT_JSON, &ev, want + wn, sizeof want - wn);
    TEST_ASSERT_TRUE(wn > h_at && h_at > nmea_at && nmea_at > 0);
    TEST_ASSERT_EQUAL_UINT64(0, gs_sinkset_drain(&set, 1.0));

    char got[4 * GS_EMIT_MAX];
    size_t gn = recv_all(c, got, sizeof got, 100);
    EQ_SZ(wn, gn);
    TEST_ASSERT_EQUAL_MEMORY(want, got, wn);
    /* UDP: three datagrams, one line each */
    const size_t cut[4] = {0, nmea_at, h_at, wn};
    for (int k = 0; k < 3; k++) {
        struct pollfd p = {ur, POLLIN, 0};
        TEST_ASSERT_EQUAL_INT(1, poll(&p, 1, 200));
        ssize_t r = recv(ur, got, sizeof got, 0);
        EQ_SZ(cut[k + 1] - cut[k], r);
        TEST_ASSERT_EQUAL_MEMORY(want + cut[k], got, (size_t)r);
    }
    /* status: one object per sink, counters as sent */
    char st[2048];
    size_t sn = gs_sinkset_status_json(&set, st, sizeof st);
    TEST_ASSERT_TRUE(sn > 0);
    EQ_SZ(strlen(st), sn);
    TEST_ASSERT_EQUAL_INT('[', st[0]);
    TEST_ASSERT_EQUAL_INT(']', st[sn - 1]);
    char frag[256];
    snprintf(frag, sizeof frag, "{\"sink\":\"file\",\"target\":\"%s\",\"state\":\"up\",\"error\":null,"
             "\"lines_in\":3,\"lines_sent\":3,\"lines_dropped\":0,\"bytes_sent\":%u,", path, (unsigned)wn);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(st, frag), st);
    snprintf(frag, sizeof frag, "{\"sink\":\"tcp\",\"target\":\"127.0.0.1:%u\",\"state\":\"up\"", (unsigned)port);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(st, frag), st);
    TEST_ASSERT_NOT_NULL(strstr(st, "\"clients\":1,"));
    TEST_ASSERT_NOT_NULL(strstr(st, "{\"sink\":\"udp\""));
    TEST_ASSERT_EQUAL_UINT(0, gs_sinkset_status_json(&set, st, 40)); /* too small: "" */
    TEST_ASSERT_EQUAL_STRING("", st);
    gs_sinkset_close(&set);
    EQ_SZ(0, set.n);

    /* the file holds the same bytes */
    FILE *f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL(f);
    gn = fread(got, 1, sizeof got, f);
    fclose(f);
    EQ_SZ(wn, gn);
    TEST_ASSERT_EQUAL_MEMORY(want, got, wn);
    close(c);
    close(ur);
    unlink(path);
}

void test_open_failure_names_the_sink_and_leaves_nothing_open(void)
{
    gs_cfg_error e;
    TEST_ASSERT_EQUAL_INT(GS_OK, parse("[sink.stdout]\nenabled = no\n[sink.tcp]\nport = 0\n"
                                       "[sink.serial]\ndevice = /nonexistent/ttyACM9\n",
                                       &e));
    gs_sinkset set;
    char err[256] = "";
    TEST_ASSERT_EQUAL_INT(-1, gs_sinkset_open_config(&set, &g_sinks, 0.0, err, sizeof err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "serial /nonexistent/ttyACM9"), err);
    EQ_SZ(0, set.n);
}

void test_stdout_sink_on_a_full_pipe_and_a_closed_one(void)
{
    TEST_ASSERT_EQUAL_INT(0, gs_sink_ignore_sigpipe());
    struct sigaction sa;
    sigaction(SIGPIPE, NULL, &sa);
    TEST_ASSERT_TRUE(sa.sa_handler == SIG_IGN);
    int p[2];
    TEST_ASSERT_EQUAL_INT(0, pipe(p));
    gs_sink s;
    char err[128];
    TEST_ASSERT_EQUAL_INT(0, gs_sink_fd_open(&s, p[1], "stdout", err, sizeof err));
    /* nobody reads: the pipe fills and later lines are dropped, never waited for */
    char line[1001];
    memset(line, 'x', 1000);
    line[1000] = '\n';
    unsigned taken = 0;
    for (int i = 0; i < 400; i++)
        taken += s.write_line(s.state, line, sizeof line) == 0;
    gs_sink_info in;
    s.info(s.state, &in);
    EQ_SZ(400, in.c.lines_in);
    EQ_SZ(taken, in.c.lines_sent);
    EQ_SZ(400 - taken, in.c.lines_dropped);
    TEST_ASSERT_TRUE(taken > 10 && taken < 400);
    EQ_SZ((uint64_t)taken * sizeof line, in.c.bytes_sent);
    /* what is in the pipe is whole lines */
    static char buf[1 << 20];
    fcntl(p[0], F_SETFL, O_NONBLOCK);
    ssize_t n = read(p[0], buf, sizeof buf);
    EQ_SZ((uint64_t)taken * sizeof line, n);
    /* the reader goes away: EPIPE, the sink fails for good, no signal */
    close(p[0]);
    TEST_ASSERT_EQUAL_INT(-1, s.write_line(s.state, line, sizeof line));
    s.info(s.state, &in);
    TEST_ASSERT_EQUAL_INT(GS_SINK_FAILED, in.state);
    TEST_ASSERT_EQUAL_INT(EPIPE, in.last_errno);
    TEST_ASSERT_EQUAL_INT(-1, s.write_line(s.state, line, sizeof line));
    s.info(s.state, &in);
    EQ_SZ(400 - taken + 2, in.c.lines_dropped);
    s.close(s.state); /* not its descriptor: the caller's */
    TEST_ASSERT_EQUAL_INT(0, close(p[1]));
}

/* a name that is not UTF-8 or holds control bytes still gives valid JSON
 * (found by tests/fuzz/fuzz_sink_config.c: host = "loc\x9alhost") */
void test_status_json_escapes_any_name(void)
{
    int fd = open("/dev/null", O_WRONLY);
    TEST_ASSERT_TRUE(fd >= 0);
    gs_sinkset set;
    gs_sinkset_init(&set);
    gs_sink s;
    char err[160];
    TEST_ASSERT_EQUAL_INT(0, gs_sink_fd_open(&s, fd, "loc\x9alhost \"a\\b\"\t\xc3\xa9", err, sizeof err));
    TEST_ASSERT_EQUAL_INT(0, gs_sinkset_add(&set, &s));
    char st[1024];
    size_t n = gs_sinkset_status_json(&set, st, sizeof st);
    TEST_ASSERT_TRUE(n > 0);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(st, "\"target\":\"loc\\ufffdlhost \\\"a\\\\b\\\"\\u0009\xc3\xa9\",\"state\""), st);
    /* every cap up to the full size: "" and 0, never a cut line */
    for (size_t cap = 1; cap <= n; cap++) {
        char small[1024];
        TEST_ASSERT_EQUAL_UINT(0, gs_sinkset_status_json(&set, small, cap));
        TEST_ASSERT_EQUAL_STRING("", small);
    }
    gs_sinkset_close(&set);
    close(fd);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_defaults);
    RUN_TEST(test_every_key);
    RUN_TEST(test_bad_files_name_line_section_and_key);
    RUN_TEST(test_sinkset_from_profile_fans_out_the_same_bytes);
    RUN_TEST(test_open_failure_names_the_sink_and_leaves_nothing_open);
    RUN_TEST(test_stdout_sink_on_a_full_pipe_and_a_closed_one);
    RUN_TEST(test_status_json_escapes_any_name);
    return UNITY_END();
}
