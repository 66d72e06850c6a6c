/* gs_out.h - write emitted lines to a file descriptor: whole lines only, either
 * one write(2) per line (live output, atomic on pipes up to PIPE_BUF) or
 * gathered in a buffer that only ever holds whole lines. The first error is
 * sticky: after it nothing more is written. */
#ifndef GS_OUT_H
#define GS_OUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

typedef struct {
    int fd;
    bool own_fd;       /* close it in gs_out_close */
    int err;           /* first errno, 0 none (EPIPE: the reader went away) */
    char *buf;         /* NULL: one write per line */
    size_t cap, len;
    uint64_t lines, bytes;
} gs_out;

/* buf_bytes 0: one write per line; else gather whole lines up to buf_bytes. 0 or -1 (errno). */
int gs_out_open_fd(gs_out *o, int fd, size_t buf_bytes);
/* The stream's descriptor (flushed first); the stream stays the caller's. */
int gs_out_open_stream(gs_out *o, FILE *f, size_t buf_bytes);
/* Create/truncate a file (mode 0644). -1 with errno on failure. */
int gs_out_open_path(gs_out *o, const char *path, size_t buf_bytes);
/* One line (it should end in '\n'); 0 ok, -1 once an error happened (o->err). */
int gs_out_line(gs_out *o, const char *line, size_t len);
int gs_out_flush(gs_out *o);
/* Flush, close an own descriptor; returns the sticky error state (0 or -1). */
int gs_out_close(gs_out *o);

#endif
