/* gs_sink_net.c - socket sinks: a TCP server (several clients, each with its
 * own position in one shared bounded queue), a TCP client that reconnects with
 * capped exponential backoff, and UDP (one datagram per line). Everything is
 * non-blocking and written with MSG_NOSIGNAL. */
#include "gs_sink.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

/* a connect that has not finished after this long is abandoned and retried */
#define CONNECT_TIMEOUT_S 5.0

static int set_nonblock_cloexec(int fd)
{
    int fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0)
        return -1;
    int fd_fl = fcntl(fd, F_GETFD);
    if (fd_fl < 0 || fcntl(fd, F_SETFD, fd_fl | FD_CLOEXEC) != 0)
        return -1;
    return 0;
}

static void no_sigpipe(int fd)
{
#ifdef SO_NOSIGPIPE
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_NOSIGPIPE, &one, sizeof one);
#else
    (void)fd; /* Linux: MSG_NOSIGNAL on every send */
#endif
}

static int new_socket(int family, int type)
{
    int fd = socket(family, type, 0);
    if (fd < 0)
        return -1;
    if (set_nonblock_cloexec(fd) != 0) {
        int e = errno;
        close(fd);
        errno = e;
        return -1;
    }
    no_sigpipe(fd);
    return fd;
}

/* "host:port" text for status and errors ([v6]:port) */
static void addr_text(char *dst, size_t cap, const char *host, unsigned port)
{
    snprintf(dst, cap, strchr(host, ':') ? "[%s]:%u" : "%s:%u", host, port);
}

static bool is_loopback(const struct sockaddr *sa)
{
    if (sa->sa_family == AF_INET) {
        const struct sockaddr_in *a = (const struct sockaddr_in *)(const void *)sa;
        return (ntohl(a->sin_addr.s_addr) >> 24) == 127u;
    }
    if (sa->sa_family == AF_INET6) {
        const struct sockaddr_in6 *a = (const struct sockaddr_in6 *)(const void *)sa;
        static const unsigned char lo[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
        static const unsigned char v4map[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
        const unsigned char *b = a->sin6_addr.s6_addr;
        return memcmp(b, lo, 16) == 0 || (memcmp(b, v4map, 12) == 0 && b[12] == 127u);
    }
    return false;
}

/* resolve host:port (numeric_only: no name lookup) into *ss; 0 or an EAI_ code */
static int resolve(const char *host, uint16_t port, int socktype, bool numeric_only, bool passive,
                   struct sockaddr_storage *ss, socklen_t *sslen)
{
    char serv[8];
    snprintf(serv, sizeof serv, "%u", (unsigned)port);
    struct addrinfo hints, *res = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = socktype;
    hints.ai_flags = AI_NUMERICSERV | (numeric_only ? AI_NUMERICHOST : 0) | (passive ? AI_PASSIVE : 0);
    int rc = getaddrinfo(host, serv, &hints, &res);
    if (rc != 0)
        return rc;
    memcpy(ss, res->ai_addr, res->ai_addrlen);
    *sslen = res->ai_addrlen;
    freeaddrinfo(res);
    return 0;
}

/* ================================================================ TCP server */

typedef struct {
    int fd;
    gs_lineq_reader r;
} tcp_client;

typedef struct {
    gs_sink_tcp_cfg cfg;
    char target[160];
    int lfd;
    uint16_t port;
    gs_lineq q;
    tcp_client *cl;       /* cfg.max_clients slots, fd -1 when free */
    uint64_t gone_sent, gone_dropped, gone_bytes; /* totals of clients that left */
    uint64_t accepted, refused;
    int last_errno;
} tcp_server;

static void client_drop(tcp_server *s, tcp_client *c, int err)
{
    gs_lineq_reader_catch_up(&c->r, &s->q);
    if (c->r.cur_len > 0 && c->r.cur_off > 0)
        c->r.dropped++; /* the peer got part of a line: count it lost */
    s->gone_sent += c->r.sent;
    s->gone_dropped += c->r.dropped;
    s->gone_bytes += c->r.bytes;
    close(c->fd);
    c->fd = -1;
    if (err)
        s->last_errno = err;
}

static void client_pump(tcp_server *s, tcp_client *c)
{
    int e = gs_lineq_pump(&c->r, &s->q, c->fd, gs_lineq_write_sock);
    if (e)
        client_drop(s, c, e);
}

static int tcp_write_line(void *state, const char *line, size_t len)
{
    tcp_server *s = state;
    if (gs_lineq_take(&s->q, line, len) != 0)
        return -1;
    for (uint32_t i = 0; i < s->cfg.max_clients; i++)
        if (s->cl[i].fd >= 0)
            client_pump(s, &s->cl[i]);
    return 0;
}

static void tcp_accept(tcp_server *s)
{
    for (;;) {
        int fd = accept(s->lfd, NULL, NULL);
        if (fd < 0) {
            if (errno == EINTR || errno == ECONNABORTED)
                continue;
            if (errno != EAGAIN && errno != EWOULDBLOCK)
                s->last_errno = errno; /* e.g. EMFILE: try again next poll */
            return;
        }
        tcp_client *slot = NULL;
        for (uint32_t i = 0; i < s->cfg.max_clients && !slot; i++)
            if (s->cl[i].fd < 0)
                slot = &s->cl[i];
        if (!slot || set_nonblock_cloexec(fd) != 0) {
            close(fd); /* full: closed at once rather than left waiting in the backlog */
            s->refused++;
            continue;
        }
        no_sigpipe(fd);
        int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one); /* a line is a message */
        if (s->cfg.sndbuf_bytes) {
            int b = (int)s->cfg.sndbuf_bytes;
            setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &b, sizeof b);
        }
        slot->fd = fd;
        gs_lineq_reader_init(&slot->r, &s->q); /* from the next whole line on */
        s->accepted++;
    }
}

static void tcp_poll(void *state, double now_s)
{
    (void)now_s;
    tcp_server *s = state;
    tcp_accept(s);
    for (uint32_t i = 0; i < s->cfg.max_clients; i++) {
        tcp_client *c = &s->cl[i];
        if (c->fd < 0)
            continue;
        struct pollfd p = {c->fd, POLLIN, 0};
        if (poll(&p, 1, 0) == 1) {
            if (p.revents & (POLLERR | POLLNVAL)) {
                client_drop(s, c, ECONNRESET);
                continue;
            }
            if (p.revents & (POLLIN | POLLHUP)) {
                char junk[256]; /* clients have nothing to say: read and discard */
                ssize_t n = recv(c->fd, junk, sizeof junk, MSG_DONTWAIT);
                if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
                    client_drop(s, c, n == 0 ? 0 : errno);
                    continue;
                }
            }
        }
        client_pump(s, c);
    }
}

static void tcp_info(const void *state, gs_sink_info *o)
{
    const tcp_server *s = state;
    memset(o, 0, sizeof *o);
    o->kind = "tcp";
    snprintf(o->target, sizeof o->target, "%s", s->target);
    o->state = GS_SINK_UP;
    o->last_errno = s->last_errno;
    o->c.lines_in = s->q.taken;
    o->c.lines_sent = s->gone_sent;
    o->c.lines_dropped = s->gone_dropped + s->q.refused;
    o->c.bytes_sent = s->gone_bytes;
    o->c.reopens = s->accepted;
    o->c.refused = s->refused;
    for (uint32_t i = 0; i < s->cfg.max_clients; i++) {
        const tcp_client *c = &s->cl[i];
        if (c->fd < 0)
            continue;
        o->c.clients++;
        o->c.lines_sent += c->r.sent;
        o->c.bytes_sent += c->r.bytes;
        o->c.lines_dropped += c->r.dropped + gs_lineq_reader_lost(&c->r, &s->q);
        uint64_t pend = gs_lineq_reader_pending(&c->r, &s->q);
        if (pend > o->c.lines_queued)
            o->c.lines_queued = pend;
    }
}

static void tcp_close(void *state)
{
    tcp_server *s = state;
    for (uint32_t i = 0; s->cl && i < s->cfg.max_clients; i++)
        if (s->cl[i].fd >= 0)
            close(s->cl[i].fd);
    if (s->lfd >= 0)
        close(s->lfd);
    free(s->cl);
    gs_lineq_free(&s->q);
    free(s);
}

uint16_t gs_sink_tcp_port(const gs_sink *sink)
{
    if (!sink || sink->write_line != tcp_write_line)
        return 0;
    return ((const tcp_server *)sink->state)->port;
}

int gs_sink_tcp_open(gs_sink *out, const gs_sink_tcp_cfg *cfg, char *err, size_t cap)
{
    memset(out, 0, sizeof *out);
    char where[96];
    addr_text(where, sizeof where, cfg->bind, cfg->port);
    struct sockaddr_storage ss;
    socklen_t sslen = 0;
    int rc = resolve(cfg->bind, cfg->port, SOCK_STREAM, true, true, &ss, &sslen);
    if (rc != 0) {
        snprintf(err, cap, "tcp %s: bind needs a numeric address (%s)", where, gai_strerror(rc));
        return -1;
    }
    if (!is_loopback((const struct sockaddr *)&ss) && !cfg->allow_remote) {
        snprintf(err, cap, "tcp %s: refusing a non-loopback address unless `bind` is written out", where);
        return -1;
    }
    if (cfg->max_clients < 1) {
        snprintf(err, cap, "tcp %s: max_clients must be at least 1", where);
        return -1;
    }
    tcp_server *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, cap, "tcp %s: out of memory", where);
        return -1;
    }
    s->cfg = *cfg;
    s->lfd = -1;
    s->cl = calloc(cfg->max_clients, sizeof *s->cl);
    if (!s->cl || gs_lineq_init(&s->q, cfg->queue_lines, (size_t)cfg->queue_lines * GS_EMIT_MAX) != 0) {
        snprintf(err, cap, "tcp %s: out of memory", where);
        tcp_close(s);
        return -1;
    }
    for (uint32_t i = 0; i < cfg->max_clients; i++)
        s->cl[i].fd = -1;
    s->lfd = new_socket(ss.ss_family, SOCK_STREAM);
    int one = 1;
    if (s->lfd < 0 || setsockopt(s->lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0) {
        snprintf(err, cap, "tcp %s: socket: %s", where, strerror(errno));
        tcp_close(s);
        return -1;
    }
    if (bind(s->lfd, (const struct sockaddr *)&ss, sslen) != 0) {
        snprintf(err, cap, "tcp %s: %s%s", where, errno == EADDRINUSE ? "port in use: " : "cannot bind: ",
                 strerror(errno));
        tcp_close(s);
        return -1;
    }
    if (listen(s->lfd, 8) != 0) {
        snprintf(err, cap, "tcp %s: listen: %s", where, strerror(errno));
        tcp_close(s);
        return -1;
    }
    struct sockaddr_storage got;
    socklen_t gl = sizeof got;
    if (getsockname(s->lfd, (struct sockaddr *)&got, &gl) != 0) {
        snprintf(err, cap, "tcp %s: getsockname: %s", where, strerror(errno));
        tcp_close(s);
        return -1;
    }
    s->port = ntohs(got.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)(void *)&got)->sin6_port
                                              : ((struct sockaddr_in *)(void *)&got)->sin_port);
    addr_text(s->target, sizeof s->target, cfg->bind, s->port);
    out->state = s;
    out->write_line = tcp_write_line;
    out->poll = tcp_poll;
    out->info = tcp_info;
    out->close = tcp_close;
    return 0;
}

/* ================================================================ TCP client */

typedef struct {
    gs_sink_tcp_client_cfg cfg;
    char target[160];
    struct sockaddr_storage ss;
    socklen_t sslen;
    int fd;
    gs_sink_state st;
    double now_s, next_try_s, connect_start_s, backoff_s;
    gs_lineq q;
    gs_lineq_reader r;
    uint64_t connects;
    int last_errno;
} tcp_client_sink;

static void tc_schedule(tcp_client_sink *s, int err)
{
    if (s->fd >= 0)
        close(s->fd);
    s->fd = -1;
    if (err)
        s->last_errno = err;
    s->st = GS_SINK_RETRYING;
    s->next_try_s = s->now_s + s->backoff_s;
    s->backoff_s *= 2.0;
    if (s->backoff_s > s->cfg.backoff_max_s)
        s->backoff_s = s->cfg.backoff_max_s;
    gs_lineq_reader_rewind(&s->r); /* a new connection starts with a whole line */
}

/* A connect to a free loopback port in the ephemeral range can meet itself
 * (TCP simultaneous open) and would then swallow every line: treat as refused. */
static bool self_connected(int fd)
{
    struct sockaddr_storage a, b;
    socklen_t al = sizeof a, bl = sizeof b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    if (getsockname(fd, (struct sockaddr *)&a, &al) != 0 || getpeername(fd, (struct sockaddr *)&b, &bl) != 0)
        return false;
    return al == bl && memcmp(&a, &b, al) == 0;
}

static void tc_schedule(tcp_client_sink *s, int err);

static void tc_connected(tcp_client_sink *s)
{
    if (self_connected(s->fd)) {
        tc_schedule(s, ECONNREFUSED);
        return;
    }
    s->st = GS_SINK_UP;
    s->connects++;
    s->backoff_s = s->cfg.backoff_min_s;
    int one = 1;
    setsockopt(s->fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

static void tc_start(tcp_client_sink *s)
{
    s->fd = new_socket(s->ss.ss_family, SOCK_STREAM);
    if (s->fd < 0) {
        tc_schedule(s, errno);
        return;
    }
    s->connect_start_s = s->now_s;
    if (connect(s->fd, (const struct sockaddr *)&s->ss, s->sslen) == 0) {
        tc_connected(s);
        return;
    }
    if (errno == EINPROGRESS || errno == EINTR) {
        s->st = GS_SINK_CONNECTING;
        return;
    }
    tc_schedule(s, errno);
}

static void tc_pump(tcp_client_sink *s)
{
    if (s->st != GS_SINK_UP)
        return;
    int e = gs_lineq_pump(&s->r, &s->q, s->fd, gs_lineq_write_sock);
    if (e)
        tc_schedule(s, e);
}

static int tc_write_line(void *state, const char *line, size_t len)
{
    tcp_client_sink *s = state;
    if (gs_lineq_take(&s->q, line, len) != 0)
        return -1;
    tc_pump(s);
    return 0;
}

static void tc_poll(void *state, double now_s)
{
    tcp_client_sink *s = state;
    s->now_s = now_s;
    if (s->st == GS_SINK_RETRYING) {
        if (now_s < s->next_try_s)
            return;
        tc_start(s);
    }
    if (s->st == GS_SINK_CONNECTING) {
        struct pollfd p = {s->fd, POLLOUT, 0};
        if (poll(&p, 1, 0) == 1) {
            int e = 0;
            socklen_t el = sizeof e;
            if (getsockopt(s->fd, SOL_SOCKET, SO_ERROR, &e, &el) != 0)
                e = errno;
            if (e) {
                tc_schedule(s, e);
                return;
            }
            tc_connected(s);
        } else if (now_s - s->connect_start_s > CONNECT_TIMEOUT_S) {
            tc_schedule(s, ETIMEDOUT);
            return;
        } else {
            return;
        }
    }
    if (s->st == GS_SINK_UP) {
        struct pollfd p = {s->fd, POLLIN, 0};
        if (poll(&p, 1, 0) == 1) {
            if (p.revents & (POLLERR | POLLNVAL)) {
                tc_schedule(s, ECONNRESET);
                return;
            }
            if (p.revents & (POLLIN | POLLHUP)) {
                char junk[256]; /* the server has nothing to say: discard */
                ssize_t n = recv(s->fd, junk, sizeof junk, MSG_DONTWAIT);
                if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
                    tc_schedule(s, n == 0 ? ECONNRESET : errno);
                    return;
                }
            }
        }
        tc_pump(s);
    }
}

static void tc_info(const void *state, gs_sink_info *o)
{
    const tcp_client_sink *s = state;
    memset(o, 0, sizeof *o);
    o->kind = "tcp_client";
    snprintf(o->target, sizeof o->target, "%s", s->target);
    o->state = s->st;
    o->last_errno = s->last_errno;
    gs_sink_counters_fill(&o->c, &s->q, &s->r);
    o->c.reopens = s->connects;
}

static void tc_close(void *state)
{
    tcp_client_sink *s = state;
    if (s->fd >= 0)
        close(s->fd);
    gs_lineq_free(&s->q);
    free(s);
}

int gs_sink_tcp_client_open(gs_sink *out, const gs_sink_tcp_client_cfg *cfg, double now_s, char *err,
                            size_t cap)
{
    memset(out, 0, sizeof *out);
    tcp_client_sink *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, cap, "tcp_client %s: out of memory", cfg->host);
        return -1;
    }
    s->cfg = *cfg;
    s->fd = -1;
    addr_text(s->target, sizeof s->target, cfg->host, cfg->port);
    if (cfg->port == 0) {
        snprintf(err, cap, "tcp_client %s: port 0", s->target);
        free(s);
        return -1;
    }
    int rc = resolve(cfg->host, cfg->port, SOCK_STREAM, false, false, &s->ss, &s->sslen);
    if (rc != 0) {
        snprintf(err, cap, "tcp_client %s: %s", s->target, gai_strerror(rc));
        free(s);
        return -1;
    }
    if (gs_lineq_init(&s->q, cfg->queue_lines, (size_t)cfg->queue_lines * GS_EMIT_MAX) != 0) {
        snprintf(err, cap, "tcp_client %s: out of memory", s->target);
        free(s);
        return -1;
    }
    if (!(s->cfg.backoff_min_s > 0.0))
        s->cfg.backoff_min_s = 0.5;
    if (!(s->cfg.backoff_max_s >= s->cfg.backoff_min_s))
        s->cfg.backoff_max_s = s->cfg.backoff_min_s;
    s->backoff_s = s->cfg.backoff_min_s;
    gs_lineq_reader_init(&s->r, &s->q);
    s->now_s = now_s;
    s->st = GS_SINK_RETRYING;
    s->next_try_s = now_s;
    tc_start(s); /* first attempt now; failures only schedule retries */
    out->state = s;
    out->write_line = tc_write_line;
    out->poll = tc_poll;
    out->info = tc_info;
    out->close = tc_close;
    return 0;
}

/* ======================================================================= UDP */

typedef struct {
    char target[160];
    int fd;
    uint64_t in, sent, dropped, bytes;
    int last_errno;
} udp_sink;

static int udp_write_line(void *state, const char *line, size_t len)
{
    udp_sink *s = state;
    s->in++;
    if (len == 0 || line[len - 1] != '\n' || len > GS_SINK_LINE_MAX) {
        s->dropped++;
        return -1;
    }
    for (int attempt = 0; attempt < 2; attempt++) {
        ssize_t n = send(s->fd, line, len, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n == (ssize_t)len) {
            s->sent++;
            s->bytes += (uint64_t)n;
            return 0;
        }
        if (n >= 0) {
            s->last_errno = EMSGSIZE;
            break;
        }
        s->last_errno = errno;
        /* ECONNREFUSED reports an earlier datagram nobody took; this one was not sent: once more */
        if (errno != ECONNREFUSED && errno != EINTR)
            break;
    }
    s->dropped++;
    return -1;
}

static void udp_poll(void *state, double now_s)
{
    (void)state;
    (void)now_s;
}

static void udp_info(const void *state, gs_sink_info *o)
{
    const udp_sink *s = state;
    memset(o, 0, sizeof *o);
    o->kind = "udp";
    snprintf(o->target, sizeof o->target, "%s", s->target);
    o->state = GS_SINK_UP;
    o->last_errno = s->last_errno;
    o->c.lines_in = s->in;
    o->c.lines_sent = s->sent;
    o->c.lines_dropped = s->dropped;
    o->c.bytes_sent = s->bytes;
}

static void udp_close(void *state)
{
    udp_sink *s = state;
    if (s->fd >= 0)
        close(s->fd);
    free(s);
}

int gs_sink_udp_open(gs_sink *out, const gs_sink_udp_cfg *cfg, char *err, size_t cap)
{
    memset(out, 0, sizeof *out);
    udp_sink *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, cap, "udp %s: out of memory", cfg->host);
        return -1;
    }
    addr_text(s->target, sizeof s->target, cfg->host, cfg->port);
    struct sockaddr_storage ss;
    socklen_t sslen = 0;
    int rc = cfg->port == 0 ? EAI_SERVICE : resolve(cfg->host, cfg->port, SOCK_DGRAM, false, false, &ss, &sslen);
    if (rc != 0) {
        snprintf(err, cap, "udp %s: %s", s->target, cfg->port == 0 ? "port 0" : gai_strerror(rc));
        free(s);
        return -1;
    }
    s->fd = new_socket(ss.ss_family, SOCK_DGRAM);
    if (s->fd < 0 || connect(s->fd, (const struct sockaddr *)&ss, sslen) != 0) {
        snprintf(err, cap, "udp %s: %s", s->target, strerror(errno));
        udp_close(s);
        return -1;
    }
    out->state = s;
    out->write_line = udp_write_line;
    out->poll = udp_poll;
    out->info = udp_info;
    out->close = udp_close;
    return 0;
}
