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

/* Enough for any event in either format. */
#define GS_EMIT_MAX 640

#endif
