/* gs_lineq.c - bounded ring of whole lines with independent readers. */
#include "gs_lineq.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

int gs_lineq_init(gs_lineq *q, uint32_t max_lines, size_t cap_bytes)
{
    memset(q, 0, sizeof *q);
    if (max_lines < 1)
        max_lines = 1;
    if (cap_bytes < GS_SINK_LINE_MAX)
        cap_bytes = GS_SINK_LINE_MAX;
    q->buf = malloc(cap_bytes);
    q->start = calloc(max_lines, sizeof *q->start);
    q->len = calloc(max_lines, sizeof *q->len);
    if (!q->buf || !q->start || !q->len) {
        gs_lineq_free(q);
        errno = ENOMEM;
        return -1;
    }
    q->cap_bytes = cap_bytes;
    q->max_lines = max_lines;
    return 0;
}

void gs_lineq_free(gs_lineq *q)
{
    free(q->buf);
    free(q->start);
    free(q->len);
    memset(q, 0, sizeof *q);
}

int gs_lineq_take(gs_lineq *q, const char *line, size_t len)
{
    q->taken++;
    if (len == 0 || line[len - 1] != '\n' || gs_lineq_push(q, line, len) != 0) {
        q->refused++;
        return -1;
    }
    return 0;
}

static void evict_oldest(gs_lineq *q)
{
    q->head_seq++;
    q->evicted++;
}

int gs_lineq_push(gs_lineq *q, const char *line, size_t len)
{
    if (len == 0 || len > GS_SINK_LINE_MAX || len > q->cap_bytes)
        return -1;
    /* room for one more slot and len more bytes */
    while (q->next_seq - q->head_seq >= q->max_lines)
        evict_oldest(q);
    while (q->head_seq < q->next_seq &&
           q->wpos + len - q->start[q->head_seq % q->max_lines] > q->cap_bytes)
        evict_oldest(q);
    size_t at = (size_t)(q->wpos % q->cap_bytes);
    size_t first = q->cap_bytes - at;
    if (first > len)
        first = len;
    memcpy(q->buf + at, line, first);
    if (first < len)
        memcpy(q->buf, line + first, len - first); /* wraps */
    uint32_t slot = (uint32_t)(q->next_seq % q->max_lines);
    q->start[slot] = q->wpos;
    q->len[slot] = (uint32_t)len;
    q->wpos += len;
    q->next_seq++;
    return 0;
}

/* copy line seq (stored) into dst; returns its length */
static size_t copy_line(const gs_lineq *q, uint64_t seq, char *dst)
{
    uint32_t slot = (uint32_t)(seq % q->max_lines);
    size_t len = q->len[slot];
    size_t at = (size_t)(q->start[slot] % q->cap_bytes);
    size_t first = q->cap_bytes - at;
    if (first > len)
        first = len;
    memcpy(dst, q->buf + at, first);
    if (first < len)
        memcpy(dst + first, q->buf, len - first);
    return len;
}

void gs_lineq_reader_init(gs_lineq_reader *r, const gs_lineq *q)
{
    memset(r, 0, sizeof *r);
    r->next_seq = q->next_seq;
}

uint64_t gs_lineq_reader_lost(const gs_lineq_reader *r, const gs_lineq *q)
{
    return q->head_seq > r->next_seq ? q->head_seq - r->next_seq : 0;
}

void gs_lineq_reader_catch_up(gs_lineq_reader *r, const gs_lineq *q)
{
    uint64_t lost = gs_lineq_reader_lost(r, q);
    r->dropped += lost;
    r->next_seq += lost;
}

uint64_t gs_lineq_reader_pending(const gs_lineq_reader *r, const gs_lineq *q)
{
    uint64_t from = r->next_seq > q->head_seq ? r->next_seq : q->head_seq;
    return (q->next_seq - from) + (r->cur_len > 0 ? 1u : 0u);
}

void gs_lineq_reader_rewind(gs_lineq_reader *r) { r->cur_off = 0; }

/* the reader's next line in hand (copied out of the ring); false when none waits */
static bool take_next(gs_lineq_reader *r, const gs_lineq *q)
{
    if (r->cur_len > 0)
        return true;
    gs_lineq_reader_catch_up(r, q);
    if (r->next_seq >= q->next_seq)
        return false;
    r->cur_len = copy_line(q, r->next_seq, r->cur);
    r->cur_off = 0;
    r->next_seq++;
    return true;
}

int gs_lineq_pump(gs_lineq_reader *r, const gs_lineq *q, int fd, gs_lineq_write_fn wr)
{
    for (;;) {
        if (!take_next(r, q))
            return 0; /* nothing waiting */
        while (r->cur_off < r->cur_len) {
            ssize_t w = wr(fd, r->cur + r->cur_off, r->cur_len - r->cur_off);
            if (w < 0) {
                if (errno == EINTR)
                    continue;
                if (errno == EAGAIN || errno == EWOULDBLOCK)
                    return 0;
                return errno ? errno : EIO;
            }
            if (w == 0)
                return 0; /* nothing taken: try again later */
            r->cur_off += (size_t)w;
            r->bytes += (uint64_t)w;
        }
        r->sent++;
        r->cur_len = 0;
        r->cur_off = 0;
    }
}

ssize_t gs_lineq_write_fd(int fd, const void *p, size_t n) { return write(fd, p, n); }

ssize_t gs_lineq_write_sock(int fd, const void *p, size_t n)
{
    return send(fd, p, n, MSG_NOSIGNAL | MSG_DONTWAIT);
}

int gs_lineq_pump_msg(gs_lineq_reader *r, const gs_lineq *q, gs_lineq_send_fn send, void *ctx)
{
    while (take_next(r, q)) {
        int e = send(ctx, r->cur, r->cur_len);
        if (e == EAGAIN)
            return 0;
        if (e)
            return e;
        r->sent++;
        r->bytes += r->cur_len;
        r->cur_len = 0;
        r->cur_off = 0;
    }
    return 0;
}
