/* test_sink_tcp.c - the socket sinks on loopback with real sockets: a TCP
 * server with a client that connects late, one that never reads (its backlog
 * overflows: the pipeline and the other clients go on, drops counted, whole
 * lines only), one that disconnects mid-line, a full house, a port in use, a
 * refused non-loopback bind; the TCP client sink reconnecting with backoff to
 * a server that starts late and again after the server drops it; UDP datagrams.
 * SIGPIPE keeps its default action here: a send without MSG_NOSIGNAL would kill
 * the test. */
#include "gs_sink.h"
#include "unity.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
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

/* ------------------------------------------------------------------ helpers */

/* line i: "{"i":000042,"p":"abc..."}\n", lengths vary with i */
static size_t make_line(char *buf, size_t cap, unsigned i)
{
    char pad[256];
    unsigned n = (i * 53u) % 180u;
    for (unsigned k = 0; k < n; k++)
        pad[k] = (char)('a' + (i + k) % 26u);
    pad[n] = '\0';
    int w = snprintf(buf, cap, "{\"i\":%06u,\"p\":\"%s\"}\n", i, pad);
    TEST_ASSERT_TRUE(w > 0 && (size_t)w < cap);
    return (size_t)w;
}

static unsigned check_line(const char *s, size_t n)
{
    unsigned i;
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, sscanf(s, "{\"i\":%u,", &i), "line does not start whole");
    char want[512];
    size_t wn = make_line(want, sizeof want, i);
    EQ_SZ(wn, n);
    TEST_ASSERT_EQUAL_MEMORY(want, s, n);
    return i;
}

/* A reading peer: bytes so far, split into checked lines as they complete. */
typedef struct {
    int fd;
    char buf[8192];
    size_t len;
    unsigned nums[65536];
    size_t n;
    bool eof;
} peer;

static void peer_take(peer *p)
{
    size_t at = 0;
    for (;;) {
        const char *nl = memchr(p->buf + at, '\n', p->len - at);
        if (!nl)
            break;
        size_t len = (size_t)(nl - (p->buf + at)) + 1u;
        TEST_ASSERT_TRUE(p->n < 65536);
        p->nums[p->n++] = check_line(p->buf + at, len);
        at += len;
    }
    memmove(p->buf, p->buf + at, p->len - at);
    p->len -= at;
}

/* read what is there, waiting up to wait_ms for the first bytes */
static size_t peer_read(peer *p, int wait_ms)
{
    size_t got = 0;
    for (;;) {
        struct pollfd q = {p->fd, POLLIN, 0};
        if (poll(&q, 1, got ? 0 : wait_ms) != 1)
            break;
        ssize_t r = recv(p->fd, p->buf + p->len, sizeof p->buf - p->len, MSG_DONTWAIT);
        if (r == 0) {
            p->eof = true;
            break;
        }
        if (r < 0)
            break;
        p->len += (size_t)r;
        got += (size_t)r;
        peer_take(p);
    }
    return got;
}

static void expect_run(const peer *p, unsigned from, unsigned to)
{
    EQ_SZ(to - from, p->n);
    for (size_t j = 0; j < p->n; j++)
        TEST_ASSERT_EQUAL_UINT(from + j, p->nums[j]);
    EQ_SZ(0, p->len); /* no partial line left over */
}

static int connect_to(uint16_t port, int rcvbuf)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    TEST_ASSERT_TRUE(fd >= 0);
    if (rcvbuf > 0)
        setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    TEST_ASSERT_EQUAL_INT(0, connect(fd, (struct sockaddr *)&a, sizeof a));
    return fd;
}

static peer *peer_new(uint16_t port, int rcvbuf)
{
    peer *p = calloc(1, sizeof *p);
    TEST_ASSERT_NOT_NULL(p);
    p->fd = connect_to(port, rcvbuf);
    return p;
}

static void peer_free(peer *p)
{
    if (p->fd >= 0)
        close(p->fd);
    free(p);
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

static gs_sink_tcp_cfg server_cfg(uint32_t max_clients, uint32_t queue_lines)
{
    gs_sink_tcp_cfg c;
    memset(&c, 0, sizeof c);
    snprintf(c.bind, sizeof c.bind, "127.0.0.1");
    c.port = 0;
    c.max_clients = max_clients;
    c.queue_lines = queue_lines;
    return c;
}

static gs_sink open_server(const gs_sink_tcp_cfg *c)
{
    gs_sink s;
    char err[256] = "";
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_tcp_open(&s, c, err, sizeof err), err);
    TEST_ASSERT_TRUE(gs_sink_tcp_port(&s) > 0);
    return s;
}

/* poll the sink until it reports n clients (accepts are in poll) */
static void wait_clients(gs_sink *s, uint32_t n)
{
    for (int k = 0; k < 200 && info_of(s).c.clients != n; k++) {
        s->poll(s->state, 0.0);
        if (info_of(s).c.clients != n)
            poll(NULL, 0, 2);
    }
    TEST_ASSERT_EQUAL_UINT32(n, info_of(s).c.clients);
}

/* a loopback port nobody listens on (bound, read, closed) */
static uint16_t free_port(void)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    TEST_ASSERT_EQUAL_INT(0, bind(fd, (struct sockaddr *)&a, sizeof a));
    socklen_t l = sizeof a;
    TEST_ASSERT_EQUAL_INT(0, getsockname(fd, (struct sockaddr *)&a, &l));
    close(fd);
    return ntohs(a.sin_port);
}

static int listen_on(uint16_t port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    TEST_ASSERT_EQUAL_INT(0, bind(fd, (struct sockaddr *)&a, sizeof a));
    TEST_ASSERT_EQUAL_INT(0, listen(fd, 4));
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    return fd;
}

/* ------------------------------------------------------------ TCP server */

void test_sigpipe_is_default_here(void)
{
    struct sigaction sa;
    TEST_ASSERT_EQUAL_INT(0, sigaction(SIGPIPE, NULL, &sa));
    TEST_ASSERT_TRUE(sa.sa_handler == SIG_DFL);
}

void test_late_client_starts_at_a_line_boundary(void)
{
    gs_sink_tcp_cfg c = server_cfg(4, 64);
    gs_sink s = open_server(&c);
    uint16_t port = gs_sink_tcp_port(&s);
    gs_sink_info in = info_of(&s);
    char want[32];
    snprintf(want, sizeof want, "127.0.0.1:%u", (unsigned)port);
    TEST_ASSERT_EQUAL_STRING(want, in.target);

    write_lines(&s, 0, 5); /* nobody listens yet: these go nowhere, and are not drops */
    peer *a = peer_new(port, 0);
    wait_clients(&s, 1);
    write_lines(&s, 5, 25);
    peer *b = peer_new(port, 0);
    wait_clients(&s, 2);
    write_lines(&s, 25, 40);
    s.poll(s.state, 0.0);
    while (peer_read(a, 50) > 0) {}
    while (peer_read(b, 50) > 0) {}
    expect_run(a, 5, 40);
    expect_run(b, 25, 40);
    in = info_of(&s);
    EQ_SZ(40, in.c.lines_in);
    EQ_SZ(35 + 15, in.c.lines_sent);
    EQ_SZ(0, in.c.lines_dropped);
    EQ_SZ(0, in.c.lines_queued);
    EQ_SZ(2, in.c.reopens); /* clients accepted */
    peer_free(a);
    peer_free(b);
    s.close(s.state);
}

void test_client_that_never_reads_stalls_nothing(void)
{
    gs_sink_tcp_cfg c = server_cfg(4, 64);
    /* loopback's large segments let the kernel buffer megabytes per client;
     * a small send buffer makes the slow client's backlog overflow soon */
    c.sndbuf_bytes = 4096;
    gs_sink s = open_server(&c);
    uint16_t port = gs_sink_tcp_port(&s);
    peer *slow = peer_new(port, 4096);
    peer *fast = peer_new(port, 0);
    wait_clients(&s, 2);
    const unsigned N = 20000;
    char line[512];
    for (unsigned i = 0; i < N; i++) {
        size_t n = make_line(line, sizeof line, i);
        TEST_ASSERT_EQUAL_INT(0, s.write_line(s.state, line, n));
        if (i % 2u == 1u) { /* the frame loop: poll, and the fast client reads */
            s.poll(s.state, 0.0);
            peer_read(fast, 0);
        }
    }
    gs_sink_info in = info_of(&s);
    TEST_ASSERT_TRUE_MESSAGE(in.c.lines_dropped > 0, "the slow client's backlog never overflowed");
    TEST_ASSERT_TRUE(in.c.lines_queued <= 64 + 1);
    /* the fast client got every line */
    for (int k = 0; k < 100 && fast->n < N; k++) {
        s.poll(s.state, 0.0);
        peer_read(fast, 10);
    }
    expect_run(fast, 0, N);
    /* the slow one reads at last: whole lines, increasing, received + dropped = N */
    for (int k = 0; k < 2000; k++) {
        s.poll(s.state, 0.0);
        size_t got = peer_read(slow, 10);
        if (got == 0 && info_of(&s).c.lines_queued == 0)
            break;
    }
    in = info_of(&s);
    EQ_SZ(0, in.c.lines_queued);
    EQ_SZ(0, slow->len);
    EQ_SZ(N, slow->n + in.c.lines_dropped);
    EQ_SZ(N + slow->n, in.c.lines_sent);
    printf("slow client: %u received, %u dropped of %u\n", (unsigned)slow->n, (unsigned)in.c.lines_dropped, N);
    for (size_t j = 1; j < slow->n; j++)
        TEST_ASSERT_TRUE(slow->nums[j] > slow->nums[j - 1]);
    TEST_ASSERT_EQUAL_UINT(N - 1, slow->nums[slow->n - 1]);
    TEST_ASSERT_EQUAL_UINT(0, slow->nums[0]);
    peer_free(slow);
    peer_free(fast);
    s.close(s.state);
}

void test_client_disconnecting_mid_line(void)
{
    gs_sink_tcp_cfg c = server_cfg(4, 64);
    gs_sink s = open_server(&c);
    uint16_t port = gs_sink_tcp_port(&s);
    peer *quitter = peer_new(port, 0);
    peer *stay = peer_new(port, 0);
    wait_clients(&s, 2);
    write_lines(&s, 0, 10);
    /* the quitter reads part of a line and hangs up with bytes unread (a reset) */
    char part[17];
    TEST_ASSERT_EQUAL_INT(17, recv(quitter->fd, part, sizeof part, MSG_WAITALL));
    close(quitter->fd);
    quitter->fd = -1;
    /* writes to it now fail with EPIPE/ECONNRESET: no signal, the client is dropped */
    for (unsigned i = 10; i < 200; i++) {
        write_lines(&s, i, i + 1);
        s.poll(s.state, 0.0);
    }
    wait_clients(&s, 1);
    while (peer_read(stay, 50) > 0) {}
    expect_run(stay, 0, 200);
    gs_sink_info in = info_of(&s);
    EQ_SZ(200, in.c.lines_in);
    EQ_SZ(0, in.c.lines_queued);

    /* one that leaves politely (FIN), and the sink writes before it polls: the
     * first send draws a reset, the second fails with EPIPE (SIGPIPE without
     * MSG_NOSIGNAL); the client who joined meanwhile gets every line */
    peer *next = peer_new(port, 0);
    wait_clients(&s, 2);
    shutdown(stay->fd, SHUT_RDWR);
    close(stay->fd);
    stay->fd = -1;
    write_lines(&s, 200, 210);
    wait_clients(&s, 1);
    while (peer_read(next, 50) > 0) {}
    expect_run(next, 200, 210);
    peer_free(quitter);
    peer_free(stay);
    peer_free(next);
    s.close(s.state);
}

void test_full_house_refuses_extra_clients(void)
{
    gs_sink_tcp_cfg c = server_cfg(2, 16);
    gs_sink s = open_server(&c);
    uint16_t port = gs_sink_tcp_port(&s);
    peer *a = peer_new(port, 0), *b = peer_new(port, 0);
    wait_clients(&s, 2);
    peer *extra = peer_new(port, 0);
    s.poll(s.state, 0.0);
    peer_read(extra, 200);
    TEST_ASSERT_TRUE_MESSAGE(extra->eof, "the extra client was not closed");
    EQ_SZ(2, info_of(&s).c.clients);
    EQ_SZ(1, info_of(&s).c.refused);
    write_lines(&s, 0, 3);
    while (peer_read(a, 30) > 0) {}
    while (peer_read(b, 30) > 0) {}
    expect_run(a, 0, 3);
    expect_run(b, 0, 3);
    EQ_SZ(0, extra->n);
    peer_free(a);
    peer_free(b);
    peer_free(extra);
    s.close(s.state);
}

void test_port_in_use_and_bad_binds(void)
{
    gs_sink_tcp_cfg c = server_cfg(1, 4);
    gs_sink s = open_server(&c);
    gs_sink other;
    char err[256] = "";
    c.port = gs_sink_tcp_port(&s);
    TEST_ASSERT_EQUAL_INT(-1, gs_sink_tcp_open(&other, &c, err, sizeof err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "port in use"), err);
    char where[32];
    snprintf(where, sizeof where, "127.0.0.1:%u", (unsigned)c.port);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, where), err);
    s.close(s.state);

    /* a non-loopback address needs allow_remote (the config sets it only when bind is written) */
    const char *remote[] = {"0.0.0.0", "::", "192.0.2.1"};
    for (size_t i = 0; i < 3; i++) {
        c = server_cfg(1, 4);
        snprintf(c.bind, sizeof c.bind, "%s", remote[i]);
        err[0] = '\0';
        TEST_ASSERT_EQUAL_INT(-1, gs_sink_tcp_open(&other, &c, err, sizeof err));
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "non-loopback"), err);
    }
    /* names are not resolved for a bind */
    c = server_cfg(1, 4);
    snprintf(c.bind, sizeof c.bind, "localhost");
    TEST_ASSERT_EQUAL_INT(-1, gs_sink_tcp_open(&other, &c, err, sizeof err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "numeric"), err);
    /* IPv6 loopback and the rest of 127/8 are loopback */
    const char *lo[] = {"::1", "127.0.0.2"};
    for (size_t i = 0; i < 2; i++) {
        c = server_cfg(1, 4);
        snprintf(c.bind, sizeof c.bind, "%s", lo[i]);
        if (gs_sink_tcp_open(&other, &c, err, sizeof err) == 0)
            other.close(other.state);
        else /* a machine without IPv6 may refuse ::1, but never as non-loopback */
            TEST_ASSERT_NULL_MESSAGE(strstr(err, "non-loopback"), err);
    }
}

/* ------------------------------------------------------------ TCP client */

static int accept_one(int lfd, int wait_ms)
{
    struct pollfd q = {lfd, POLLIN, 0};
    if (poll(&q, 1, wait_ms) != 1)
        return -1;
    return accept(lfd, NULL, NULL);
}

void test_tcp_client_reconnects_with_backoff(void)
{
    uint16_t port = free_port();
    gs_sink_tcp_client_cfg c;
    memset(&c, 0, sizeof c);
    snprintf(c.host, sizeof c.host, "127.0.0.1");
    c.port = port;
    c.backoff_min_s = 0.1;
    c.backoff_max_s = 0.4;
    c.queue_lines = 16;
    gs_sink s;
    char err[256] = "";
    /* now_s is the test's clock: attempts at 0 (open), 0.1, 0.3, 0.7, 1.1, 1.5 ... */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_tcp_client_open(&s, &c, 0.0, err, sizeof err), err);
    write_lines(&s, 0, 20); /* 16 fit: the 4 oldest are dropped */
    const double t[] = {0.0, 0.05, 0.1, 0.3, 0.7, 1.1};
    for (size_t k = 0; k < sizeof t / sizeof t[0]; k++) {
        s.poll(s.state, t[k]);
        s.poll(s.state, t[k]); /* a refused connect is noticed at once */
        TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, info_of(&s).state);
    }
    TEST_ASSERT_EQUAL_INT(ECONNREFUSED, info_of(&s).last_errno);
    /* the server starts; the next attempt is due at 1.5 (backoff capped at 0.4) */
    int lfd = listen_on(port);
    s.poll(s.state, 1.45);
    TEST_ASSERT_EQUAL_INT(-1, accept_one(lfd, 50));
    s.poll(s.state, 1.5);
    int fd = accept_one(lfd, 500);
    TEST_ASSERT_TRUE_MESSAGE(fd >= 0, "no connection at 1.5");
    for (int k = 0; k < 100 && info_of(&s).state != GS_SINK_UP; k++)
        s.poll(s.state, 1.5);
    TEST_ASSERT_EQUAL_INT(GS_SINK_UP, info_of(&s).state);
    peer *p = calloc(1, sizeof *p);
    p->fd = fd;
    s.poll(s.state, 1.5);
    while (peer_read(p, 50) > 0) {}
    expect_run(p, 4, 20);
    gs_sink_info in = info_of(&s);
    EQ_SZ(16, in.c.lines_sent);
    EQ_SZ(4, in.c.lines_dropped);
    EQ_SZ(1, in.c.reopens);

    /* the server drops us: the lines written meanwhile wait and go out on the
     * next connection, after the backoff (reset to its minimum by the success) */
    close(p->fd);
    p->fd = -1;
    for (int k = 0; k < 100 && info_of(&s).state == GS_SINK_UP; k++) {
        s.poll(s.state, 2.0);
        poll(NULL, 0, 1);
    }
    TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, info_of(&s).state);
    write_lines(&s, 20, 30);
    s.poll(s.state, 2.05);
    TEST_ASSERT_EQUAL_INT(-1, accept_one(lfd, 30));
    s.poll(s.state, 2.1);
    fd = accept_one(lfd, 500);
    TEST_ASSERT_TRUE(fd >= 0);
    peer *q = calloc(1, sizeof *q);
    q->fd = fd;
    for (int k = 0; k < 100 && q->n < 10; k++) {
        s.poll(s.state, 2.1);
        peer_read(q, 10);
    }
    expect_run(q, 20, 30);
    in = info_of(&s);
    EQ_SZ(26, in.c.lines_sent);
    EQ_SZ(2, in.c.reopens);
    peer_free(p);
    peer_free(q);
    close(lfd);
    s.close(s.state);
}

/* ------------------------------------------------------------------- UDP */

void test_udp_one_datagram_per_line(void)
{
    int r = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    TEST_ASSERT_EQUAL_INT(0, bind(r, (struct sockaddr *)&a, sizeof a));
    socklen_t l = sizeof a;
    getsockname(r, (struct sockaddr *)&a, &l);
    gs_sink_udp_cfg c;
    memset(&c, 0, sizeof c);
    snprintf(c.host, sizeof c.host, "127.0.0.1");
    c.port = ntohs(a.sin_port);
    gs_sink s;
    char err[256] = "";
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_udp_open(&s, &c, err, sizeof err), err);
    write_lines(&s, 0, 50);
    char dg[1024];
    for (unsigned i = 0; i < 50; i++) {
        struct pollfd q = {r, POLLIN, 0};
        TEST_ASSERT_EQUAL_INT(1, poll(&q, 1, 200));
        ssize_t n = recv(r, dg, sizeof dg, 0);
        TEST_ASSERT_TRUE(n > 0);
        TEST_ASSERT_EQUAL_UINT(i, check_line(dg, (size_t)n)); /* exactly one line, whole */
    }
    gs_sink_info in = info_of(&s);
    EQ_SZ(50, in.c.lines_sent);
    EQ_SZ(0, in.c.lines_dropped);
    s.close(s.state);

    /* nobody listening: ICMP errors come back; nothing breaks, every line is accounted for */
    close(r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_udp_open(&s, &c, err, sizeof err), err);
    write_lines(&s, 0, 20);
    in = info_of(&s);
    EQ_SZ(20, in.c.lines_in);
    EQ_SZ(20, in.c.lines_sent + in.c.lines_dropped);
    s.close(s.state);

    /* bad targets are one clear error */
    c.port = 0;
    TEST_ASSERT_EQUAL_INT(-1, gs_sink_udp_open(&s, &c, err, sizeof err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "port 0"), err);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_sigpipe_is_default_here);
    RUN_TEST(test_late_client_starts_at_a_line_boundary);
    RUN_TEST(test_client_that_never_reads_stalls_nothing);
    RUN_TEST(test_client_disconnecting_mid_line);
    RUN_TEST(test_full_house_refuses_extra_clients);
    RUN_TEST(test_port_in_use_and_bad_binds);
    RUN_TEST(test_tcp_client_reconnects_with_backoff);
    RUN_TEST(test_udp_one_datagram_per_line);
    return UNITY_END();
}
