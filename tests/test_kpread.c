/* test_kpread.c - the keypoint readers against files written by the test:
 * a table of bad CSV inputs (each with its expected line, field and message),
 * valid CSV of every layout (CRLF, missing keypoints, frame column, lines across
 * the 1 MiB read block), AlphaPose with two people and frames out of order,
 * the fixed-order and the looked-up column passes agreeing on the sample,
 * OpenPose BODY_25 / COCO-18 mapped to COCO-17 keypoint by keypoint, and the
 * JSON tokenizer on good and bad documents. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "unity.h"
#include "gs_json_tok.h"
#include "gs_kpread.h"

static char g_dir[128];
static int g_seq;

void setUp(void) {}
void tearDown(void) {}

/* Write text to a new file in the temp dir; its path into path (256 bytes). */
static void write_file_n(const char *name, const char *text, size_t len, char *path)
{
    snprintf(path, 256, "%s/%03d_%s", g_dir, g_seq++, name);
    FILE *f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
    TEST_ASSERT_EQUAL_UINT64(len, fwrite(text, 1, len, f));
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
}

static void write_file(const char *name, const char *text, char *path)
{
    write_file_n(name, text, strlen(text), path);
}

/* Read everything: frames into out (up to cap), returns the final status. */
static gs_kpr_status read_all(const char *path, const gs_kpread_opts *o, gs_kpframe *out,
                              size_t cap, size_t *n, gs_kpread_error *err, gs_layout *layout)
{
    *n = 0;
    memset(err, 0, sizeof *err);
    gs_kpread *r = gs_kpread_open(path, o, err);
    if (!r)
        return err->status;
    if (layout)
        *layout = gs_kpread_layout(r);
    gs_kpframe tmp;
    gs_kpr_status st;
    for (;;) {
        st = gs_kpread_next(r, *n < cap ? &out[*n] : &tmp, err);
        if (st != GS_KPR_FRAME)
            break;
        (*n)++;
    }
    if (st < 0) {
        /* the reader stays in error */
        gs_kpread_error again;
        TEST_ASSERT_EQUAL_INT(st, gs_kpread_next(r, &tmp, &again));
        TEST_ASSERT_EQUAL_STRING(err->text, again.text);
    }
    gs_kpread_close(r);
    return st;
}

/* ---- CSV: the table of bad inputs -------------------------------------- */

typedef struct {
    const char *name;
    const char *text;          /* whole file */
    double fps;                /* NaN: no --fps */
    int layout;                /* -1: no --layout */
    gs_kpr_status status;
    size_t frames_before;      /* frames read before the error */
    uint32_t line;             /* 0: no line in the message */
    const char *field;         /* "" none */
    const char *msg;           /* substring of the message */
} csv_bad;

static const csv_bad k_bad[] = {
    {"not a number", "t,x,y,c\n0,1,2,0.9\n0.1,abc,2,0.9\n", NAN, -1, GS_KPR_EDATA, 1, 3, "x",
     "not a number ('abc')"},
    {"nan text", "t,x,y,c\n0,1,2,0.9\n0.1,1,nan,0.9\n", NAN, -1, GS_KPR_EDATA, 1, 3, "y",
     "not a number ('nan')"},
    {"inf text", "t,x,y,c\n0,inf,2,0.9\n", NAN, -1, GS_KPR_EDATA, 0, 2, "x", "not a number ('inf')"},
    {"overflow", "t,x,y,c\n0,1e999,2,0.9\n", NAN, -1, GS_KPR_EDATA, 0, 2, "x", "not a number"},
    /* finite as double, inf as the float a keypoint is kept in */
    {"float overflow", "t,x,y,c\n0,1,2,0.9\n0.1,1e39,2,0.9\n", NAN, -1, GS_KPR_EDATA, 1, 3, "x",
     "'1e39' is beyond the float range"},
    {"float overflow y", "t,x,y,c\n0,1,-3.5e38,0.9\n", NAN, -1, GS_KPR_EDATA, 0, 2, "y",
     "'-3.5e38' is beyond the float range"},
    {"float overflow size", "t,x,y,c,size\n0,1,2,0.9,1e300\n", NAN, -1, GS_KPR_EDATA, 0, 2, "size",
     "beyond the float range"},
    {"spaces inside", "t,x,y,c\n0,1 2,2,0.9\n", NAN, -1, GS_KPR_EDATA, 0, 2, "x",
     "not a number ('1 2')"},
    {"two dots", "t,x,y,c\n0,1.2.3,2,0.9\n", NAN, -1, GS_KPR_EDATA, 0, 2, "x", "not a number"},
    {"time backwards", "t,x,y,c\n0.2,1,2,0.9\n0.1,1,2,0.9\n", NAN, -1, GS_KPR_EDATA, 1, 3, "t",
     "time goes backwards"},
    {"time repeats", "t,x,y,c\n0,1,2,0.9\n0.1,1,2,0.9\n0.1,1,2,0.9\n", NAN, -1, GS_KPR_EDATA, 2, 4,
     "t", "time repeats"},
    {"empty time", "t,x,y,c\n,1,2,0.9\n", NAN, -1, GS_KPR_EDATA, 0, 2, "t", "empty"},
    {"too few fields", "t,x,y,c\n0,1,2,0.9\n0.1,1,2\n", NAN, -1, GS_KPR_EDATA, 1, 3, "",
     "expected 4 fields, found 3"},
    {"too many fields", "t,x,y,c\n0,1,2,0.9,7\n", NAN, -1, GS_KPR_EDATA, 0, 2, "",
     "expected 4 fields, found 5"},
    {"truncated last line", "t,x,y,c\n0,1,2,0.9\n0.1,1,", NAN, -1, GS_KPR_EDATA, 1, 3, "",
     "truncated last line"},
    {"empty c", "t,x,y,c\n0,1,2,\n", NAN, -1, GS_KPR_EDATA, 0, 2, "c", "empty"},
    {"empty x with c", "t,x,y,c\n0,,2,0.8\n", NAN, -1, GS_KPR_EDATA, 0, 2, "x", "'c' is 0.8"},
    {"c above 1", "t,x,y,c\n0,1,2,1.5\n", NAN, -1, GS_KPR_EDATA, 0, 2, "c", "outside 0..1"},
    {"c negative", "t,x,y,c\n0,1,2,-0.1\n", NAN, -1, GS_KPR_EDATA, 0, 2, "c", "outside 0..1"},
    {"blank line inside", "t,x,y,c\n0,1,2,0.9\n\n0.1,1,2,0.9\n", NAN, -1, GS_KPR_EDATA, 1, 3, "",
     "empty line"},
    {"empty file", "", NAN, -1, GS_KPR_EDATA, 0, 1, "", "empty file"},
    {"empty header line", "\n0,1,2,0.9\n", NAN, -1, GS_KPR_EDATA, 0, 1, "", "bad header"},
    {"unknown column", "t,x,y,conf\n", NAN, -1, GS_KPR_EDATA, 0, 1, "", "unknown column 'conf'"},
    {"no time column", "x,y,c\n", NAN, -1, GS_KPR_EDATA, 0, 1, "", "no time column"},
    {"missing c", "t,x,y\n", NAN, -1, GS_KPR_EDATA, 0, 1, "", "missing column 'c'"},
    {"duplicate x", "t,x,y,c,x\n", NAN, -1, GS_KPR_EDATA, 0, 1, "", "duplicate column 'x'"},
    {"mixed names", "t,x,y,c,x0,y0,c0\n", NAN, -1, GS_KPR_EDATA, 0, 1, "", "mixes"},
    {"two keypoints", "t,x0,y0,c0,x1,y1,c1\n", NAN, -1, GS_KPR_EDATA, 0, 1, "", "fit no layout"},
    {"size with coco", NULL, NAN, -1, GS_KPR_EDATA, 0, 1, "", "'size' column"},
    {"fps with t", "t,x,y,c\n0,1,2,0.9\n", 30.0, -1, GS_KPR_EUSAGE, 0, 0, "", "--fps is not allowed"},
    {"frame without fps", "frame,x,y,c\n0,1,2,0.9\n", NAN, -1, GS_KPR_EUSAGE, 0, 0, "",
     "--fps is required"},
    {"frame not integer", "frame,x,y,c\n0,1,2,0.9\n1.5,1,2,0.9\n", 30.0, -1, GS_KPR_EDATA, 1, 3,
     "frame", "not a frame number ('1.5')"},
    {"frame repeats", "frame,x,y,c\n0,1,2,0.9\n0,1,2,0.9\n", 30.0, -1, GS_KPR_EDATA, 1, 3, "frame",
     "frame number repeats"},
    {"layout mismatch", "t,x,y,c\n0,1,2,0.9\n", NAN, GS_LAYOUT_COCO17, GS_KPR_EUSAGE, 0, 1, "",
     "--layout coco17"},
    {"quoted number", "t,x,y,c\n0,\"1\",2,0.9\n", NAN, -1, GS_KPR_EDATA, 0, 2, "x",
     "not a number"},
};

/* "t,x0,y0,c0,...,x16,y16,c16" (+ ",size" when with_size) */
static void coco_header(char *buf, size_t cap, int npts, bool with_size)
{
    int n = snprintf(buf, cap, "t");
    for (int k = 0; k < npts; k++)
        n += snprintf(buf + n, cap - (size_t)n, ",x%d,y%d,c%d", k, k, k);
    if (with_size)
        n += snprintf(buf + n, cap - (size_t)n, ",size");
    snprintf(buf + n, cap - (size_t)n, "\n");
}

void test_csv_bad_inputs(void)
{
    for (size_t i = 0; i < sizeof k_bad / sizeof k_bad[0]; i++) {
        const csv_bad *c = &k_bad[i];
        char path[256], text[2048];
        const char *body = c->text;
        if (!body) { /* the size column with a COCO-17 header */
            coco_header(text, sizeof text, 17, true);
            body = text;
        }
        write_file("bad.csv", body, path);
        gs_kpread_opts o;
        gs_kpread_opts_default(&o);
        o.fps = c->fps;
        if (c->layout >= 0) {
            o.layout_set = true;
            o.layout = (gs_layout)c->layout;
        }
        gs_kpframe fr[4];
        size_t n;
        gs_kpread_error err;
        gs_kpr_status st = read_all(path, &o, fr, 4, &n, &err, NULL);
        char ctx[1024];
        snprintf(ctx, sizeof ctx, "case '%s': %s", c->name, err.text);
        TEST_ASSERT_EQUAL_INT_MESSAGE(c->status, st, ctx);
        TEST_ASSERT_EQUAL_UINT64_MESSAGE((uint64_t)(c->frames_before), (uint64_t)(n), ctx);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(c->line, err.line, ctx);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(c->field, err.field, ctx);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err.text, c->msg), ctx);
        /* "FILE:LINE: field 'name': message" */
        char head[512];
        if (c->line > 0)
            snprintf(head, sizeof head, "%s:%u: ", path, (unsigned)c->line);
        else
            snprintf(head, sizeof head, "%s: ", path);
        if (c->field[0])
            snprintf(head + strlen(head), sizeof head - strlen(head), "field '%s': ", c->field);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(err.text, head, strlen(head)), ctx);
        TEST_ASSERT_NULL_MESSAGE(strchr(err.text, '\n'), ctx); /* one line */
    }
}

void test_csv_exact_message(void)
{
    char path[256], hdr[1024], text[4096];
    coco_header(hdr, sizeof hdr, 17, false);
    int n = snprintf(text, sizeof text, "%s", hdr);
    for (int row = 0; row < 3; row++) {
        n += snprintf(text + n, sizeof text - (size_t)n, "%d.5", row);
        for (int k = 0; k < 17; k++) {
            if (row == 2 && k == 5)
                n += snprintf(text + n, sizeof text - (size_t)n, ",abc,1,0.9");
            else
                n += snprintf(text + n, sizeof text - (size_t)n, ",%d,%d,0.9", 100 + k, 200 + k);
        }
        n += snprintf(text + n, sizeof text - (size_t)n, "\n");
    }
    write_file("x5.csv", text, path);
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    gs_kpframe fr[4];
    size_t nf;
    gs_kpread_error err;
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, read_all(path, &o, fr, 4, &nf, &err, NULL));
    TEST_ASSERT_EQUAL_UINT64(2, nf);
    char want[512];
    snprintf(want, sizeof want, "%s:4: field 'x5': not a number ('abc')", path);
    TEST_ASSERT_EQUAL_STRING(want, err.text);
}

void test_csv_missing_file(void)
{
    char path[256];
    snprintf(path, sizeof path, "%s/does_not_exist.csv", g_dir);
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    gs_kpread_error err;
    TEST_ASSERT_NULL(gs_kpread_open(path, &o, &err));
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, err.status);
    TEST_ASSERT_NOT_NULL(strstr(err.text, "cannot open"));
    TEST_ASSERT_EQUAL_INT(0, strncmp(err.text, path, strlen(path)));
    /* a folder given as CSV */
    TEST_ASSERT_NULL(gs_kpread_open(g_dir, &o, &err));
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, err.status);
}

/* ---- CSV: valid files --------------------------------------------------- */

void test_csv_point_with_size_crlf_and_missing(void)
{
    char path[256];
    /* CRLF, spaces around fields, a missing point with empty x,y,size, a dropped
     * frame (0.3 absent), a complete last line without newline */
    write_file("pt.csv",
               "t,x,y,c,size\r\n0.0,10.5,20.25,0.9,44\r\n0.1, -3 ,4e2,1,45.5\r\n0.2,,,0,\r\n"
               "0.4,7,8,0.5,46",
               path);
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    gs_kpframe fr[8];
    size_t n;
    gs_kpread_error err;
    gs_layout lay;
    TEST_ASSERT_EQUAL_INT_MESSAGE(GS_KPR_EOF, read_all(path, &o, fr, 8, &n, &err, &lay), err.text);
    TEST_ASSERT_EQUAL_INT(GS_LAYOUT_POINT, lay);
    TEST_ASSERT_EQUAL_UINT64(4, n);
    const double t[4] = {0.0, 0.1, 0.2, 0.4};
    const float x[4] = {10.5f, -3.0f, NAN, 7.0f}, y[4] = {20.25f, 400.0f, NAN, 8.0f};
    const float c[4] = {0.9f, 1.0f, 0.0f, 0.5f}, s[4] = {44.0f, 45.5f, NAN, 46.0f};
    for (int i = 0; i < 4; i++) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, t[i], fr[i].t_s);
        TEST_ASSERT_EQUAL_UINT64(i, fr[i].frame);
        if (isnan(x[i])) {
            TEST_ASSERT_TRUE(isnan(fr[i].kp[0].x_px) && isnan(fr[i].kp[0].y_px));
            TEST_ASSERT_TRUE(isnan(fr[i].size_px));
        } else {
            TEST_ASSERT_EQUAL_FLOAT(x[i], fr[i].kp[0].x_px);
            TEST_ASSERT_EQUAL_FLOAT(y[i], fr[i].kp[0].y_px);
            TEST_ASSERT_EQUAL_FLOAT(s[i], fr[i].size_px);
        }
        TEST_ASSERT_EQUAL_FLOAT(c[i], fr[i].kp[0].c);
    }
}

/* A file of npts keypoints per row: x_k = 10*row + k + 0.25, y_k = 1000 - row - k/4,
 * c_k = (k%3+7)/10; keypoint (row%npts) missing with empty x,y. */
static void layout_file(int npts, int rows, bool trailing_blank, char *path)
{
    size_t cap = (size_t)rows * (size_t)npts * 40 + 4096;
    char *text = malloc(cap);
    TEST_ASSERT_NOT_NULL(text);
    coco_header(text, cap, npts, false);
    size_t n = strlen(text);
    for (int r = 0; r < rows; r++) {
        n += (size_t)snprintf(text + n, cap - n, "%.6f", r / 30.0);
        for (int k = 0; k < npts; k++) {
            if (k == r % npts)
                n += (size_t)snprintf(text + n, cap - n, ",,,0");
            else
                n += (size_t)snprintf(text + n, cap - n, ",%.2f,%.2f,%.1f", 10.0 * r + k + 0.25,
                                      1000.0 - r - k / 4.0, (k % 3 + 7) / 10.0);
        }
        n += (size_t)snprintf(text + n, cap - n, "\n");
    }
    if (trailing_blank)
        n += (size_t)snprintf(text + n, cap - n, "\n\r\n");
    write_file_n(npts == 17 ? "coco.csv" : "blaze.csv", text, n, path);
    free(text);
}

static void check_layout_frames(const gs_kpframe *fr, size_t n, int npts)
{
    for (size_t r = 0; r < n; r++) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, r / 30.0, fr[r].t_s);
        for (int k = 0; k < npts; k++) {
            const gs_kp *kp = &fr[r].kp[k];
            if (k == (int)(r % (size_t)npts)) {
                TEST_ASSERT_EQUAL_FLOAT(0.0f, kp->c);
                TEST_ASSERT_TRUE(isnan(kp->x_px) && isnan(kp->y_px));
            } else {
                TEST_ASSERT_FLOAT_WITHIN(1e-3f, (float)(10.0 * r + k + 0.25), kp->x_px);
                TEST_ASSERT_FLOAT_WITHIN(1e-3f, (float)(1000.0 - r - k / 4.0), kp->y_px);
                TEST_ASSERT_FLOAT_WITHIN(1e-6f, (float)((k % 3 + 7) / 10.0), kp->c);
            }
        }
    }
}

void test_csv_coco17_and_blazepose33(void)
{
    const int layouts[2] = {17, 33};
    for (int li = 0; li < 2; li++) {
        int npts = layouts[li];
        char path[256];
        layout_file(npts, 40, true, path);
        gs_kpread_opts o;
        gs_kpread_opts_default(&o);
        o.layout_set = true; /* the header agrees with --layout */
        o.layout = npts == 17 ? GS_LAYOUT_COCO17 : GS_LAYOUT_BLAZEPOSE33;
        static gs_kpframe fr[40];
        size_t n;
        gs_kpread_error err;
        gs_layout lay;
        TEST_ASSERT_EQUAL_INT_MESSAGE(GS_KPR_EOF, read_all(path, &o, fr, 40, &n, &err, &lay),
                                      err.text);
        TEST_ASSERT_EQUAL_INT(o.layout, lay);
        TEST_ASSERT_EQUAL_UINT64(40, n);
        check_layout_frames(fr, n, npts);
    }
}

/* The bundled sample in its own column order (t, x0, y0, c0, x1, ...: the reader's
 * fixed-order pass) and with the keypoints' columns in other orders (the pass that
 * looks up each column's role): the same frames, bit for bit. */
#ifndef GS_SOURCE_DIR
#define GS_SOURCE_DIR "."
#endif
#define SAMPLE_ROWS 400
#define SAMPLE_COLS (1 + 3 * 17)

static bool same_float_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

void test_csv_column_orders_agree(void)
{
    static char cell[SAMPLE_ROWS + 1][SAMPLE_COLS][24];
    FILE *f = fopen(GS_SOURCE_DIR "/tests/data/sample_jumps.csv", "r");
    TEST_ASSERT_NOT_NULL(f);
    char line[2048];
    int rows = 0;
    while (rows <= SAMPLE_ROWS && fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        int c = 0;
        for (char *tok = line;; c++) { /* empty fields (a missing keypoint) included */
            size_t l = strcspn(tok, ",");
            TEST_ASSERT_TRUE(c < SAMPLE_COLS && l < sizeof cell[0][0]);
            memcpy(cell[rows][c], tok, l);
            cell[rows][c][l] = '\0';
            if (tok[l] == '\0')
                break;
            tok += l + 1;
        }
        TEST_ASSERT_EQUAL_INT(SAMPLE_COLS, c + 1);
        rows++;
    }
    fclose(f);
    TEST_ASSERT_TRUE(rows > 300);
    /* column c of each order: 0 is t; 3k+1..3k+3 are x_k, y_k, c_k in the file */
    static int order[3][SAMPLE_COLS];
    for (int c = 0; c < SAMPLE_COLS; c++) order[0][c] = c;                            /* as written */
    for (int k = 0; k < 17; k++)
        for (int j = 0; j < 3; j++) {
            order[1][1 + 3 * k + j] = 1 + 3 * (16 - k) + j;                           /* keypoints reversed */
            order[2][1 + 3 * k + j] = 1 + 3 * k + (j + 2) % 3;                        /* c_k, x_k, y_k */
        }
    order[1][0] = order[2][0] = 0;
    static gs_kpframe fr[3][SAMPLE_ROWS];
    size_t n[3];
    for (int v = 0; v < 3; v++) {
        static char text[SAMPLE_ROWS * 2048];
        size_t len = 0;
        for (int r = 0; r < rows; r++)
            for (int c = 0; c < SAMPLE_COLS; c++)
                len += (size_t)snprintf(text + len, sizeof text - len, "%s%c", cell[r][order[v][c]],
                                        c + 1 < SAMPLE_COLS ? ',' : '\n');
        char path[256];
        write_file_n("order.csv", text, len, path);
        gs_kpread_opts o;
        gs_kpread_opts_default(&o);
        gs_kpread_error err;
        gs_layout lay;
        TEST_ASSERT_EQUAL_INT_MESSAGE(GS_KPR_EOF, read_all(path, &o, fr[v], SAMPLE_ROWS, &n[v], &err, &lay), err.text);
        TEST_ASSERT_EQUAL_INT(GS_LAYOUT_COCO17, lay);
        TEST_ASSERT_EQUAL_UINT64((uint64_t)(rows - 1), (uint64_t)n[v]);
    }
    for (int v = 1; v < 3; v++)
        for (size_t i = 0; i < n[0]; i++) {
            const gs_kpframe *a = &fr[0][i], *b = &fr[v][i];
            char msg[64];
            snprintf(msg, sizeof msg, "order %d, frame %u", v, (unsigned)i);
            TEST_ASSERT_EQUAL_HEX64_MESSAGE(0, memcmp(&a->t_s, &b->t_s, sizeof a->t_s), msg);
            TEST_ASSERT_EQUAL_UINT64_MESSAGE(a->frame, b->frame, msg);
            TEST_ASSERT_TRUE_MESSAGE(isnan(a->size_px) && isnan(b->size_px), msg);
            for (int k = 0; k < 17; k++)
                TEST_ASSERT_TRUE_MESSAGE(same_float_bits(a->kp[k].x_px, b->kp[k].x_px) &&
                                             same_float_bits(a->kp[k].y_px, b->kp[k].y_px) &&
                                             same_float_bits(a->kp[k].c, b->kp[k].c),
                                         msg);
        }
    /* and the values are the file's: every confidence against strtod */
    for (int r = 1; r < rows; r++)
        for (int k = 0; k < 17; k++)
            TEST_ASSERT_TRUE(same_float_bits((float)strtod(cell[r][3 + 3 * k], NULL), fr[0][r - 1].kp[k].c));
}

void test_csv_frame_column_with_fps(void)
{
    char path[256];
    write_file("frame.csv", "frame,x,y,c\n0,1,2,0.9\n1,1,2,0.9\n5,1,2,0.9\n", path);
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    o.fps = 25.0;
    gs_kpframe fr[4];
    size_t n;
    gs_kpread_error err;
    gs_kpread *r = gs_kpread_open(path, &o, &err);
    TEST_ASSERT_NOT_NULL_MESSAGE(r, err.text);
    TEST_ASSERT_EQUAL_STRING("cli", gs_kpread_fps_origin(r));
    gs_kpread_close(r);
    TEST_ASSERT_EQUAL_INT(GS_KPR_EOF, read_all(path, &o, fr, 4, &n, &err, NULL));
    TEST_ASSERT_EQUAL_UINT64(3, n);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, fr[0].t_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.04, fr[1].t_s);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.2, fr[2].t_s);
    TEST_ASSERT_EQUAL_UINT64(5, fr[2].frame);
}

/* Rows that straddle the 1 MiB read block: every value must survive the refill. */
void test_csv_across_read_blocks(void)
{
    char path[256];
    int rows = 6000; /* ~ 3 MiB of COCO-17 rows */
    layout_file(17, rows, false, path);
    struct stat sb;
    TEST_ASSERT_EQUAL_INT(0, stat(path, &sb));
    TEST_ASSERT_TRUE(sb.st_size > 2 * (1 << 20));
    gs_kpframe *fr = malloc((size_t)rows * sizeof *fr);
    TEST_ASSERT_NOT_NULL(fr);
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    size_t n;
    gs_kpread_error err;
    TEST_ASSERT_EQUAL_INT_MESSAGE(GS_KPR_EOF, read_all(path, &o, fr, (size_t)rows, &n, &err, NULL),
                                  err.text);
    TEST_ASSERT_EQUAL_UINT64((size_t)rows, n);
    check_layout_frames(fr, n, 17);
    free(fr);
}

void test_csv_line_longer_than_block(void)
{
    char path[256];
    size_t len = (1u << 20) + 100;
    char *text = malloc(len + 64);
    TEST_ASSERT_NOT_NULL(text);
    if (!text)
        return; /* unreachable (the assert jumps out); tells gcc -O2 + ASan it is not NULL */
    int h = snprintf(text, 64, "t,x,y,c\n0,");
    memset(text + h, '1', len);
    memcpy(text + h + len, ",2,0.9\n", 7);
    write_file_n("long.csv", text, (size_t)h + len + 7, path);
    free(text);
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    gs_kpframe fr[1];
    size_t n;
    gs_kpread_error err;
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, read_all(path, &o, fr, 1, &n, &err, NULL));
    TEST_ASSERT_EQUAL_UINT32(2, err.line);
    TEST_ASSERT_NOT_NULL(strstr(err.text, "line longer"));
}

/* ---- AlphaPose ---------------------------------------------------------- */

/* One AlphaPose result: person `who` (A: big at x~500, B: small at x~1500),
 * keypoint k at (base + 3k, 300 + 20k), score 0.8. */
static int ap_person(char *buf, size_t cap, int frame, char who, bool with_idx, float dx)
{
    float base = who == 'A' ? 500.0f + dx : 1500.0f + dx;
    float scale = who == 'A' ? 20.0f : 5.0f;
    int n = snprintf(buf, cap, "{\"image_id\": \"%06d.jpg\", \"category_id\": 1,\n \"keypoints\": [",
                     frame);
    for (int k = 0; k < 17; k++)
        n += snprintf(buf + n, cap - (size_t)n, "%s%.2f, %.2f, 0.8", k ? ", " : "",
                      base + 3.0f * k, 300.0f + scale * k);
    n += snprintf(buf + n, cap - (size_t)n, "],\n \"score\": 2.5, \"box\": [1, 2, 3, 4]");
    if (with_idx)
        n += snprintf(buf + n, cap - (size_t)n, ", \"idx\": %s", who == 'A' ? "[3.0]" : "7");
    n += snprintf(buf + n, cap - (size_t)n, "}");
    return n;
}

/* frames 3,0,2,1,4 in that order; B listed first; frame 4 only has B;
 * frame 6 only has A (after a gap). */
static void ap_file(bool with_idx, char *path)
{
    static char text[65536];
    int n = snprintf(text, sizeof text, "[");
    const int order[5] = {3, 0, 2, 1, 4};
    bool first = true;
    for (int i = 0; i < 5; i++) {
        int f = order[i];
        n += snprintf(text + n, sizeof text - (size_t)n, "%s", first ? "" : ",\n");
        n += ap_person(text + n, sizeof text - (size_t)n, f, 'B', with_idx, (float)f);
        first = false;
        if (f != 4) {
            n += snprintf(text + n, sizeof text - (size_t)n, ",\n");
            n += ap_person(text + n, sizeof text - (size_t)n, f, 'A', with_idx, 2.0f * f);
        }
    }
    n += snprintf(text + n, sizeof text - (size_t)n, ",\n");
    n += ap_person(text + n, sizeof text - (size_t)n, 6, 'A', with_idx, 12.0f);
    snprintf(text + n, sizeof text - (size_t)n, "]\n");
    write_file(with_idx ? "ap_idx.json" : "ap_noidx.json", text, path);
}

void test_alphapose_two_people_out_of_order(void)
{
    for (int with_idx = 0; with_idx < 2; with_idx++) {
        char path[256];
        ap_file(with_idx != 0, path);
        gs_kpread_opts o;
        gs_kpread_opts_default(&o);
        o.format = GS_KPF_ALPHAPOSE;
        o.fps = 30.0;
        gs_kpframe fr[8];
        size_t n;
        gs_kpread_error err;
        gs_layout lay;
        TEST_ASSERT_EQUAL_INT_MESSAGE(GS_KPR_EOF, read_all(path, &o, fr, 8, &n, &err, &lay),
                                      err.text);
        TEST_ASSERT_EQUAL_INT(GS_LAYOUT_COCO17, lay);
        /* A is followed: frames 0,1,2,3 and 6; frame 4 (B only) is absent */
        const int want[5] = {0, 1, 2, 3, 6};
        TEST_ASSERT_EQUAL_UINT64(5, n);
        for (int i = 0; i < 5; i++) {
            TEST_ASSERT_EQUAL_UINT64(want[i], fr[i].frame);
            TEST_ASSERT_DOUBLE_WITHIN(1e-12, want[i] / 30.0, fr[i].t_s);
            for (int k = 0; k < 17; k++) {
                TEST_ASSERT_FLOAT_WITHIN(1e-3f, 500.0f + 2.0f * want[i] + 3.0f * k, fr[i].kp[k].x_px);
                TEST_ASSERT_FLOAT_WITHIN(1e-3f, 300.0f + 20.0f * k, fr[i].kp[k].y_px);
                TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.8f, fr[i].kp[k].c);
            }
        }
    }
    /* --track 7 follows B: frames 0..4 */
    char path[256];
    ap_file(true, path);
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    o.format = GS_KPF_ALPHAPOSE;
    o.fps = 30.0;
    o.track = 7;
    gs_kpframe fr[8];
    size_t n;
    gs_kpread_error err;
    TEST_ASSERT_EQUAL_INT_MESSAGE(GS_KPR_EOF, read_all(path, &o, fr, 8, &n, &err, NULL), err.text);
    TEST_ASSERT_EQUAL_UINT64(5, n);
    for (int i = 0; i < 5; i++) {
        TEST_ASSERT_EQUAL_UINT64(i, fr[i].frame);
        TEST_ASSERT_FLOAT_WITHIN(1e-3f, 1500.0f + i, fr[i].kp[0].x_px);
        TEST_ASSERT_FLOAT_WITHIN(1e-3f, 300.0f + 5.0f * 16, fr[i].kp[16].y_px);
    }
    /* an empty result list: no frames, no error */
    char empty[256];
    write_file("empty_list.json", "[ ]\n", empty);
    o.track = -1;
    TEST_ASSERT_EQUAL_INT(GS_KPR_EOF, read_all(empty, &o, fr, 8, &n, &err, NULL));
    TEST_ASSERT_EQUAL_UINT64(0, n);
    /* a track id nobody has */
    o.track = 99;
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, read_all(path, &o, fr, 8, &n, &err, NULL));
    TEST_ASSERT_NOT_NULL(strstr(err.text, "track id 99"));
}

typedef struct {
    const char *name;
    const char *text;
    double fps;
    gs_kpr_status status;
    uint32_t line;
    const char *field;
    const char *msg;
} json_bad;

static const json_bad k_ap_bad[] = {
    {"invalid JSON", "[\n{\"image_id\": \"0.jpg\",\n \"keypoints\": [1, 2,, 3]}]\n", 30, GS_KPR_EDATA,
     3, "", "invalid JSON"},
    {"truncated", "[\n{\"image_id\": \"0.jpg\", \"keypoints\": [1, 2", 30, GS_KPR_EDATA, 2, "",
     "invalid JSON: unexpected end of file"},
    {"wrong count", "[\n{\"image_id\": \"0.jpg\", \"keypoints\": [1, 2, 3]},\n\n  {\"image_id\": "
                    "\"1.jpg\", \"keypoints\": [1, 2, 3, 4]}]",
     30, GS_KPR_EDATA, 2, "keypoints", "3 numbers, expected 51"},
    {"not a number", "[{\"image_id\": \"0.jpg\",\n \"keypoints\": [1, \"x\", 3]}]", 30, GS_KPR_EDATA, 1,
     "keypoints", "element 1 is not a number"},
    {"float overflow", "[{\"image_id\": \"0.jpg\",\n \"keypoints\": [1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5,"
                       " 1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5, 1,2,0.5,"
                       " 1,-1e39,0.5, 1,2,0.5]}]",
     30, GS_KPR_EDATA, 1, "keypoints", "element 46 (-1e+39) is beyond the float range"},
    {"no image_id", "[\n\n{\"score\": 1.5, \"idx\": null}]", 30, GS_KPR_EDATA, 3, "image_id", "missing"},
    {"no digits", "[{\"image_id\": \"a.jpg\", \"keypoints\": []}]", 30, GS_KPR_EDATA, 1, "image_id",
     "no frame number"},
    {"not a list", "{\"image_id\": \"0.jpg\"}", 30, GS_KPR_EDATA, 1, "", "expected a JSON array"},
    {"empty file", "", 30, GS_KPR_EDATA, 1, "", "empty file"},
    {"trailing garbage", "[]\nx", 30, GS_KPR_EDATA, 2, "", "invalid JSON"},
    {"no fps", "[]", NAN, GS_KPR_EUSAGE, 0, "", "--fps is required"},
};

void test_alphapose_bad_inputs(void)
{
    for (size_t i = 0; i < sizeof k_ap_bad / sizeof k_ap_bad[0]; i++) {
        const json_bad *c = &k_ap_bad[i];
        char path[256];
        write_file("bad.json", c->text, path);
        gs_kpread_opts o;
        gs_kpread_opts_default(&o);
        o.format = GS_KPF_ALPHAPOSE;
        o.fps = c->fps;
        gs_kpframe fr[2];
        size_t n;
        gs_kpread_error err;
        gs_kpr_status st = read_all(path, &o, fr, 2, &n, &err, NULL);
        char ctx[1024];
        snprintf(ctx, sizeof ctx, "case '%s': %s", c->name, err.text);
        TEST_ASSERT_EQUAL_INT_MESSAGE(c->status, st, ctx);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(c->line, err.line, ctx);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(c->field, err.field, ctx);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err.text, c->msg), ctx);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(err.text, path, strlen(path)), ctx);
    }
}

/* ---- OpenPose ----------------------------------------------------------- */

static const char *const k_coco17_names[17] = {
    "nose", "leye", "reye", "lear", "rear", "lsho", "rsho", "lelb", "relb",
    "lwri", "rwri", "lhip", "rhip", "lknee", "rknee", "lank", "rank"};
static const char *const k_body25_names[25] = {
    "nose", "neck", "rsho", "relb", "rwri", "lsho", "lelb", "lwri", "midhip",
    "rhip", "rknee", "rank", "lhip", "lknee", "lank", "reye", "leye", "rear",
    "lear", "lbigtoe", "lsmalltoe", "lheel", "rbigtoe", "rsmalltoe", "rheel"};
static const char *const k_coco18_names[18] = {
    "nose", "neck", "rsho", "relb", "rwri", "lsho", "lelb", "lwri", "rhip",
    "rknee", "rank", "lhip", "lknee", "lank", "reye", "leye", "rear", "lear"};

static int name_index(const char *const *names, int n, const char *want)
{
    for (int i = 0; i < n; i++)
        if (strcmp(names[i], want) == 0)
            return i;
    return -1;
}

/* Source keypoint j of person p: (100 + j + 1000 p + frame, 50 + 2 j, 0.05 + j / 40);
 * source keypoint `missing` is 0,0,0. */
static void op_write(const char *dir, const char *name, int frame, int npts, int npeople,
                     int missing)
{
    char path[512], text[16384];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    int n = snprintf(text, sizeof text, "{\"version\":1.3,\"people\":[");
    for (int p = 0; p < npeople; p++) {
        n += snprintf(text + n, sizeof text - (size_t)n,
                      "%s\n{\"person_id\":[-1],\"pose_keypoints_2d\":[", p ? "," : "");
        for (int j = 0; j < npts; j++) {
            if (j == missing)
                n += snprintf(text + n, sizeof text - (size_t)n, "%s0,0,0", j ? "," : "");
            else
                n += snprintf(text + n, sizeof text - (size_t)n, "%s%d,%d,%.4f", j ? "," : "",
                              100 + j + 1000 * p + frame, 50 + 2 * j, 0.05 + j / 40.0);
        }
        n += snprintf(text + n, sizeof text - (size_t)n,
                      "],\"face_keypoints_2d\":[],\"hand_left_keypoints_2d\":[]}");
    }
    snprintf(text + n, sizeof text - (size_t)n, "]}\n");
    FILE *f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    fputs(text, f);
    fclose(f);
}

static void op_check_mapping(int npts)
{
    const char *const *src_names = npts == 25 ? k_body25_names : k_coco18_names;
    char dir[256];
    snprintf(dir, sizeof dir, "%s/op%d_%03d", g_dir, npts, g_seq++);
    TEST_ASSERT_EQUAL_INT(0, mkdir(dir, 0755));
    /* written out of order; the frame index is the last digit run of the name */
    op_write(dir, "cam2_000000000012_keypoints.json", 12, npts, 1, -1);
    op_write(dir, "cam2_000000000010_keypoints.json", 10, npts, 1, 16); /* leye missing */
    op_write(dir, "cam2_000000000011_keypoints.json", 11, npts, 2, -1); /* person 1 is far */
    char junk_path[300];
    snprintf(junk_path, sizeof junk_path, "%s/notes.txt", dir); /* not a keypoint file: ignored */
    FILE *junk = fopen(junk_path, "w");
    TEST_ASSERT_NOT_NULL(junk);
    fclose(junk);

    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    o.format = GS_KPF_OPENPOSE;
    o.fps = 10.0;
    gs_kpframe fr[4];
    size_t n;
    gs_kpread_error err;
    TEST_ASSERT_EQUAL_INT_MESSAGE(GS_KPR_EOF, read_all(dir, &o, fr, 4, &n, &err, NULL), err.text);
    TEST_ASSERT_EQUAL_UINT64(3, n);
    for (int i = 0; i < 3; i++) {
        int frame = 10 + i;
        TEST_ASSERT_EQUAL_UINT64(frame, fr[i].frame);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, frame / 10.0, fr[i].t_s);
        for (int k = 0; k < 17; k++) {
            int j = name_index(src_names, npts == 25 ? 25 : 18, k_coco17_names[k]);
            TEST_ASSERT_TRUE(j >= 0);
            const gs_kp *kp = &fr[i].kp[k];
            char ctx[96];
            snprintf(ctx, sizeof ctx, "%s from %d points, frame %d", k_coco17_names[k], npts, frame);
            if (frame == 10 && j == 16) {
                TEST_ASSERT_EQUAL_FLOAT_MESSAGE(0.0f, kp->c, ctx);
                TEST_ASSERT_TRUE_MESSAGE(isnan(kp->x_px) && isnan(kp->y_px), ctx);
                continue;
            }
            TEST_ASSERT_FLOAT_WITHIN_MESSAGE(1e-3f, (float)(100 + j + frame), kp->x_px, ctx);
            TEST_ASSERT_FLOAT_WITHIN_MESSAGE(1e-3f, (float)(50 + 2 * j), kp->y_px, ctx);
            TEST_ASSERT_FLOAT_WITHIN_MESSAGE(1e-4f, (float)(0.05 + j / 40.0), kp->c, ctx);
        }
    }
}

void test_openpose_body25_mapping(void) { op_check_mapping(25); }
void test_openpose_coco18_mapping(void) { op_check_mapping(18); }

void test_openpose_bad_inputs(void)
{
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    o.format = GS_KPF_OPENPOSE;
    o.fps = 30.0;
    gs_kpframe fr[4];
    size_t n;
    gs_kpread_error err;
    char dir[256];

    /* a missing folder */
    snprintf(dir, sizeof dir, "%s/no_such_folder", g_dir);
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, read_all(dir, &o, fr, 4, &n, &err, NULL));
    TEST_ASSERT_NOT_NULL(strstr(err.text, "cannot open"));

    /* a folder without keypoint files */
    snprintf(dir, sizeof dir, "%s/op_empty_%03d", g_dir, g_seq++);
    TEST_ASSERT_EQUAL_INT(0, mkdir(dir, 0755));
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, read_all(dir, &o, fr, 4, &n, &err, NULL));
    TEST_ASSERT_NOT_NULL(strstr(err.text, "no *_keypoints.json"));

    /* wrong keypoint count in the second person of a file: its line */
    snprintf(dir, sizeof dir, "%s/op_count_%03d", g_dir, g_seq++);
    TEST_ASSERT_EQUAL_INT(0, mkdir(dir, 0755));
    op_write(dir, "v_0_keypoints.json", 0, 25, 1, -1);
    char path[512];
    snprintf(path, sizeof path, "%s/v_1_keypoints.json", dir);
    FILE *f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    fputs("{\"people\":[\n{\"pose_keypoints_2d\":[1,2,3]}\n]}\n", f);
    fclose(f);
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, read_all(dir, &o, fr, 4, &n, &err, NULL));
    char want[600];
    snprintf(want, sizeof want,
             "%s:2: field 'pose_keypoints_2d': 3 numbers, expected 75 (BODY_25) or 54 (COCO-18)",
             path);
    TEST_ASSERT_EQUAL_STRING(want, err.text);

    /* invalid JSON */
    f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    fputs("{\"people\":[\n\n{\"pose_keypoints_2d\":[1,2,3}\n]}\n", f);
    fclose(f);
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, read_all(dir, &o, fr, 4, &n, &err, NULL));
    TEST_ASSERT_EQUAL_UINT32(3, err.line);
    TEST_ASSERT_NOT_NULL(strstr(err.text, "invalid JSON"));

    /* a coordinate finite as double but inf as float (BODY_25 keypoint 7, the left wrist) */
    f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    fputs("{\"people\":[\n{\"pose_keypoints_2d\":[", f);
    for (int k = 0; k < 25; k++)
        fprintf(f, "%s%s,20,0.5", k ? "," : "", k == 7 ? "4e38" : "10");
    fputs("]}\n]}\n", f);
    fclose(f);
    TEST_ASSERT_EQUAL_INT(GS_KPR_EDATA, read_all(dir, &o, fr, 4, &n, &err, NULL));
    TEST_ASSERT_EQUAL_UINT32(2, err.line);
    TEST_ASSERT_EQUAL_STRING("pose_keypoints_2d", err.field);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err.text, "keypoint 7 (4e+38, 20) is beyond the float range"), err.text);
}

/* ---- the JSON tokenizer ------------------------------------------------- */

static bool json_valid(const char *s)
{
    gs_jlex l;
    gs_jtok t;
    gs_jlex_init(&l, s, strlen(s));
    for (;;) {
        gs_jt k = gs_jlex_next(&l, &t);
        if (k == GS_JT_EOF)
            return true;
        if (k == GS_JT_ERROR)
            return false;
    }
}

void test_json_tokenizer_table(void)
{
    static const struct {
        const char *text;
        bool ok;
    } cases[] = {
        {"{}", true}, {"[]", true}, {" [1, -2.5e+3, 0, true, false, null, \"a\\u00e9\\n\"] ", true},
        {"{\"a\": {\"b\": [[], {}]}}", true}, {"3", true}, {"\"x\"", true},
        {"", false}, {"[", false}, {"[1,]", false}, {"{\"a\" 1}", false}, {"{\"a\":}", false},
        {"{1: 2}", false}, {"[01]", false}, {"[1.]", false}, {"[.5]", false}, {"[-]", false},
        {"[1e]", false}, {"[tru]", false}, {"[nulll]", false}, {"[\"a\\x\"]", false},
        {"[\"a\\u12\"]", false}, {"[\"tab\there\"]", false}, {"[1] [2]", false}, {"[1}", false},
        {"{\"a\":1]", false}, {"[\"unterminated]", false}, {"{,}", false}, {"[1 2]", false},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        TEST_ASSERT_EQUAL_INT_MESSAGE(cases[i].ok, json_valid(cases[i].text), cases[i].text);

    /* token stream, skip and line numbers */
    const char *doc = "{\"skip\": {\"x\": [1, {\"y\": 2}]},\n \"k\": [10, 20.5],\n \"s\": \"v\"}";
    gs_jlex l;
    gs_jtok t;
    gs_jlex_init(&l, doc, strlen(doc));
    TEST_ASSERT_EQUAL_INT(GS_JT_OBJ, gs_jlex_next(&l, &t));
    TEST_ASSERT_EQUAL_INT(GS_JT_KEY, gs_jlex_next(&l, &t));
    TEST_ASSERT_TRUE(gs_jtok_eq(&t, "skip"));
    TEST_ASSERT_EQUAL_INT(GS_JT_OBJ, gs_jlex_next(&l, &t));
    TEST_ASSERT_TRUE(gs_jlex_skip(&l, &t));
    TEST_ASSERT_EQUAL_INT(GS_JT_KEY, gs_jlex_next(&l, &t));
    TEST_ASSERT_TRUE(gs_jtok_eq(&t, "k"));
    TEST_ASSERT_EQUAL_UINT32(2, t.line);
    TEST_ASSERT_EQUAL_INT(GS_JT_ARR, gs_jlex_next(&l, &t));
    double d;
    TEST_ASSERT_EQUAL_INT(GS_JT_NUM, gs_jlex_next(&l, &t));
    TEST_ASSERT_TRUE(gs_jtok_num(&t, &d));
    TEST_ASSERT_EQUAL_DOUBLE(10.0, d);
    TEST_ASSERT_EQUAL_INT(GS_JT_NUM, gs_jlex_next(&l, &t));
    TEST_ASSERT_TRUE(gs_jtok_num(&t, &d));
    TEST_ASSERT_EQUAL_DOUBLE(20.5, d);
    TEST_ASSERT_EQUAL_INT(GS_JT_ARR_END, gs_jlex_next(&l, &t));
    TEST_ASSERT_EQUAL_INT(GS_JT_KEY, gs_jlex_next(&l, &t));
    TEST_ASSERT_EQUAL_INT(GS_JT_STR, gs_jlex_next(&l, &t));
    TEST_ASSERT_TRUE(gs_jtok_eq(&t, "v"));
    TEST_ASSERT_EQUAL_UINT32(3, t.line);
    TEST_ASSERT_EQUAL_INT(GS_JT_OBJ_END, gs_jlex_next(&l, &t));
    TEST_ASSERT_EQUAL_INT(GS_JT_EOF, gs_jlex_next(&l, &t));

    /* nesting limit */
    char deep[GS_JSON_MAX_DEPTH + 3];
    memset(deep, '[', sizeof deep - 1);
    deep[sizeof deep - 1] = '\0';
    TEST_ASSERT_FALSE(json_valid(deep));
}

/* ---- runner --------------------------------------------------------------- */

static void rm_tree(const char *dir)
{
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/gs_test_kpread_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    UNITY_BEGIN();
    RUN_TEST(test_csv_bad_inputs);
    RUN_TEST(test_csv_exact_message);
    RUN_TEST(test_csv_missing_file);
    RUN_TEST(test_csv_point_with_size_crlf_and_missing);
    RUN_TEST(test_csv_coco17_and_blazepose33);
    RUN_TEST(test_csv_column_orders_agree);
    RUN_TEST(test_csv_frame_column_with_fps);
    RUN_TEST(test_csv_across_read_blocks);
    RUN_TEST(test_csv_line_longer_than_block);
    RUN_TEST(test_alphapose_two_people_out_of_order);
    RUN_TEST(test_alphapose_bad_inputs);
    RUN_TEST(test_openpose_body25_mapping);
    RUN_TEST(test_openpose_coco18_mapping);
    RUN_TEST(test_openpose_bad_inputs);
    RUN_TEST(test_json_tokenizer_table);
    int fails = UNITY_END();
    rm_tree(g_dir);
    return fails;
}
