/* test_sink_serial.c - the serial sink through pseudo-terminal pairs: the bytes
 * and the line framing at the master side, raw 8N1 at the configured baud, an
 * unplug (the master closed) seen by poll and by write, the device reopened
 * through a symlink once it is back, and a full queue dropping whole lines. */
#define _XOPEN_SOURCE 700 /* posix_openpt, grantpt, unlockpt, ptsname */
#include "gs_sink.h"
#include "unity.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#define EQ_SZ(a, b) TEST_ASSERT_EQUAL_UINT64((uint64_t)(a), (uint64_t)(b))

void setUp(void) {}
void tearDown(void) {}

/* ------------------------------------------------------------------ helpers */

/* a pty pair: master fd, slave path (nobody holds the slave open) */
static int open_pty(char *slave, size_t cap)
{
    int m = posix_openpt(O_RDWR | O_NOCTTY);
    TEST_ASSERT_TRUE_MESSAGE(m >= 0, "posix_openpt");
    TEST_ASSERT_EQUAL_INT(0, grantpt(m));
    TEST_ASSERT_EQUAL_INT(0, unlockpt(m));
    const char *p = ptsname(m);
    TEST_ASSERT_NOT_NULL(p);
    snprintf(slave, cap, "%s", p);
    int fl = fcntl(m, F_GETFL);
    fcntl(m, F_SETFL, fl | O_NONBLOCK);
    return m;
}

/* Line i: JSON-like with bytes a cooked tty would change (tab, CR), every third
 * an NMEA-style sentence ending in CR LF; lengths vary. */
static size_t make_line(char *buf, size_t cap, unsigned i)
{
    char pad[256];
    unsigned n = (i * 37u) % 200u;
    for (unsigned k = 0; k < n; k++)
        pad[k] = (char)('a' + (i + k) % 26u);
    pad[n] = '\0';
    int w = (i % 3u == 2u) ? snprintf(buf, cap, "$GSTST,%06u,%s*00\r\n", i, pad)
                           : snprintf(buf, cap, "{\"event\":\"test\",\"i\":%06u,\"p\":\"\t%s\"}\n", i, pad);
    TEST_ASSERT_TRUE(w > 0 && (size_t)w < cap);
    return (size_t)w;
}

/* the number a received line carries, after checking it is exactly line i */
static unsigned check_line(const char *s, size_t n)
{
    const char *d = memchr(s, ',', n);
    unsigned i;
    if (s[0] == '$')
        TEST_ASSERT_EQUAL_INT(1, sscanf(s, "$GSTST,%u,", &i));
    else {
        d = strstr(s, "\"i\":");
        TEST_ASSERT_NOT_NULL(d);
        TEST_ASSERT_EQUAL_INT(1, sscanf(d, "\"i\":%u", &i));
    }
    char want[512];
    size_t wn = make_line(want, sizeof want, i);
    EQ_SZ(wn, n);
    TEST_ASSERT_EQUAL_MEMORY(want, s, n);
    return i;
}

/* read whatever the master has, waiting up to idle_ms for more; returns bytes */
static size_t read_master(int m, char *buf, size_t cap, int idle_ms)
{
    size_t n = 0;
    while (n < cap) {
        struct pollfd p = {m, POLLIN, 0};
        if (poll(&p, 1, idle_ms) != 1 || !(p.revents & POLLIN))
            break;
        ssize_t r = read(m, buf + n, cap - n);
        if (r <= 0)
            break;
        n += (size_t)r;
    }
    return n;
}

/* split buf into lines; each is checked and its number stored; returns count.
 * A tail without '\n' fails the test: only whole lines may arrive. */
static size_t split_lines(const char *buf, size_t n, unsigned *nums, size_t cap)
{
    size_t k = 0, at = 0;
    while (at < n) {
        const char *nl = memchr(buf + at, '\n', n - at);
        TEST_ASSERT_NOT_NULL_MESSAGE(nl, "a partial line arrived");
        size_t len = (size_t)(nl - (buf + at)) + 1u;
        TEST_ASSERT_TRUE(k < cap);
        nums[k++] = check_line(buf + at, len);
        at += len;
    }
    return k;
}

static gs_sink_serial_cfg cfg_for(const char *dev, uint32_t baud, uint32_t queue)
{
    gs_sink_serial_cfg c;
    memset(&c, 0, sizeof c);
    snprintf(c.device, sizeof c.device, "%s", dev);
    c.baud = baud;
    c.reopen_s = 1.0;
    c.queue_lines = queue;
    return c;
}

static gs_sink_info info_of(const gs_sink *s)
{
    gs_sink_info in;
    s->info(s->state, &in);
    return in;
}

static void write_lines(gs_sink *s, unsigned from, unsigned to)
{
    char line[512];
    for (unsigned i = from; i < to; i++) {
        size_t n = make_line(line, sizeof line, i);
        TEST_ASSERT_EQUAL_INT(0, s->write_line(s->state, line, n));
    }
}

/* expect exactly lines [from, to) at master m */
static void expect_lines(int m, unsigned from, unsigned to)
{
    static char buf[1 << 16];
    static unsigned nums[4096];
    size_t n = read_master(m, buf, sizeof buf, 100);
    size_t k = split_lines(buf, n, nums, 4096);
    EQ_SZ(to - from, k);
    for (size_t j = 0; j < k; j++)
        TEST_ASSERT_EQUAL_UINT(from + j, nums[j]);
}

/* the slave's settings, read through a second descriptor */
static void expect_raw(const char *dev, speed_t speed)
{
    int fd = open(dev, O_RDWR | O_NOCTTY | O_NONBLOCK);
    TEST_ASSERT_TRUE(fd >= 0);
    struct termios t;
    TEST_ASSERT_EQUAL_INT(0, tcgetattr(fd, &t));
    close(fd);
    TEST_ASSERT_EQUAL_UINT(speed, cfgetospeed(&t));
    TEST_ASSERT_EQUAL_UINT(speed, cfgetispeed(&t));
    TEST_ASSERT_EQUAL_UINT(CS8, t.c_cflag & CSIZE);
    TEST_ASSERT_EQUAL_UINT(0, t.c_cflag & (PARENB | CSTOPB));
    TEST_ASSERT_EQUAL_UINT(0, t.c_oflag & OPOST);
    TEST_ASSERT_EQUAL_UINT(0, t.c_lflag & (ICANON | ECHO | ISIG | IEXTEN));
    TEST_ASSERT_EQUAL_UINT(0, t.c_iflag & (ICRNL | INLCR | IXON | ISTRIP));
}

/* -------------------------------------------------------------------- tests */

void test_sigpipe_is_default_here(void)
{
    /* the sinks must not need SIGPIPE ignored: the tests run with the default */
    struct sigaction sa;
    TEST_ASSERT_EQUAL_INT(0, sigaction(SIGPIPE, NULL, &sa));
    TEST_ASSERT_TRUE(sa.sa_handler == SIG_DFL);
}

void test_bytes_and_framing_at_the_other_end(void)
{
    char dev[128];
    int m = open_pty(dev, sizeof dev);
    gs_sink s;
    char err[256] = "";
    gs_sink_serial_cfg c = cfg_for(dev, 115200, 64);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_serial_open(&s, &c, 0.0, err, sizeof err), err);
    expect_raw(dev, B115200);
    write_lines(&s, 0, 40);
    s.poll(s.state, 0.01);
    expect_lines(m, 0, 40);
    gs_sink_info in = info_of(&s);
    TEST_ASSERT_EQUAL_STRING("serial", in.kind);
    TEST_ASSERT_EQUAL_INT(GS_SINK_UP, in.state);
    TEST_ASSERT_EQUAL_UINT64(40, in.c.lines_in);
    TEST_ASSERT_EQUAL_UINT64(40, in.c.lines_sent);
    TEST_ASSERT_EQUAL_UINT64(0, in.c.lines_dropped);
    TEST_ASSERT_EQUAL_UINT64(0, in.c.lines_queued);
    uint64_t bytes = 0;
    char line[512];
    for (unsigned i = 0; i < 40; i++)
        bytes += make_line(line, sizeof line, i);
    TEST_ASSERT_EQUAL_UINT64(bytes, in.c.bytes_sent);
    /* a line without its newline is refused and counted, never sent in part */
    TEST_ASSERT_EQUAL_INT(-1, s.write_line(s.state, "no newline", 10));
    TEST_ASSERT_EQUAL_UINT64(1, info_of(&s).c.lines_dropped);
    EQ_SZ(0, read_master(m, line, sizeof line, 20));
    s.close(s.state);
    close(m);
}

void test_every_baud_and_bad_ones(void)
{
    static const struct {
        uint32_t baud;
        speed_t code;
    } ok[] = {{9600, B9600},     {19200, B19200},   {38400, B38400},   {57600, B57600},
              {115200, B115200}, {230400, B230400}, {460800, B460800}, {921600, B921600}};
    char dev[128], err[256];
    int m = open_pty(dev, sizeof dev);
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        gs_sink s;
        gs_sink_serial_cfg c = cfg_for(dev, ok[i].baud, 4);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_serial_open(&s, &c, 0.0, err, sizeof err), err);
        expect_raw(dev, ok[i].code);
        s.close(s.state);
    }
    const uint32_t bad[] = {0, 300, 4800, 14400, 115201, 1000000};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        gs_sink s;
        gs_sink_serial_cfg c = cfg_for(dev, bad[i], 4);
        err[0] = '\0';
        TEST_ASSERT_EQUAL_INT(-1, gs_sink_serial_open(&s, &c, 0.0, err, sizeof err));
        TEST_ASSERT_NOT_NULL(strstr(err, "unsupported baud"));
        TEST_ASSERT_NOT_NULL(strstr(err, dev));
    }
    close(m);
}

void test_missing_device_and_not_a_tty(void)
{
    gs_sink s;
    char err[256] = "";
    gs_sink_serial_cfg c = cfg_for("/nonexistent/ttyGS0", 9600, 4);
    TEST_ASSERT_EQUAL_INT(-1, gs_sink_serial_open(&s, &c, 0.0, err, sizeof err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "/nonexistent/ttyGS0"), err);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, strerror(ENOENT)), err);
    c = cfg_for("/dev/null", 9600, 4);
    TEST_ASSERT_EQUAL_INT(-1, gs_sink_serial_open(&s, &c, 0.0, err, sizeof err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "not a terminal"), err);
}

void test_unplug_queue_and_reopen_through_symlink(void)
{
    char dir[] = "/tmp/gs_serial_XXXXXX";
    TEST_ASSERT_NOT_NULL(mkdtemp(dir));
    char link[64];
    snprintf(link, sizeof link, "%s/ttyGS", dir);
    char dev[128];
    int m = open_pty(dev, sizeof dev);
    TEST_ASSERT_EQUAL_INT(0, symlink(dev, link));

    gs_sink s;
    char err[256] = "";
    gs_sink_serial_cfg c = cfg_for(link, 57600, 32);
    c.reopen_s = 1.0;
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_serial_open(&s, &c, 0.0, err, sizeof err), err);
    write_lines(&s, 0, 3);
    expect_lines(m, 0, 3);

    /* unplug: the other side goes away; poll sees the hang-up */
    close(m);
    s.poll(s.state, 0.1);
    gs_sink_info in = info_of(&s);
    TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, in.state);
    TEST_ASSERT_EQUAL_UINT64(3, in.c.lines_sent);
    write_lines(&s, 3, 10); /* queued meanwhile */
    TEST_ASSERT_EQUAL_UINT64(7, info_of(&s).c.lines_queued);
    char text[256], want[256];
    uint64_t b3 = 0;
    for (unsigned i = 0; i < 3; i++)
        b3 += make_line(want, sizeof want, i);
    snprintf(want, sizeof want, "serial %s@57600 retrying (%s): 3 sent, 0 dropped, 7 queued, %llu bytes", link,
             strerror(EIO), (unsigned long long)b3);
    TEST_ASSERT_TRUE(gs_sink_status_text(&s, text, sizeof text) > 0);
    TEST_ASSERT_EQUAL_STRING(want, text);

    /* the device comes back under the same name */
    m = open_pty(dev, sizeof dev);
    TEST_ASSERT_EQUAL_INT(0, unlink(link));
    TEST_ASSERT_EQUAL_INT(0, symlink(dev, link));
    s.poll(s.state, 0.6); /* before reopen_s: not yet */
    TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, info_of(&s).state);
    char tmp[64];
    EQ_SZ(0, read_master(m, tmp, sizeof tmp, 20));
    s.poll(s.state, 1.15);
    in = info_of(&s);
    TEST_ASSERT_EQUAL_INT(GS_SINK_UP, in.state);
    TEST_ASSERT_EQUAL_UINT64(1, in.c.reopens);
    expect_raw(dev, B57600); /* the new device is configured again */
    expect_lines(m, 3, 10);

    /* second unplug, noticed by a write this time; a reopen attempt while it is
     * still missing fails quietly and is retried */
    close(m);
    unlink(link);
    write_lines(&s, 10, 14);
    TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, info_of(&s).state);
    s.poll(s.state, 2.5);
    TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, info_of(&s).state);
    TEST_ASSERT_EQUAL_INT(ENOENT, info_of(&s).last_errno);
    m = open_pty(dev, sizeof dev);
    TEST_ASSERT_EQUAL_INT(0, symlink(dev, link));
    s.poll(s.state, 3.0); /* next attempt at 2.5 + 1.0 */
    TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, info_of(&s).state);
    s.poll(s.state, 3.6);
    TEST_ASSERT_EQUAL_INT(GS_SINK_UP, info_of(&s).state);
    expect_lines(m, 10, 14);
    in = info_of(&s);
    TEST_ASSERT_EQUAL_UINT64(14, in.c.lines_sent);
    TEST_ASSERT_EQUAL_UINT64(0, in.c.lines_dropped);
    TEST_ASSERT_EQUAL_UINT64(2, in.c.reopens);

    s.close(s.state);
    close(m);
    unlink(link);
    rmdir(dir);
}

void test_queue_overflow_drops_whole_oldest_lines(void)
{
    char dev[128], err[256] = "";
    int m = open_pty(dev, sizeof dev);
    gs_sink s;
    gs_sink_serial_cfg c = cfg_for(dev, 921600, 8);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_serial_open(&s, &c, 0.0, err, sizeof err), err);
    /* nobody reads the master: the tty buffer fills, then the queue, then the
     * oldest queued lines go */
    const unsigned N = 5000;
    write_lines(&s, 0, N);
    gs_sink_info in = info_of(&s);
    TEST_ASSERT_EQUAL_UINT64(N, in.c.lines_in);
    TEST_ASSERT_TRUE(in.c.lines_dropped > 0);
    TEST_ASSERT_TRUE(in.c.lines_queued <= 8 + 1); /* 8 in the queue, one in hand */
    TEST_ASSERT_EQUAL_UINT64(N, in.c.lines_sent + in.c.lines_dropped + in.c.lines_queued);

    /* now read everything: whole lines, increasing, the last ones all there */
    static char buf[1 << 20];
    static unsigned nums[8192];
    size_t total = 0;
    for (int round = 0; round < 1000; round++) {
        size_t n = read_master(m, buf + total, sizeof buf - total, 30);
        total += n;
        s.poll(s.state, 0.01 * round);
        if (n == 0 && info_of(&s).c.lines_queued == 0)
            break;
    }
    total += read_master(m, buf + total, sizeof buf - total, 30);
    size_t k = split_lines(buf, total, nums, 8192);
    in = info_of(&s);
    TEST_ASSERT_EQUAL_UINT64(0, in.c.lines_queued);
    TEST_ASSERT_EQUAL_UINT64(k, in.c.lines_sent);
    TEST_ASSERT_EQUAL_UINT64(N, k + in.c.lines_dropped);
    for (size_t j = 1; j < k; j++)
        TEST_ASSERT_TRUE(nums[j] > nums[j - 1]);
    TEST_ASSERT_EQUAL_UINT(N - 1, nums[k - 1]);
    /* the oldest go: the 8 newest lines were in the queue at the end, all arrived
     * (how many gaps there are depends on when the pty drained) */
    TEST_ASSERT_TRUE(k >= 8);
    for (unsigned j = 0; j < 8; j++)
        TEST_ASSERT_EQUAL_UINT(N - 8 + j, nums[k - 8 + j]);
    TEST_ASSERT_EQUAL_UINT(0, nums[0]);
    s.close(s.state);
    close(m);
}

void test_line_cut_by_unplug_goes_out_whole_on_the_next_device(void)
{
    char dir[] = "/tmp/gs_serial_XXXXXX";
    TEST_ASSERT_NOT_NULL(mkdtemp(dir));
    char link[64];
    snprintf(link, sizeof link, "%s/ttyGS", dir);
    char dev[128], err[256] = "";
    int m = open_pty(dev, sizeof dev);
    TEST_ASSERT_EQUAL_INT(0, symlink(dev, link));
    gs_sink s;
    gs_sink_serial_cfg c = cfg_for(link, 115200, 4);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_serial_open(&s, &c, 0.0, err, sizeof err), err);
    /* fill the tty so that the line in hand is (most likely) written in part */
    unsigned n = 0;
    while (info_of(&s).c.lines_queued < 3 && n < 100000) {
        write_lines(&s, n, n + 1);
        n++;
    }
    close(m);
    unlink(link);
    s.poll(s.state, 0.1);
    TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, info_of(&s).state);
    m = open_pty(dev, sizeof dev);
    TEST_ASSERT_EQUAL_INT(0, symlink(dev, link));
    s.poll(s.state, 1.2);
    TEST_ASSERT_EQUAL_INT(GS_SINK_UP, info_of(&s).state);
    /* the new device starts at a line boundary: split_lines checks every byte */
    static char buf[1 << 16];
    static unsigned nums[64];
    size_t k = split_lines(buf, read_master(m, buf, sizeof buf, 100), nums, 64);
    gs_sink_info in = info_of(&s);
    TEST_ASSERT_TRUE(k >= 1);
    TEST_ASSERT_EQUAL_UINT(n - 1, nums[k - 1]);
    TEST_ASSERT_EQUAL_UINT64(0, in.c.lines_queued);
    TEST_ASSERT_EQUAL_UINT64(n, in.c.lines_sent + in.c.lines_dropped);
    s.close(s.state);
    close(m);
    unlink(link);
    rmdir(dir);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_sigpipe_is_default_here);
    RUN_TEST(test_bytes_and_framing_at_the_other_end);
    RUN_TEST(test_every_baud_and_bad_ones);
    RUN_TEST(test_missing_device_and_not_a_tty);
    RUN_TEST(test_unplug_queue_and_reopen_through_symlink);
    RUN_TEST(test_queue_overflow_drops_whole_oldest_lines);
    RUN_TEST(test_line_cut_by_unplug_goes_out_whole_on_the_next_device);
    return UNITY_END();
}
