/* gs_kpread.h - keypoint readers: CSV (streamed, constant memory), AlphaPose
 * result lists and OpenPose per-frame folders (held in memory), all handing
 * out one frame of keypoints at a time with its source time in seconds.
 * This is the POSIX edge: it may use malloc and stdio. */
#ifndef GS_KPREAD_H
#define GS_KPREAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gravscale/gs_types.h"
#include "gs_json_tok.h"

#define GS_KP_MAX 33  /* keypoints of the largest layout (BlazePose-33) */

typedef enum { GS_KPF_CSV = 0, GS_KPF_ALPHAPOSE, GS_KPF_OPENPOSE } gs_kp_format;

const char *gs_kp_format_name(gs_kp_format f);
bool gs_kp_format_from_name(const char *s, gs_kp_format *out);

typedef struct {
    gs_kp_format format;
    bool layout_set;    /* --layout given: the CSV header must match it */
    gs_layout layout;
    double fps;         /* --fps, NaN when not given */
    long track;         /* --track, -1 when not given */
} gs_kpread_opts;

void gs_kpread_opts_default(gs_kpread_opts *o);

typedef struct {
    double t_s;              /* source time, seconds */
    uint64_t frame;          /* frame index (JSON, CSV 'frame'), else the 0-based data row */
    gs_kp kp[GS_KP_MAX];     /* gs_layout_kp_count(layout) used; missing: c = 0, x/y NaN when absent */
    float size_px;           /* point layout 'size' column, NaN unknown */
} gs_kpframe;

typedef enum {
    GS_KPR_FRAME = 1,   /* a frame was read */
    GS_KPR_EOF = 0,     /* clean end of input */
    GS_KPR_EDATA = -1,  /* bad input data (exit 1) */
    GS_KPR_EUSAGE = -2  /* options do not fit the input, e.g. --fps with timestamps (exit 2) */
} gs_kpr_status;

typedef struct {
    gs_kpr_status status;
    uint32_t line;      /* 1-based line of the offending row/object, 0 when not tied to a line */
    char field[48];     /* header name of the offending field, "" when none */
    char text[768];     /* ready to print after "gravscale: ": "FILE:LINE: message" */
} gs_kpread_error;

typedef struct gs_kpread gs_kpread;

/* Open a reader. On failure returns NULL and fills *err (status EDATA or EUSAGE). */
gs_kpread *gs_kpread_open(const char *path, const gs_kpread_opts *opts, gs_kpread_error *err);
/* Next frame. Returns GS_KPR_FRAME, GS_KPR_EOF, or an error status with *err
 * filled; after an error the reader stays in error. */
gs_kpr_status gs_kpread_next(gs_kpread *r, gs_kpframe *f, gs_kpread_error *err);
gs_layout gs_kpread_layout(const gs_kpread *r);
/* "timestamps" (CSV t column) or "cli" (times from --fps). */
const char *gs_kpread_fps_origin(const gs_kpread *r);
/* For progress: input bytes consumed so far and in total (0 when unknown). */
void gs_kpread_progress(const gs_kpread *r, uint64_t *done_bytes, uint64_t *total_bytes);
void gs_kpread_close(gs_kpread *r);

/* ---- shared by the reader implementations (not for callers) ------------- */

/* One detected person of a JSON source, COCO-17 keypoints. */
typedef struct {
    uint64_t frame;
    uint32_t line;      /* line of the person's object in its file */
    uint32_t order;     /* input order, keeps the sort stable */
    long track;         /* tracker id, -1 unknown */
    float score;
    gs_kp kp[17];
} gs_kp_person;

/* A growable array of persons; the JSON readers fill it, then hand it over. */
typedef struct {
    gs_kp_person *v;
    size_t n, cap;
} gs_kp_people;

bool gs_kp_people_push(gs_kp_people *p, const gs_kp_person *one);
void gs_kp_people_free(gs_kp_people *p);

/* Format an error: status, line, field and "path:line: " + printf-style message. */
void gs_kpread_fail(gs_kpread_error *err, gs_kpr_status st, const char *path, uint32_t line,
                    const char *field, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;

/* The implementations behind gs_kpread_open: they fill *people (all frames,
 * any order) from their input; the generic part sorts and chooses one person per frame. */
bool gs_kp_alphapose_load(const char *path, gs_kp_people *people, gs_kpread_error *err);
bool gs_kp_openpose_load(const char *dir, gs_kp_people *people, gs_kpread_error *err);

/* Read a whole file into a NUL-terminated malloc'd buffer (JSON readers). NULL + err on failure. */
char *gs_kp_slurp(const char *path, size_t *len, gs_kpread_error *err);
/* Read the JSON number array that starts with token *v into out[0..cap): the
 * count in *n (may exceed cap: then only cap stored). obj_line: the line named
 * in errors. false + err on bad JSON, a non-array or a non-number element. */
bool gs_kp_json_numbers(gs_jlex *lex, const gs_jtok *v, const char *path, uint32_t obj_line,
                        const char *key, double *out, size_t cap, size_t *n, gs_kpread_error *err);
/* Report the lexer's syntax error as "path:line: invalid JSON: why". */
void gs_kp_json_syntax(const gs_jlex *lex, const char *path, gs_kpread_error *err);
/* Start reading a JSON file: the first token must be of kind want, else an error
 * (empty file, syntax, or `what`) naming the file and line. */
bool gs_kp_json_begin(gs_jlex *lex, const char *text, size_t len, const char *path, gs_jt want,
                      const char *what, gs_jtok *first, gs_kpread_error *err);
/* The tracker id of an "idx"/"person_id" value starting with token *v: a number
 * or an array whose first element is a number; -1 for null, [] or a negative id. */
bool gs_kp_json_track(gs_jlex *lex, const gs_jtok *v, const char *path, uint32_t obj_line,
                      const char *key, long *track, gs_kpread_error *err);

/* The OpenPose -> COCO-17 maps (index into the source layout for each COCO-17 keypoint). */
/* Frame index from a file or image name: its last run of digits ("000123.jpg" -> 123). */
bool gs_kp_index_from_name(const char *s, size_t n, uint64_t *out);

extern const uint8_t gs_kp_body25_to_coco17[17];
extern const uint8_t gs_kp_coco18_to_coco17[17];

#endif
