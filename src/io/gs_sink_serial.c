/* gs_sink_serial.c - lines to a tty: raw 8N1 at the configured baud, non-blocking,
 * a bounded queue of whole lines; when the device goes away (EIO, ENXIO, a
 * hang-up) it is closed and reopened every reopen_s seconds, lines queue meanwhile. */
#include "gs_sink.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

typedef struct {
    gs_sink_serial_cfg cfg;
    int fd;
    gs_lineq q;
    gs_lineq_reader r;
    uint64_t reopens;
    int last_errno;
    double now_s, next_open_s;
} serial_sink;

typedef struct {
    uint32_t baud;
    speed_t code;
} baud_code;

static const baud_code k_bauds[] = {
    {9600, B9600},     {19200, B19200},   {38400, B38400},   {57600, B57600},
    {115200, B115200}, {230400, B230400}, {460800, B460800}, {921600, B921600},
};

static bool baud_lookup(uint32_t baud, speed_t *code)
{
    for (size_t i = 0; i < sizeof k_bauds / sizeof k_bauds[0]; i++)
        if (k_bauds[i].baud == baud) {
            *code = k_bauds[i].code;
            return true;
        }
    return false;
}

bool gs_sink_serial_baud_ok(uint32_t baud)
{
    speed_t c;
    return baud_lookup(baud, &c);
}

/* Raw mode by hand (cfmakeraw is not POSIX): no input or output processing, no
 * echo, no signals, 8 data bits, no parity, one stop bit, receiver on, modem
 * lines ignored, no flow control. */
static int set_raw(int fd, speed_t code)
{
    struct termios t;
    if (tcgetattr(fd, &t) != 0)
        return -1;
    t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON | IXOFF | IXANY);
    t.c_oflag &= ~(tcflag_t)OPOST;
    t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
    t.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB);
#ifdef CRTSCTS
    t.c_cflag &= ~(tcflag_t)CRTSCTS;
#endif
    t.c_cflag |= CS8 | CREAD | CLOCAL;
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    if (cfsetispeed(&t, code) != 0 || cfsetospeed(&t, code) != 0)
        return -1;
    return tcsetattr(fd, TCSANOW, &t);
}

/* open and configure the device; fd or -1 with errno */
static int open_tty(const gs_sink_serial_cfg *cfg)
{
    speed_t code;
    if (!baud_lookup(cfg->baud, &code)) {
        errno = EINVAL;
        return -1;
    }
    int fd = open(cfg->device, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return -1;
    if (!isatty(fd) || set_raw(fd, code) != 0) {
        int e = errno ? errno : ENOTTY;
        close(fd);
        errno = e;
        return -1;
    }
    return fd;
}

static void lose_device(serial_sink *s, int err)
{
    if (s->fd >= 0)
        close(s->fd);
    s->fd = -1;
    s->last_errno = err;
    s->next_open_s = s->now_s + s->cfg.reopen_s;
    gs_lineq_reader_rewind(&s->r); /* the line in hand goes out whole on the next device */
}

static void pump(serial_sink *s)
{
    if (s->fd < 0)
        return;
    int e = gs_lineq_pump(&s->r, &s->q, s->fd, gs_lineq_write_fd);
    if (e)
        lose_device(s, e);
}

static int serial_write_line(void *state, const char *line, size_t len)
{
    serial_sink *s = state;
    if (gs_lineq_take(&s->q, line, len) != 0)
        return -1;
    pump(s);
    return 0;
}

static void serial_poll(void *state, double now_s)
{
    serial_sink *s = state;
    s->now_s = now_s;
    if (s->fd < 0) {
        if (now_s < s->next_open_s)
            return;
        int fd = open_tty(&s->cfg);
        if (fd < 0) {
            s->last_errno = errno;
            s->next_open_s = now_s + s->cfg.reopen_s;
            return;
        }
        s->fd = fd;
        s->reopens++;
    }
    struct pollfd p = {s->fd, POLLOUT, 0};
    int r = poll(&p, 1, 0);
    if (r == 1 && (p.revents & (POLLHUP | POLLERR | POLLNVAL))) {
        lose_device(s, (p.revents & POLLNVAL) ? EBADF : EIO);
        return;
    }
    pump(s);
}

static void serial_info(const void *state, gs_sink_info *o)
{
    const serial_sink *s = state;
    memset(o, 0, sizeof *o);
    o->kind = "serial";
    snprintf(o->target, sizeof o->target, "%s@%u", s->cfg.device, (unsigned)s->cfg.baud);
    o->state = s->fd >= 0 ? GS_SINK_UP : GS_SINK_RETRYING;
    o->last_errno = s->last_errno;
    gs_sink_counters_fill(&o->c, &s->q, &s->r);
    o->c.reopens = s->reopens;
}

static void serial_close(void *state)
{
    serial_sink *s = state;
    if (s->fd >= 0)
        close(s->fd);
    gs_lineq_free(&s->q);
    free(s);
}

int gs_sink_serial_open(gs_sink *out, const gs_sink_serial_cfg *cfg, double now_s, char *err, size_t cap)
{
    memset(out, 0, sizeof *out);
    if (!gs_sink_serial_baud_ok(cfg->baud)) {
        snprintf(err, cap, "serial %s: unsupported baud %u", cfg->device, (unsigned)cfg->baud);
        return -1;
    }
    serial_sink *s = calloc(1, sizeof *s);
    if (!s || gs_lineq_init(&s->q, cfg->queue_lines, (size_t)cfg->queue_lines * GS_EMIT_MAX) != 0) {
        free(s);
        snprintf(err, cap, "serial %s: out of memory", cfg->device);
        return -1;
    }
    s->cfg = *cfg;
    if (!(s->cfg.reopen_s > 0.0))
        s->cfg.reopen_s = 1.0;
    s->now_s = now_s;
    s->fd = open_tty(&s->cfg);
    if (s->fd < 0) {
        snprintf(err, cap, "serial %s: %s", cfg->device,
                 errno == ENOTTY ? "not a terminal device" : strerror(errno));
        gs_lineq_free(&s->q);
        free(s);
        return -1;
    }
    gs_lineq_reader_init(&s->r, &s->q);
    out->state = s;
    out->write_line = serial_write_line;
    out->poll = serial_poll;
    out->info = serial_info;
    out->close = serial_close;
    return 0;
}
