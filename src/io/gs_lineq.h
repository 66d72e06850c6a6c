/* gs_lineq.h - a bounded ring of whole lines with numbered entries and readers
 * that each keep their own position. One ring serves one sink; the TCP server
 * shares it between its clients, so a line is stored once however many read it.
 * Full: the oldest line is evicted; a reader that had not taken it yet counts
 * it as dropped the next time it looks. A reader copies the line it is sending
 * into its own buffer first, so eviction never cuts a line in half. */
#ifndef GS_LINEQ_H
#define GS_LINEQ_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

/* Longest line a sink accepts (the emitter's lines are at most GS_EMIT_MAX). */
#define GS_SINK_LINE_MAX 2048u

typedef struct {
    char *buf;           /* byte ring, cap_bytes long */
    size_t cap_bytes;
    uint64_t *start;     /* per slot: the line's first byte as a position in the byte stream */
    uint32_t *len;
    uint32_t max_lines;  /* slots */
    uint64_t head_seq;   /* oldest line still stored */
    uint64_t next_seq;   /* number the next pushed line gets */
    uint64_t wpos;       /* bytes pushed so far (position of the next byte) */
    uint64_t evicted;    /* lines pushed out to make room */
    uint64_t taken;      /* lines offered through gs_lineq_take */
    uint64_t refused;    /* ... of them not stored: no final newline, or too long */
} gs_lineq;

/* max_lines >= 1 lines, cap_bytes of text (raised to GS_SINK_LINE_MAX). 0 or -1 (ENOMEM). */
int gs_lineq_init(gs_lineq *q, uint32_t max_lines, size_t cap_bytes);
void gs_lineq_free(gs_lineq *q);
/* Append a line (1..GS_SINK_LINE_MAX bytes), evicting the oldest as needed. 0, or -1 if too long. */
int gs_lineq_push(gs_lineq *q, const char *line, size_t len);

/* A sink's intake: count the line and store it when it is one whole line
 * (ends in '\n'); 0, or -1 refused (counted). */
int gs_lineq_take(gs_lineq *q, const char *line, size_t len);

/* One reader: a position in the ring plus the line it is sending. */
typedef struct {
    uint64_t next_seq;   /* next line to take from the ring */
    char cur[GS_SINK_LINE_MAX];
    size_t cur_len, cur_off; /* cur_len 0: no line in hand */
    uint64_t sent, dropped, bytes;
} gs_lineq_reader;

/* Start at the ring's next line: a reader that joins late gets lines from now on. */
void gs_lineq_reader_init(gs_lineq_reader *r, const gs_lineq *q);
/* Lines the ring evicted before this reader took them are added to r->dropped. */
void gs_lineq_reader_catch_up(gs_lineq_reader *r, const gs_lineq *q);
/* Lines waiting for this reader (in the ring and in hand). */
uint64_t gs_lineq_reader_pending(const gs_lineq_reader *r, const gs_lineq *q);
/* Evicted lines this reader has not noticed yet (for counters between pumps). */
uint64_t gs_lineq_reader_lost(const gs_lineq_reader *r, const gs_lineq *q);

/* Write function: bytes written, or -1 with errno (EAGAIN: try later). */
typedef ssize_t (*gs_lineq_write_fn)(int fd, const void *p, size_t n);

/* Send to fd until the ring is empty for this reader or the fd would block.
 * Returns 0 (idle or would block) or the errno of a write error (the line in
 * hand stays, with its offset). */
int gs_lineq_pump(gs_lineq_reader *r, const gs_lineq *q, int fd, gs_lineq_write_fn wr);

/* Message sinks (MQTT): send(ctx, line, len) takes one whole line (with its '\n')
 * and returns 0 when it took it, EAGAIN to stop for now (the line stays in hand) or
 * another errno (the line stays too). Returns 0 (idle or EAGAIN) or that errno. */
typedef int (*gs_lineq_send_fn)(void *ctx, const char *line, size_t len);
int gs_lineq_pump_msg(gs_lineq_reader *r, const gs_lineq *q, gs_lineq_send_fn send, void *ctx);

/* A stream was lost: the line in hand restarts from its first byte on the next
 * connection, so the new peer starts at a line boundary. */
void gs_lineq_reader_rewind(gs_lineq_reader *r);

/* write(2) and send(2) with MSG_NOSIGNAL | MSG_DONTWAIT, for gs_lineq_pump. */
ssize_t gs_lineq_write_fd(int fd, const void *p, size_t n);
ssize_t gs_lineq_write_sock(int fd, const void *p, size_t n);

#endif
