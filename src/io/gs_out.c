/* gs_out.c - whole-line writer with a sticky first error. */
#include "gs_out.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int gs_out_open_fd(gs_out *o, int fd, size_t buf_bytes)
{
    memset(o, 0, sizeof *o);
    o->fd = fd;
    if (buf_bytes > 0) {
        o->buf = malloc(buf_bytes);
        if (!o->buf) {
            o->err = ENOMEM;
            errno = ENOMEM;
            return -1;
        }
        o->cap = buf_bytes;
    }
    return 0;
}

int gs_out_open_stream(gs_out *o, FILE *f, size_t buf_bytes)
{
    fflush(f); /* bytes the stream holds go first */
    return gs_out_open_fd(o, fileno(f), buf_bytes);
}

int gs_out_open_path(gs_out *o, const char *path, size_t buf_bytes)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) {
        memset(o, 0, sizeof *o);
        o->fd = -1;
        o->err = errno;
        return -1;
    }
    if (gs_out_open_fd(o, fd, buf_bytes) != 0) {
        int e = errno;
        close(fd);
        errno = e;
        return -1;
    }
    o->own_fd = true;
    return 0;
}

/* Write all of p[0..n) (a partial write continues; EINTR retries). */
static int write_all(gs_out *o, const char *p, size_t n)
{
    while (n > 0) {
        ssize_t w = write(o->fd, p, n);
        if (w < 0) {
            if (errno == EINTR)
                continue;
            o->err = errno;
            return -1;
        }
        if (w == 0) {
            o->err = EIO;
            return -1;
        }
        p += w;
        n -= (size_t)w;
        o->bytes += (uint64_t)w;
    }
    return 0;
}

int gs_out_flush(gs_out *o)
{
    if (o->err)
        return -1;
    if (o->len > 0) {
        size_t n = o->len;
        o->len = 0;
        return write_all(o, o->buf, n);
    }
    return 0;
}

int gs_out_line(gs_out *o, const char *line, size_t len)
{
    if (o->err)
        return -1;
    o->lines++;
    if (!o->buf)
        return write_all(o, line, len);
    if (o->len + len > o->cap && gs_out_flush(o) != 0)
        return -1;
    if (len > o->cap)
        return write_all(o, line, len); /* longer than the buffer: on its own */
    memcpy(o->buf + o->len, line, len);
    o->len += len;
    return 0;
}

int gs_out_close(gs_out *o)
{
    int rc = gs_out_flush(o);
    if (o->own_fd && o->fd >= 0) {
        if (close(o->fd) != 0 && !o->err) {
            o->err = errno;
            rc = -1;
        }
        o->fd = -1;
    }
    free(o->buf);
    o->buf = NULL;
    o->cap = 0;
    return o->err ? -1 : rc;
}
