/* gs_kp_alphapose.c - AlphaPose result lists: a JSON array of person objects
 * ("image_id", "keypoints" = 17 x (x, y, score), "score", optional "idx"),
 * held in memory because frames may come in any order. Also the JSON helpers
 * the OpenPose reader shares. */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gs_kpread.h"

char *gs_kp_slurp(const char *path, size_t *len, gs_kpread_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "cannot open: %s", strerror(errno));
        return NULL;
    }
    struct stat sb;
    if (fstat(fileno(f), &sb) == 0 && S_ISDIR(sb.st_mode)) {
        fclose(f);
        gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "is a folder, not a JSON file");
        return NULL;
    }
    size_t cap = 1u << 16, n = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n < cap) {
            if (ferror(f)) {
                gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "read error: %s",
                               strerror(errno));
                free(buf);
                fclose(f);
                return NULL;
            }
            break;
        }
        cap *= 2;
        char *nb = realloc(buf, cap + 1);
        if (!nb)
            free(buf);
        buf = nb;
    }
    fclose(f);
    if (!buf) {
        gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "out of memory");
        return NULL;
    }
    buf[n] = '\0';
    *len = n;
    return buf;
}

void gs_kp_json_syntax(const gs_jlex *lex, const char *path, gs_kpread_error *err)
{
    gs_kpread_fail(err, GS_KPR_EDATA, path, lex->err_line ? lex->err_line : 1, NULL,
                   "invalid JSON: %s", lex->err);
}

bool gs_kp_json_begin(gs_jlex *lex, const char *text, size_t len, const char *path, gs_jt want,
                      const char *what, gs_jtok *first, gs_kpread_error *err)
{
    gs_jlex_init(lex, text, len);
    gs_jt k = gs_jlex_next(lex, first);
    if (k == GS_JT_ERROR) {
        if (len == 0)
            gs_kpread_fail(err, GS_KPR_EDATA, path, 1, NULL, "empty file");
        else
            gs_kp_json_syntax(lex, path, err);
        return false;
    }
    if (k != want) {
        gs_kpread_fail(err, GS_KPR_EDATA, path, first->line, NULL, "%s", what);
        return false;
    }
    return true;
}

bool gs_kp_json_numbers(gs_jlex *lex, const gs_jtok *v, const char *path, uint32_t obj_line,
                        const char *key, double *out, size_t cap, size_t *n, gs_kpread_error *err)
{
    if (v->type == GS_JT_ERROR) {
        gs_kp_json_syntax(lex, path, err);
        return false;
    }
    if (v->type != GS_JT_ARR) {
        gs_kpread_fail(err, GS_KPR_EDATA, path, obj_line, key, "not an array of numbers");
        return false;
    }
    size_t i = 0;
    gs_jtok t;
    for (;;) {
        gs_jt k = gs_jlex_next(lex, &t);
        if (k == GS_JT_ARR_END)
            break;
        if (k == GS_JT_ERROR) {
            gs_kp_json_syntax(lex, path, err);
            return false;
        }
        double d;
        if (k != GS_JT_NUM || !gs_jtok_num(&t, &d) || !isfinite(d)) {
            gs_kpread_fail(err, GS_KPR_EDATA, path, obj_line, key,
                           "element %zu is not a number ('%.*s')", i,
                           (int)(t.len > 40 ? 40 : t.len), t.s);
            return false;
        }
        if (i < cap)
            out[i] = d;
        i++;
    }
    *n = i;
    return true;
}

bool gs_kp_json_track(gs_jlex *lex, const gs_jtok *v, const char *path, uint32_t obj_line,
                      const char *key, long *track, gs_kpread_error *err)
{
    double d = -1.0;
    if (v->type == GS_JT_NUM) {
        if (!gs_jtok_num(v, &d))
            d = -1.0;
    } else if (v->type == GS_JT_ARR) {
        double vals[4];
        size_t n = 0;
        if (!gs_kp_json_numbers(lex, v, path, obj_line, key, vals, 4, &n, err))
            return false;
        if (n > 0)
            d = vals[0];
    } else if (v->type == GS_JT_NULL) {
        d = -1.0;
    } else if (v->type == GS_JT_ERROR) {
        gs_kp_json_syntax(lex, path, err);
        return false;
    } else {
        gs_kpread_fail(err, GS_KPR_EDATA, path, obj_line, key, "not a track id");
        return false;
    }
    if (d >= 0.0 && d <= 2e9 && d == floor(d))
        *track = (long)d;
    else
        *track = -1;
    return true;
}

/* Frame index from a file or image name: its last run of digits ("000123.jpg" -> 123). */
bool gs_kp_index_from_name(const char *s, size_t n, uint64_t *out)
{
    size_t e = n;
    while (e > 0 && !(s[e - 1] >= '0' && s[e - 1] <= '9'))
        e--;
    if (e == 0)
        return false;
    size_t b = e;
    while (b > 0 && s[b - 1] >= '0' && s[b - 1] <= '9')
        b--;
    if (e - b > 15)
        return false;
    uint64_t v = 0;
    for (size_t i = b; i < e; i++)
        v = v * 10 + (uint64_t)(s[i] - '0');
    *out = v;
    return true;
}

static bool parse_person(gs_jlex *lex, const gs_jtok *obj, const char *path, gs_kp_person *p,
                         gs_kpread_error *err)
{
    bool have_id = false, have_kp = false;
    gs_jtok t, v;
    p->track = -1;
    p->score = NAN;
    for (;;) {
        gs_jt k = gs_jlex_next(lex, &t);
        if (k == GS_JT_OBJ_END)
            break;
        if (k != GS_JT_KEY) {
            gs_kp_json_syntax(lex, path, err);
            return false;
        }
        if (gs_jlex_next(lex, &v) == GS_JT_ERROR) {
            gs_kp_json_syntax(lex, path, err);
            return false;
        }
        if (gs_jtok_eq(&t, "image_id")) {
            if (v.type == GS_JT_STR) {
                if (!gs_kp_index_from_name(v.s, v.len, &p->frame)) {
                    gs_kpread_fail(err, GS_KPR_EDATA, path, obj->line, "image_id",
                                   "no frame number in '%.*s'", (int)(v.len > 40 ? 40 : v.len),
                                   v.s);
                    return false;
                }
            } else {
                double d;
                if (v.type != GS_JT_NUM || !gs_jtok_num(&v, &d) || d < 0 || d != floor(d) ||
                    d > 1e15) {
                    gs_kpread_fail(err, GS_KPR_EDATA, path, obj->line, "image_id",
                                   "not an image name or frame number");
                    return false;
                }
                p->frame = (uint64_t)d;
            }
            have_id = true;
        } else if (gs_jtok_eq(&t, "keypoints")) {
            double vals[51];
            size_t n = 0;
            if (!gs_kp_json_numbers(lex, &v, path, obj->line, "keypoints", vals, 51, &n, err))
                return false;
            if (n != 51) {
                gs_kpread_fail(err, GS_KPR_EDATA, path, obj->line, "keypoints",
                               "%zu numbers, expected 51 (COCO-17 x, y, score)", n);
                return false;
            }
            for (int j = 0; j < 34; j++) {
                double xy = vals[3 * (j / 2) + j % 2];
                if (!(fabs(xy) <= FLT_MAX)) { /* kept as float: it would become inf */
                    gs_kpread_fail(err, GS_KPR_EDATA, path, obj->line, "keypoints",
                                   "element %d (%.6g) is beyond the float range of a pixel coordinate",
                                   3 * (j / 2) + j % 2, xy);
                    return false;
                }
            }
            for (int j = 0; j < 17; j++) {
                double c = vals[3 * j + 2];
                p->kp[j].x_px = (float)vals[3 * j];
                p->kp[j].y_px = (float)vals[3 * j + 1];
                p->kp[j].c = (float)(c < 0.0 ? 0.0 : c > 1.0 ? 1.0 : c); /* heatmap scores can overshoot 1 */
            }
            have_kp = true;
        } else if (gs_jtok_eq(&t, "score")) {
            double d;
            if (v.type == GS_JT_NUM && gs_jtok_num(&v, &d))
                p->score = (float)d;
            else if (!gs_jlex_skip(lex, &v)) {
                gs_kp_json_syntax(lex, path, err);
                return false;
            }
        } else if (gs_jtok_eq(&t, "idx")) {
            if (!gs_kp_json_track(lex, &v, path, obj->line, "idx", &p->track, err))
                return false;
        } else if (!gs_jlex_skip(lex, &v)) {
            gs_kp_json_syntax(lex, path, err);
            return false;
        }
    }
    if (!have_id || !have_kp) {
        gs_kpread_fail(err, GS_KPR_EDATA, path, obj->line, have_id ? "keypoints" : "image_id",
                       "missing");
        return false;
    }
    return true;
}

bool gs_kp_alphapose_load(const char *path, gs_kp_people *people, gs_kpread_error *err)
{
    size_t len;
    char *text = gs_kp_slurp(path, &len, err);
    if (!text)
        return false;
    gs_jlex lex;
    gs_jtok t;
    bool ok = false;
    if (!gs_kp_json_begin(&lex, text, len, path, GS_JT_ARR,
                          "expected a JSON array of results (AlphaPose result list)", &t, err))
        goto out;
    gs_jt k;
    for (;;) {
        k = gs_jlex_next(&lex, &t);
        if (k == GS_JT_ARR_END)
            break;
        if (k == GS_JT_ERROR) {
            gs_kp_json_syntax(&lex, path, err);
            goto out;
        }
        if (k != GS_JT_OBJ) {
            gs_kpread_fail(err, GS_KPR_EDATA, path, t.line, NULL,
                           "expected a result object in the list");
            goto out;
        }
        gs_kp_person p;
        memset(&p, 0, sizeof p);
        p.line = t.line;
        if (!parse_person(&lex, &t, path, &p, err))
            goto out;
        if (!gs_kp_people_push(people, &p)) {
            gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "out of memory");
            goto out;
        }
    }
    if (gs_jlex_next(&lex, &t) != GS_JT_EOF) {
        gs_kp_json_syntax(&lex, path, err);
        goto out;
    }
    ok = true;
out:
    free(text);
    return ok;
}
