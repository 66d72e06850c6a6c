/* gs_emit.h - turn an event into one line of bytes in a caller buffer, so
 * stdout, a serial port, a socket and a test buffer get the same bytes. */
#ifndef GS_EMIT_H
#define GS_EMIT_H

#include "gs_event.h"

typedef enum { GS_FMT_JSON = 0, GS_FMT_NMEA } gs_format;

const char *gs_format_name(gs_format f);
bool gs_format_from_name(const char *s, size_t len, gs_format *out);

/* A JSON Lines object ending in '\n', NUL-terminated. Returns its length
 * (without the NUL), or 0 when cap is too small; then buf holds "" and nothing
 * partial. NaN/inf -> null. */
size_t gs_emit_json(const gs_event *ev, char *buf, size_t cap);

/* An NMEA 0183-style sentence "$GSxxx,...*HH\r\n" of at most 82 characters
 * (CR LF included). JUMP -> $GSJMP, HEIGHT -> $GSHGT, SUMMARY -> $GSSUM,
 * START -> $GSSTA; trace events have no NMEA form (returns 0, buf ""). Unknown
 * fields are empty. Same return convention. */
size_t gs_emit_nmea(const gs_event *ev, char *buf, size_t cap);

/* Dispatch on the format. */
size_t gs_emit(gs_format fmt, const gs_event *ev, char *buf, size_t cap);

/* A JSON string literal of s as the emitter writes strings (quotes included,
 * NUL-terminated): '"' and '\\' escaped, control bytes as \u00XX, bytes that
 * are not UTF-8 as \ufffd; NULL -> null. For other JSON writers at the edge
 * (sink status lines). Returns the length, 0 when cap is too small (buf ""). */
size_t gs_emit_json_str(const char *s, char *buf, size_t cap);

/* Enough for any event in either format when its strings are the core's own
 * short names (a start event's caller strings add their length). The widest
 * line is a jump with every number at its widest (-999999999999999.8750,
 * -1.23457e-300, 4294967295) and every warning: 907 bytes + NUL, measured by
 * tests/test_emit.c; 640 was too small for it (found by tests/fuzz/fuzz_emit.c). */
#define GS_EMIT_MAX 1024

#endif
