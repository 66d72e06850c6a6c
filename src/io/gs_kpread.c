/* gs_kpread.c - the keypoint reader front: the streamed CSV reader and, for the
 * JSON formats, the choice of one person per frame. */
#include "gs_kpread.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gravscale/gs_com.h"
#include "gravscale/gs_num.h"
#include "gs_fastnum.h"

#define CSV_BLOCK (1u << 20)          /* the read buffer: the longest line accepted */
#define CSV_READ (1u << 16)           /* bytes asked of one fread: the buffer's first pages stay in use and in cache */
#define CSV_MAX_COLS (2 + 3 * GS_KP_MAX + 1)
#define PEOPLE_FIRST_FRAMES 30        /* frames with people that decide the followed track */

enum { ROLE_T = 0, ROLE_FRAME, ROLE_X, ROLE_Y, ROLE_C, ROLE_SIZE };

struct gs_kpread {
    gs_kp_format format;
    gs_layout layout;
    const char *fps_origin;
    char *path;
    bool failed;
    gs_kpread_error saved;       /* the error repeated after a failure */
    uint64_t total_bytes, done_bytes;

    /* CSV */
    FILE *f;
    char *buf;
    size_t len, pos;
    bool eof;
    uint32_t line;               /* line number of the last line handed out */
    uint32_t blank_line;         /* first of a run of blank lines not yet followed by data, 0 none */
    int ncols;
    uint8_t role[CSV_MAX_COLS];
    uint8_t kidx[CSV_MAX_COLS];
    char *names;                 /* the header's names, NUL-separated */
    const char *name[CSV_MAX_COLS];
    int col_of_c[GS_KP_MAX];     /* column of c_k, for messages */
    bool has_t, has_frame, has_size;
    bool t_then_xyc;             /* the columns are t, then x_k, y_k, c_k for k = 0, 1, ... */
    double fps;
    double last_t;
    bool have_last;
    uint64_t row;

    /* JSON */
    gs_kp_people people;
    size_t next;                 /* next person index (people sorted by frame) */
    long chosen_track;           /* followed tracker id, -1 none */
    bool have_last_pos;
    double last_cx, last_cy, last_diag;
    uint64_t last_frame;
};

const char *gs_kp_format_name(gs_kp_format f)
{
    switch (f) {
    case GS_KPF_CSV: return "csv";
    case GS_KPF_ALPHAPOSE: return "alphapose";
    case GS_KPF_OPENPOSE: return "openpose";
    }
    return "?";
}

bool gs_kp_format_from_name(const char *s, gs_kp_format *out)
{
    static const gs_kp_format all[] = {GS_KPF_CSV, GS_KPF_ALPHAPOSE, GS_KPF_OPENPOSE};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) {
        if (strcmp(s, gs_kp_format_name(all[i])) == 0) {
            *out = all[i];
            return true;
        }
    }
    return false;
}

void gs_kpread_opts_default(gs_kpread_opts *o)
{
    o->format = GS_KPF_CSV;
    o->layout_set = false;
    o->layout = GS_LAYOUT_COCO17;
    o->fps = NAN;
    o->track = -1;
}

void gs_kpread_fail(gs_kpread_error *err, gs_kpr_status st, const char *path, uint32_t line,
                    const char *field, const char *fmt, ...)
{
    if (!err)
        return;
    err->status = st;
    err->line = line;
    snprintf(err->field, sizeof err->field, "%s", field ? field : "");
    int n;
    if (line > 0)
        n = snprintf(err->text, sizeof err->text, "%s:%u: ", path, (unsigned)line);
    else
        n = snprintf(err->text, sizeof err->text, "%s: ", path);
    if (n < 0 || (size_t)n >= sizeof err->text)
        return;
    if (field && field[0]) {
        int m = snprintf(err->text + n, sizeof err->text - (size_t)n, "field '%s': ", field);
        if (m < 0 || (size_t)(n + m) >= sizeof err->text)
            return;
        n += m;
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->text + n, sizeof err->text - (size_t)n, fmt, ap);
    va_end(ap);
}

/* A field's text for a message: at most 40 characters, shown as given. */
#define SHOW_MAX 40
#define SHOW(s, n) (int)((n) > SHOW_MAX ? SHOW_MAX : (n)), (s)

static gs_kpr_status remember(gs_kpread *r, const gs_kpread_error *err)
{
    r->failed = true;
    r->saved = *err;
    return err->status;
}

/* ------------------------------------------------------------------------ */
/* CSV                                                                      */

/* Next line without its "\n" or "\r\n". 1 = a line, 0 = end of file, -1 = error. */
static int csv_getline(gs_kpread *r, const char **s, size_t *n, bool *had_nl, gs_kpread_error *err)
{
    size_t scanned = 0; /* bytes after pos already known to hold no '\n' */
    for (;;) {
        char *start = r->buf + r->pos;
        size_t avail = r->len - r->pos;
        char *nl = avail > scanned ? memchr(start + scanned, '\n', avail - scanned) : NULL;
        if (nl || (r->eof && avail > 0)) {
            size_t l = nl ? (size_t)(nl - start) : avail;
            r->pos += nl ? l + 1 : l;
            *had_nl = nl != NULL;
            if (l > 0 && start[l - 1] == '\r')
                l--;
            *s = start;
            *n = l;
            r->line++;
            return 1;
        }
        if (r->eof)
            return 0;
        scanned = avail;
        if (r->pos > 0) {
            memmove(r->buf, start, avail);
            r->len = avail;
            r->pos = 0;
        }
        if (r->len == CSV_BLOCK) {
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line + 1, NULL,
                           "line longer than %u bytes", (unsigned)CSV_BLOCK);
            return -1;
        }
        size_t ask = CSV_BLOCK - r->len < CSV_READ ? CSV_BLOCK - r->len : CSV_READ;
        size_t got = fread(r->buf + r->len, 1, ask, r->f);
        r->len += got;
        r->buf[r->len] = '\0'; /* the sentinel the number scans stop at */
        r->done_bytes += got;
        if (got == 0) {
            if (ferror(r->f)) {
                gs_kpread_fail(err, GS_KPR_EDATA, r->path, 0, NULL, "read error: %s",
                               strerror(errno));
                return -1;
            }
            r->eof = true;
        }
    }
}

static void trim(const char **s, size_t *n)
{
    while (*n > 0 && (**s == ' ' || **s == '\t')) {
        (*s)++;
        (*n)--;
    }
    while (*n > 0 && ((*s)[*n - 1] == ' ' || (*s)[*n - 1] == '\t'))
        (*n)--;
}

/* Column name -> role and keypoint index; false for an unknown name. */
static bool csv_name_role(const char *s, uint8_t *role, int *k)
{
    *k = -1;
    if (strcmp(s, "t") == 0) {
        *role = ROLE_T;
        return true;
    }
    if (strcmp(s, "frame") == 0) {
        *role = ROLE_FRAME;
        return true;
    }
    if (strcmp(s, "size") == 0) {
        *role = ROLE_SIZE;
        return true;
    }
    if (s[0] != 'x' && s[0] != 'y' && s[0] != 'c')
        return false;
    *role = s[0] == 'x' ? ROLE_X : s[0] == 'y' ? ROLE_Y : ROLE_C;
    if (s[1] == '\0')
        return true; /* plain x,y,c: the point layout */
    long v = 0;
    for (const char *p = s + 1; *p; p++) {
        if (*p < '0' || *p > '9' || v > 1000)
            return false;
        v = v * 10 + (*p - '0');
    }
    if ((s[1] == '0' && s[2] != '\0'))
        return false; /* "x01" is not a name we write */
    *k = (int)v;
    return true;
}

static gs_kpr_status csv_header(gs_kpread *r, const gs_kpread_opts *opts, gs_kpread_error *err)
{
    const char *s;
    size_t n;
    bool nl;
    int got = csv_getline(r, &s, &n, &nl, err);
    if (got < 0)
        return err->status;
    if (got == 0) {
        gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL, "empty file (expected a header line)");
        return GS_KPR_EDATA;
    }
    if (n >= 3 && (unsigned char)s[0] == 0xEF && (unsigned char)s[1] == 0xBB &&
        (unsigned char)s[2] == 0xBF) {
        s += 3; /* a UTF-8 byte order mark some spreadsheet programs write */
        n -= 3;
    }
    r->names = malloc(n + 1);
    if (!r->names) {
        gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL, "out of memory");
        return GS_KPR_EDATA;
    }
    /* split into NUL-terminated, trimmed names */
    size_t w = 0;
    const char *p = s, *e = s + n;
    int ncols = 0;
    for (;;) {
        const char *q = memchr(p, ',', (size_t)(e - p));
        if (!q)
            q = e;
        const char *fs = p;
        size_t fl = (size_t)(q - p);
        trim(&fs, &fl);
        if (ncols >= CSV_MAX_COLS) {
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL,
                           "bad header: more than %d columns", CSV_MAX_COLS);
            return GS_KPR_EDATA;
        }
        r->name[ncols++] = r->names + w;
        memcpy(r->names + w, fs, fl);
        w += fl;
        r->names[w++] = '\0';
        if (q == e)
            break;
        p = q + 1;
    }
    r->ncols = ncols;
    if (n == 0) {
        gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL, "bad header: empty first line");
        return GS_KPR_EDATA;
    }

    int max_k = -1;
    bool plain = false;
    int seen_t = 0, seen_frame = 0, seen_size = 0;
    for (int c = 0; c < ncols; c++) {
        uint8_t role;
        int k;
        if (r->name[c][0] == '\0') {
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL, "bad header: column %d has no name",
                           c + 1);
            return GS_KPR_EDATA;
        }
        if (!csv_name_role(r->name[c], &role, &k) || k >= GS_KP_MAX) {
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL,
                           "bad header: unknown column '%.*s' (expected t or frame, then "
                           "x0,y0,c0,... or x,y,c[,size])",
                           SHOW(r->name[c], strlen(r->name[c])));
            return GS_KPR_EDATA;
        }
        r->role[c] = role;
        r->kidx[c] = (uint8_t)(k < 0 ? 0 : k);
        if (role == ROLE_T)
            seen_t++;
        else if (role == ROLE_FRAME)
            seen_frame++;
        else if (role == ROLE_SIZE)
            seen_size++;
        else if (k < 0)
            plain = true;
        else if (k > max_k)
            max_k = k;
    }
    if (seen_t > 1 || seen_frame > 1 || seen_size > 1) {
        gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL, "bad header: duplicate column '%s'",
                       seen_t > 1 ? "t" : seen_frame > 1 ? "frame" : "size");
        return GS_KPR_EDATA;
    }
    if (!seen_t && !seen_frame) {
        gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL,
                       "bad header: no time column (expected 't' or 'frame' first)");
        return GS_KPR_EDATA;
    }
    if (plain && max_k >= 0) {
        gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL,
                       "bad header: mixes point columns (x,y,c) with numbered keypoints");
        return GS_KPR_EDATA;
    }
    gs_layout layout;
    int nkp;
    if (plain) {
        layout = GS_LAYOUT_POINT;
        nkp = 1;
    } else if (max_k + 1 == 17) {
        layout = GS_LAYOUT_COCO17;
        nkp = 17;
    } else if (max_k + 1 == 33) {
        layout = GS_LAYOUT_BLAZEPOSE33;
        nkp = 33;
    } else {
        gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL,
                       max_k < 0 ? "bad header: no keypoint columns"
                                 : "bad header: keypoints 0..%d fit no layout (1, 17 or 33 points)",
                       max_k);
        return GS_KPR_EDATA;
    }
    if (seen_size && layout != GS_LAYOUT_POINT) {
        gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL,
                       "bad header: a 'size' column belongs to the point layout only");
        return GS_KPR_EDATA;
    }
    /* every x_k, y_k, c_k exactly once */
    int count[3][GS_KP_MAX];
    memset(count, 0, sizeof count);
    for (int c = 0; c < ncols; c++) {
        if (r->role[c] == ROLE_X || r->role[c] == ROLE_Y || r->role[c] == ROLE_C) {
            count[r->role[c] - ROLE_X][r->kidx[c]]++;
            if (r->role[c] == ROLE_C)
                r->col_of_c[r->kidx[c]] = c;
        }
    }
    for (int k = 0; k < nkp; k++) {
        for (int j = 0; j < 3; j++) {
            if (count[j][k] != 1) {
                char nm[16];
                if (plain)
                    snprintf(nm, sizeof nm, "%c", "xyc"[j]);
                else
                    snprintf(nm, sizeof nm, "%c%d", "xyc"[j], k);
                gs_kpread_fail(err, GS_KPR_EDATA, r->path, 1, NULL, "bad header: %s column '%s'",
                               count[j][k] == 0 ? "missing" : "duplicate", nm);
                return GS_KPR_EDATA;
            }
        }
    }
    if (opts->layout_set && opts->layout != layout) {
        gs_kpread_fail(err, GS_KPR_EUSAGE, r->path, 1, NULL,
                       "header has the %s layout but --layout %s was given", gs_layout_name(layout),
                       gs_layout_name(opts->layout));
        return GS_KPR_EUSAGE;
    }
    if (!nl) {
        /* a header and nothing else, without a newline: complete, no frames */
        r->eof = true;
    }
    r->layout = layout;
    r->t_then_xyc = r->role[0] == ROLE_T && ncols == 1 + 3 * nkp;
    for (int c = 1; r->t_then_xyc && c < ncols; c++)
        r->t_then_xyc = r->role[c] == ROLE_X + (c - 1) % 3 && r->kidx[c] == (c - 1) / 3;
    r->has_t = seen_t != 0;
    r->has_frame = seen_frame != 0;
    r->has_size = seen_size != 0;
    if (r->has_t) {
        if (!isnan(opts->fps)) {
            gs_kpread_fail(err, GS_KPR_EUSAGE, r->path, 0, NULL,
                           "--fps is not allowed: the file has timestamps (column 't'); "
                           "use a 'frame' column instead of 't' to give times by --fps");
            return GS_KPR_EUSAGE;
        }
        r->fps_origin = "timestamps";
    } else {
        if (isnan(opts->fps)) {
            gs_kpread_fail(err, GS_KPR_EUSAGE, r->path, 0, NULL,
                           "the file has a 'frame' column instead of 't': --fps is required");
            return GS_KPR_EUSAGE;
        }
        r->fps = opts->fps;
        r->fps_origin = "cli";
    }
    return GS_KPR_FRAME;
}

static bool parse_number(const char *s, size_t n, double *out) { return gs_fastnum_parse(s, n, out); }

/* A row read by a fast pass: its time t must go forward (else false: the
 * general pass decides), and it is the frame's. */
static bool fast_row_done(gs_kpread *r, gs_kpframe *f, double t, double frame)
{
    if (r->have_last && !(t > r->last_t))
        return false;
    r->last_t = t;
    r->have_last = true;
    f->t_s = t;
    f->frame = r->has_frame ? (uint64_t)frame : r->row;
    r->row++;
    return true;
}

/* csv_row_fast for the columns t, x0, y0, c0, x1, ...: no column's role to look up. */
static bool csv_row_fast_xyc(gs_kpread *r, const char *s, size_t n, gs_kpframe *f)
{
    const char *e = s + n;
    double t;
    const char *q = gs_fastnum_scan(s, &t);
    if (!q || *q != ',')
        return false;
    bool bad_c = false;
    gs_kp *kp = f->kp;
    int last = r->ncols / 3 - 1;
    for (int k = 0;; k++) {
        double x, y, c;
        if (!(q = gs_fastnum_scan(q + 1, &x)) || *q != ',' || !(q = gs_fastnum_scan(q + 1, &y)) ||
            *q != ',' || !(q = gs_fastnum_scan(q + 1, &c)))
            return false;
        float cv = (float)c;
        kp[k].x_px = (float)x;
        kp[k].y_px = (float)y;
        kp[k].c = cv;
        bad_c |= !(cv >= 0.0f && cv <= 1.0f);
        if (k == last)
            break;
        if (*q != ',')
            return false;
    }
    if (q != e || bad_c)
        return false;
    f->size_px = NAN;
    return fast_row_done(r, f, t, NAN);
}

/* The common row, every field a plain decimal (a frame number plain digits), as
 * many as the header's, confidences within 0..1 and the time going forward: one
 * pass into f. false when anything differs: csv_row's general pass then decides,
 * with its messages, from the start of the row again. s[n] exists and is a line
 * end or the buffer's sentinel (csv_getline). */
static bool csv_row_fast(gs_kpread *r, const char *s, size_t n, gs_kpframe *f)
{
    const char *p = s, *e = s + n;
    double t = NAN, frame = NAN;
    bool bad_c = false;
    f->size_px = NAN;
    int last = r->ncols - 1;
    for (int c = 0; c <= last; c++) {
        double d;
        const char *q = gs_fastnum_scan(p, &d);
        if (!q || (c < last ? *q != ',' : q != e))
            return false;
        switch (r->role[c]) {
        case ROLE_T: t = d; break;
        case ROLE_FRAME:
            if (*p < '0' || *p > '9' || memchr(p, '.', (size_t)(q - p)))
                return false; /* a sign or a fraction: the integer parser's call */
            frame = d;
            break;
        case ROLE_X: f->kp[r->kidx[c]].x_px = (float)d; break;
        case ROLE_Y: f->kp[r->kidx[c]].y_px = (float)d; break;
        case ROLE_C: {
            float cv = (float)d;
            f->kp[r->kidx[c]].c = cv;
            bad_c |= !(cv >= 0.0f && cv <= 1.0f);
            break;
        }
        default: f->size_px = (float)d; break;
        }
        p = q + 1;
    }
    if (bad_c)
        return false;
    if (!r->has_t)
        t = frame / r->fps;
    return fast_row_done(r, f, t, frame);
}

static gs_kpr_status csv_row(gs_kpread *r, const char *s, size_t n, bool had_nl, gs_kpframe *f,
                             gs_kpread_error *err)
{
    if (r->t_then_xyc ? csv_row_fast_xyc(r, s, n, f) : r->ncols <= CSV_MAX_COLS && csv_row_fast(r, s, n, f))
        return GS_KPR_FRAME;
    const char *fs[CSV_MAX_COLS];
    size_t fl[CSV_MAX_COLS];
    double val[CSV_MAX_COLS];
    bool quick[CSV_MAX_COLS]; /* the field is a plain decimal, parsed while splitting into val */
    int col = 0;
    const char *p = s, *e = s + n;
    for (;;) {
        const char *q = p;
        bool fast = col < CSV_MAX_COLS && col < r->ncols && r->role[col] != ROLE_FRAME &&
                    (q = gs_fastnum_scan(p, &val[col])) != NULL && (q == e || *q == ',');
        if (!fast) {
            q = p;
            while (q < e && *q != ',')
                q++;
        }
        if (col < CSV_MAX_COLS) {
            fs[col] = p;
            fl[col] = (size_t)(q - p);
            quick[col] = fast;
        }
        col++;
        if (q == e)
            break;
        p = q + 1;
    }
    if (col != r->ncols) {
        if (!had_nl)
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, NULL,
                           "truncated last line (no newline at end of file): expected %d fields, "
                           "found %d",
                           r->ncols, col);
        else
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, NULL,
                           "expected %d fields, found %d", r->ncols, col);
        return GS_KPR_EDATA;
    }
    int nkp = (int)gs_layout_kp_count(r->layout);
    uint32_t empty_mask[(CSV_MAX_COLS + 31) / 32] = {0};
    double t = NAN;
    double frame = NAN;
    bool checks = false; /* an empty field or a confidence outside 0..1: the second pass below */
    f->size_px = NAN;
    for (int c = 0; c < col; c++) {
        const char *v = fs[c];
        size_t vl = fl[c];
        double d = NAN;
        if (!quick[c] && vl > 0 && (v[0] == ' ' || v[0] == '\t' || v[vl - 1] == ' ' || v[vl - 1] == '\t'))
            trim(&v, &vl);
        if (quick[c]) {
            d = val[c]; /* finite, below 1e15: the checks below cannot fail */
        } else if (vl == 0) {
            empty_mask[c >> 5] |= 1u << (c & 31);
            checks = true;
        } else if (r->role[c] == ROLE_FRAME) {
            long iv;
            if (!gs_num_parse_int(v, vl, &iv) || iv < 0) {
                gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c],
                               "not a frame number ('%.*s')", SHOW(v, vl));
                return GS_KPR_EDATA;
            }
            d = (double)iv;
        } else if (!parse_number(v, vl, &d) || !isfinite(d)) {
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c],
                           "not a number ('%.*s')", SHOW(v, vl));
            return GS_KPR_EDATA;
        } else if (r->role[c] >= ROLE_X && !(fabs(d) <= FLT_MAX)) {
            /* kept as float: 1e39 would become inf behind the checks (found by tests/fuzz/fuzz_csv.c) */
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c],
                           "'%.*s' is beyond the float range of a pixel value", SHOW(v, vl));
            return GS_KPR_EDATA;
        }
        switch (r->role[c]) {
        case ROLE_T: t = d; break;
        case ROLE_FRAME: frame = d; break;
        case ROLE_X: f->kp[r->kidx[c]].x_px = (float)d; break;
        case ROLE_Y: f->kp[r->kidx[c]].y_px = (float)d; break;
        case ROLE_C:
            f->kp[r->kidx[c]].c = (float)d;
            checks |= !((float)d >= 0.0f && (float)d <= 1.0f);
            break;
        default: f->size_px = (float)d; break;
        }
    }
    /* checks in column order: first the empty fields, then values */
    for (int c = 0; checks && c < col; c++) {
        bool empty = (empty_mask[c >> 5] >> (c & 31)) & 1u;
        uint8_t role = r->role[c];
        if (role == ROLE_C) {
            float cv = f->kp[r->kidx[c]].c;
            if (empty) {
                gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c],
                               "empty (a missing keypoint has c = 0)");
                return GS_KPR_EDATA;
            }
            if (!(cv >= 0.0f && cv <= 1.0f)) {
                gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c],
                               "confidence %.*s outside 0..1", SHOW(fs[c], fl[c]));
                return GS_KPR_EDATA;
            }
        } else if (empty) {
            if (role == ROLE_X || role == ROLE_Y || role == ROLE_SIZE) {
                int k = role == ROLE_SIZE ? 0 : r->kidx[c];
                float cv = f->kp[k].c;
                bool c_empty = (empty_mask[r->col_of_c[k] >> 5] >> (r->col_of_c[k] & 31)) & 1u;
                if (c_empty || cv == 0.0f) {
                    if (role == ROLE_X)
                        f->kp[k].x_px = NAN;
                    else if (role == ROLE_Y)
                        f->kp[k].y_px = NAN;
                    continue; /* a missing keypoint (size: of a missing point) */
                }
                gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c],
                               "empty, but '%s' is %.*s (only a missing keypoint, c = 0, may "
                               "have empty x,y)",
                               r->name[r->col_of_c[k]], SHOW(fs[r->col_of_c[k]], fl[r->col_of_c[k]]));
                return GS_KPR_EDATA;
            }
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c], "empty");
            return GS_KPR_EDATA;
        }
    }
    (void)nkp;
    if (r->has_t) {
        if (r->have_last && !(t > r->last_t)) {
            int c = 0;
            while (r->role[c] != ROLE_T)
                c++;
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c],
                           "time %s (%.*s after %.9g)",
                           t == r->last_t ? "repeats" : "goes backwards", SHOW(fs[c], fl[c]),
                           r->last_t);
            return GS_KPR_EDATA;
        }
    } else {
        double tf = frame / r->fps;
        if (r->have_last && !(tf > r->last_t)) {
            int c = 0;
            while (r->role[c] != ROLE_FRAME)
                c++;
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->line, r->name[c],
                           "frame number %s (%.*s after %.0f)",
                           tf == r->last_t ? "repeats" : "goes backwards", SHOW(fs[c], fl[c]),
                           r->last_t * r->fps);
            return GS_KPR_EDATA;
        }
        t = tf;
    }
    r->last_t = t;
    r->have_last = true;
    f->t_s = t;
    f->frame = r->has_frame ? (uint64_t)frame : r->row;
    r->row++;
    return GS_KPR_FRAME;
}

static gs_kpr_status csv_next(gs_kpread *r, gs_kpframe *f, gs_kpread_error *err)
{
    for (;;) {
        const char *s;
        size_t n;
        bool nl;
        int got = csv_getline(r, &s, &n, &nl, err);
        if (got < 0)
            return err->status;
        if (got == 0)
            return GS_KPR_EOF; /* blank lines at the very end are fine */
        if (n == 0) {
            if (r->blank_line == 0)
                r->blank_line = r->line;
            continue;
        }
        if (r->blank_line) {
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, r->blank_line, NULL,
                           "empty line (a missing frame is an absent row)");
            return GS_KPR_EDATA;
        }
        return csv_row(r, s, n, nl, f, err);
    }
}

/* ------------------------------------------------------------------------ */
/* JSON sources: one person per frame                                       */

bool gs_kp_people_push(gs_kp_people *p, const gs_kp_person *one)
{
    if (p->n == p->cap) {
        size_t cap = p->cap ? p->cap * 2 : 256;
        gs_kp_person *v = realloc(p->v, cap * sizeof *v);
        if (!v)
            return false;
        p->v = v;
        p->cap = cap;
    }
    p->v[p->n] = *one;
    p->v[p->n].order = (uint32_t)p->n;
    p->n++;
    return true;
}

void gs_kp_people_free(gs_kp_people *p)
{
    free(p->v);
    p->v = NULL;
    p->n = p->cap = 0;
}

static int person_cmp(const void *a, const void *b)
{
    const gs_kp_person *x = a, *y = b;
    if (x->frame != y->frame)
        return x->frame < y->frame ? -1 : 1;
    return x->order < y->order ? -1 : x->order > y->order;
}

/* Bounding box of the visible keypoints: area, centre and diagonal; false when none. */
static bool person_box(const gs_kp_person *p, double *area, double *cx, double *cy, double *diag)
{
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    int n = 0;
    for (int k = 0; k < 17; k++) {
        const gs_kp *kp = &p->kp[k];
        if (!(kp->c > 0.0f) || !isfinite(kp->x_px) || !isfinite(kp->y_px))
            continue;
        x0 = fmin(x0, kp->x_px);
        x1 = fmax(x1, kp->x_px);
        y0 = fmin(y0, kp->y_px);
        y1 = fmax(y1, kp->y_px);
        n++;
    }
    if (n == 0)
        return false;
    *area = (x1 - x0) * (y1 - y0);
    *cx = 0.5 * (x0 + x1);
    *cy = 0.5 * (y0 + y1);
    *diag = hypot(x1 - x0, y1 - y0);
    return true;
}

/* The followed track when no --track: the id with the largest summed box area
 * over the first frames that show people; -1 when those people carry no ids. */
static long people_pick_track(const gs_kp_people *pp)
{
    long best = -1;
    double best_area = -1.0;
    size_t i = 0;
    int frames = 0;
    while (i < pp->n && frames < PEOPLE_FIRST_FRAMES) {
        size_t j = i;
        while (j < pp->n && pp->v[j].frame == pp->v[i].frame)
            j++;
        frames++;
        i = j;
    }
    size_t end = i;
    for (size_t a = 0; a < end; a++) {
        long id = pp->v[a].track;
        if (id < 0)
            continue;
        bool done = false;
        for (size_t b = 0; b < a; b++)
            if (pp->v[b].track == id)
                done = true;
        if (done)
            continue;
        double sum = 0.0;
        for (size_t b = a; b < end; b++) {
            double ar, cx, cy, dg;
            if (pp->v[b].track == id && person_box(&pp->v[b], &ar, &cx, &cy, &dg))
                sum += ar;
        }
        if (sum > best_area) {
            best_area = sum;
            best = id;
        }
    }
    return best;
}

static gs_kpr_status people_next(gs_kpread *r, gs_kpframe *f)
{
    const gs_kp_people *pp = &r->people;
    while (r->next < pp->n) {
        size_t i = r->next, j = i;
        uint64_t frame = pp->v[i].frame;
        while (j < pp->n && pp->v[j].frame == frame)
            j++;
        r->next = j;
        const gs_kp_person *pick = NULL;
        if (r->chosen_track >= 0) {
            for (size_t a = i; a < j && !pick; a++)
                if (pp->v[a].track == r->chosen_track)
                    pick = &pp->v[a];
        }
        if (!pick) {
            /* people without an id: the largest at first, then the nearest to the last one */
            double best = INFINITY;
            for (size_t a = i; a < j; a++) {
                const gs_kp_person *c = &pp->v[a];
                double ar, cx, cy, dg;
                if (c->track >= 0 && r->chosen_track >= 0)
                    continue; /* another tracked person */
                if (!person_box(c, &ar, &cx, &cy, &dg))
                    continue;
                double cost;
                if (r->have_last_pos) {
                    double gap = (double)(frame - r->last_frame);
                    double gate = r->last_diag * fmin(0.25 + 0.25 * gap, 3.0);
                    double d = hypot(cx - r->last_cx, cy - r->last_cy);
                    if (d > gate)
                        continue; /* too far to be the same person */
                    cost = d;
                } else {
                    cost = -ar;
                }
                if (cost < best) {
                    best = cost;
                    pick = c;
                }
            }
        }
        if (!pick)
            continue; /* the followed person is not in this frame: a missing frame */
        double ar, cx, cy, dg;
        if (person_box(pick, &ar, &cx, &cy, &dg)) {
            r->have_last_pos = true;
            r->last_cx = cx;
            r->last_cy = cy;
            r->last_diag = dg > 1.0 ? dg : 1.0;
            r->last_frame = frame;
        }
        memcpy(f->kp, pick->kp, sizeof pick->kp);
        f->frame = frame;
        f->t_s = (double)frame / r->fps;
        f->size_px = NAN;
        return GS_KPR_FRAME;
    }
    return GS_KPR_EOF;
}

static gs_kpr_status people_open(gs_kpread *r, const gs_kpread_opts *opts, gs_kpread_error *err)
{
    if (opts->layout_set && opts->layout != GS_LAYOUT_COCO17) {
        gs_kpread_fail(err, GS_KPR_EUSAGE, r->path, 0, NULL,
                       "--layout %s does not fit --format %s (its keypoints are coco17)",
                       gs_layout_name(opts->layout), gs_kp_format_name(opts->format));
        return GS_KPR_EUSAGE;
    }
    if (!(opts->fps > 0.0) || !isfinite(opts->fps)) {
        gs_kpread_fail(err, GS_KPR_EUSAGE, r->path, 0, NULL,
                       "--fps is required with --format %s (frame times are index / fps)",
                       gs_kp_format_name(opts->format));
        return GS_KPR_EUSAGE;
    }
    bool ok = opts->format == GS_KPF_ALPHAPOSE ? gs_kp_alphapose_load(r->path, &r->people, err)
                                               : gs_kp_openpose_load(r->path, &r->people, err);
    if (!ok)
        return err->status;
    if (r->people.n > 1)
        qsort(r->people.v, r->people.n, sizeof *r->people.v, person_cmp);
    if (opts->track >= 0) {
        bool found = false;
        for (size_t i = 0; i < r->people.n && !found; i++)
            found = r->people.v[i].track == opts->track;
        if (!found) {
            gs_kpread_fail(err, GS_KPR_EDATA, r->path, 0, NULL, "no person with track id %ld",
                           opts->track);
            return GS_KPR_EDATA;
        }
        r->chosen_track = opts->track;
    } else {
        r->chosen_track = people_pick_track(&r->people);
    }
    r->layout = GS_LAYOUT_COCO17;
    r->fps = opts->fps;
    r->fps_origin = "cli";
    return GS_KPR_FRAME;
}

/* ------------------------------------------------------------------------ */

gs_kpread *gs_kpread_open(const char *path, const gs_kpread_opts *opts, gs_kpread_error *err)
{
    gs_kpread *r = calloc(1, sizeof *r);
    char *pcopy = r ? malloc(strlen(path) + 1) : NULL;
    if (!r || !pcopy) {
        free(r);
        gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "out of memory");
        return NULL;
    }
    strcpy(pcopy, path);
    r->path = pcopy;
    r->format = opts->format;
    r->chosen_track = -1;
    gs_kpr_status st;
    if (opts->format == GS_KPF_CSV) {
        struct stat sb;
        r->f = fopen(path, "rb");
        if (!r->f) {
            gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "cannot open: %s", strerror(errno));
            gs_kpread_close(r);
            return NULL;
        }
        if (fstat(fileno(r->f), &sb) == 0) {
            if (S_ISDIR(sb.st_mode)) {
                gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL,
                               "is a folder, not a CSV file (an OpenPose folder needs "
                               "--format openpose)");
                gs_kpread_close(r);
                return NULL;
            }
            if (S_ISREG(sb.st_mode))
                r->total_bytes = (uint64_t)sb.st_size;
        }
        r->buf = malloc(CSV_BLOCK + 1); /* + the sentinel */
        if (!r->buf) {
            gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "out of memory");
            gs_kpread_close(r);
            return NULL;
        }
        st = csv_header(r, opts, err);
    } else {
        st = people_open(r, opts, err);
    }
    if (st != GS_KPR_FRAME) {
        gs_kpread_close(r);
        return NULL;
    }
    return r;
}

gs_kpr_status gs_kpread_next(gs_kpread *r, gs_kpframe *f, gs_kpread_error *err)
{
    if (r->failed) {
        *err = r->saved;
        return err->status;
    }
    gs_kpr_status st = r->format == GS_KPF_CSV ? csv_next(r, f, err) : people_next(r, f);
    if (st < 0)
        return remember(r, err);
    return st;
}

gs_layout gs_kpread_layout(const gs_kpread *r) { return r->layout; }

const char *gs_kpread_fps_origin(const gs_kpread *r) { return r->fps_origin; }

void gs_kpread_progress(const gs_kpread *r, uint64_t *done_bytes, uint64_t *total_bytes)
{
    if (r->format == GS_KPF_CSV) {
        *done_bytes = r->done_bytes - (r->len - r->pos);
        *total_bytes = r->total_bytes;
    } else {
        *done_bytes = r->next;
        *total_bytes = r->people.n;
    }
}

void gs_kpread_close(gs_kpread *r)
{
    if (!r)
        return;
    if (r->f)
        fclose(r->f);
    free(r->buf);
    free(r->names);
    gs_kp_people_free(&r->people);
    free(r->path);
    free(r);
}
