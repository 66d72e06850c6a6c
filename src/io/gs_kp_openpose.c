/* gs_kp_openpose.c - OpenPose output folders: one *_keypoints.json per frame
 * (frame index = the last digit run of the name), "people"[i].pose_keypoints_2d
 * in BODY_25 (75 numbers) or COCO-18 (54), mapped to COCO-17. */
#include <dirent.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gs_kpread.h"

/* COCO-17 order: nose, l/r eye, l/r ear, l/r shoulder, l/r elbow, l/r wrist, l/r hip, l/r knee, l/r ankle */
const uint8_t gs_kp_body25_to_coco17[17] = {0, 16, 15, 18, 17, 5, 2, 6, 3, 7, 4, 12, 9, 13, 10, 14, 11};
const uint8_t gs_kp_coco18_to_coco17[17] = {0, 15, 14, 17, 16, 5, 2, 6, 3, 7, 4, 11, 8, 12, 9, 13, 10};

static const char SUFFIX[] = "_keypoints.json";

typedef struct {
    uint64_t frame;
    char *name;
} op_file;

static int file_cmp(const void *a, const void *b)
{
    const op_file *x = a, *y = b;
    if (x->frame != y->frame)
        return x->frame < y->frame ? -1 : 1;
    return strcmp(x->name, y->name);
}


static bool parse_person(gs_jlex *lex, const gs_jtok *obj, const char *path, uint64_t frame,
                         gs_kp_people *people, gs_kpread_error *err)
{
    gs_kp_person p;
    memset(&p, 0, sizeof p);
    p.frame = frame;
    p.line = obj->line;
    p.track = -1;
    p.score = NAN;
    bool have_kp = false;
    gs_jtok t, v;
    for (;;) {
        gs_jt k = gs_jlex_next(lex, &t);
        if (k == GS_JT_OBJ_END)
            break;
        if (k != GS_JT_KEY || gs_jlex_next(lex, &v) == GS_JT_ERROR) {
            gs_kp_json_syntax(lex, path, err);
            return false;
        }
        if (gs_jtok_eq(&t, "pose_keypoints_2d")) {
            double vals[75];
            size_t n = 0;
            if (!gs_kp_json_numbers(lex, &v, path, obj->line, "pose_keypoints_2d", vals, 75, &n,
                                    err))
                return false;
            const uint8_t *map;
            if (n == 75) {
                map = gs_kp_body25_to_coco17;
            } else if (n == 54) {
                map = gs_kp_coco18_to_coco17;
            } else if (n == 0) {
                continue; /* this person has no body pose (face/hand-only output) */
            } else {
                gs_kpread_fail(err, GS_KPR_EDATA, path, obj->line, "pose_keypoints_2d",
                               "%zu numbers, expected 75 (BODY_25) or 54 (COCO-18)", n);
                return false;
            }
            for (int j = 0; j < 17; j++) {
                const double *src = &vals[3 * map[j]];
                double c = src[2];
                gs_kp *kp = &p.kp[j];
                if (!(fabs(src[0]) <= FLT_MAX && fabs(src[1]) <= FLT_MAX)) { /* kept as float: it would become inf */
                    gs_kpread_fail(err, GS_KPR_EDATA, path, obj->line, "pose_keypoints_2d",
                                   "keypoint %d (%.6g, %.6g) is beyond the float range of a pixel coordinate",
                                   (int)map[j], src[0], src[1]);
                    return false;
                }
                kp->c = (float)(c < 0.0 ? 0.0 : c > 1.0 ? 1.0 : c);
                /* OpenPose writes 0,0,0 for a keypoint it did not find */
                kp->x_px = kp->c > 0.0f ? (float)src[0] : NAN;
                kp->y_px = kp->c > 0.0f ? (float)src[1] : NAN;
            }
            have_kp = true;
        } else if (gs_jtok_eq(&t, "person_id")) {
            if (!gs_kp_json_track(lex, &v, path, obj->line, "person_id", &p.track, err))
                return false;
        } else if (!gs_jlex_skip(lex, &v)) {
            gs_kp_json_syntax(lex, path, err);
            return false;
        }
    }
    if (!have_kp)
        return true; /* nothing to follow in this entry */
    if (!gs_kp_people_push(people, &p)) {
        gs_kpread_fail(err, GS_KPR_EDATA, path, 0, NULL, "out of memory");
        return false;
    }
    return true;
}

static bool parse_file(const char *path, uint64_t frame, gs_kp_people *people,
                       gs_kpread_error *err)
{
    size_t len;
    char *text = gs_kp_slurp(path, &len, err);
    if (!text)
        return false;
    bool ok = false;
    gs_jlex lex;
    gs_jtok t, v;
    if (!gs_kp_json_begin(&lex, text, len, path, GS_JT_OBJ, "expected a JSON object with \"people\"",
                          &t, err))
        goto out;
    gs_jt k;
    bool have_people = false;
    for (;;) {
        k = gs_jlex_next(&lex, &t);
        if (k == GS_JT_OBJ_END)
            break;
        if (k != GS_JT_KEY || gs_jlex_next(&lex, &v) == GS_JT_ERROR) {
            gs_kp_json_syntax(&lex, path, err);
            goto out;
        }
        if (!gs_jtok_eq(&t, "people")) {
            if (!gs_jlex_skip(&lex, &v)) {
                gs_kp_json_syntax(&lex, path, err);
                goto out;
            }
            continue;
        }
        if (v.type != GS_JT_ARR) {
            gs_kpread_fail(err, GS_KPR_EDATA, path, v.line, "people", "not an array");
            goto out;
        }
        have_people = true;
        for (;;) {
            gs_jtok o;
            k = gs_jlex_next(&lex, &o);
            if (k == GS_JT_ARR_END)
                break;
            if (k == GS_JT_ERROR) {
                gs_kp_json_syntax(&lex, path, err);
                goto out;
            }
            if (k != GS_JT_OBJ) {
                gs_kpread_fail(err, GS_KPR_EDATA, path, o.line, "people",
                               "expected a person object");
                goto out;
            }
            if (!parse_person(&lex, &o, path, frame, people, err))
                goto out;
        }
    }
    if (gs_jlex_next(&lex, &t) != GS_JT_EOF) {
        gs_kp_json_syntax(&lex, path, err);
        goto out;
    }
    if (!have_people) {
        gs_kpread_fail(err, GS_KPR_EDATA, path, 1, "people", "missing");
        goto out;
    }
    ok = true;
out:
    free(text);
    return ok;
}

bool gs_kp_openpose_load(const char *dir, gs_kp_people *people, gs_kpread_error *err)
{
    struct stat sb;
    if (stat(dir, &sb) != 0) {
        gs_kpread_fail(err, GS_KPR_EDATA, dir, 0, NULL, "cannot open: %s", strerror(errno));
        return false;
    }
    if (!S_ISDIR(sb.st_mode)) {
        gs_kpread_fail(err, GS_KPR_EDATA, dir, 0, NULL,
                       "not a folder (--format openpose reads a folder of *%s files)", SUFFIX);
        return false;
    }
    DIR *d = opendir(dir);
    if (!d) {
        gs_kpread_fail(err, GS_KPR_EDATA, dir, 0, NULL, "cannot open: %s", strerror(errno));
        return false;
    }
    op_file *files = NULL;
    size_t n = 0, cap = 0;
    bool ok = false;
    size_t dl = strlen(dir);
    const size_t sl = sizeof SUFFIX - 1;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        size_t nl = strlen(e->d_name);
        if (nl <= sl || strcmp(e->d_name + nl - sl, SUFFIX) != 0)
            continue;
        uint64_t idx;
        if (!gs_kp_index_from_name(e->d_name, nl - sl, &idx)) {
            gs_kpread_fail(err, GS_KPR_EDATA, dir, 0, NULL, "no frame number in the name '%s'",
                           e->d_name);
            goto out;
        }
        if (n == cap) {
            size_t nc = cap ? cap * 2 : 256;
            op_file *nf = realloc(files, nc * sizeof *nf);
            if (!nf) {
                gs_kpread_fail(err, GS_KPR_EDATA, dir, 0, NULL, "out of memory");
                goto out;
            }
            files = nf;
            cap = nc;
        }
        files[n].frame = idx;
        files[n].name = malloc(dl + 1 + nl + 1);
        if (!files[n].name) {
            gs_kpread_fail(err, GS_KPR_EDATA, dir, 0, NULL, "out of memory");
            goto out;
        }
        memcpy(files[n].name, dir, dl);
        files[n].name[dl] = '/';
        memcpy(files[n].name + dl + 1, e->d_name, nl + 1);
        n++;
    }
    if (n == 0) {
        gs_kpread_fail(err, GS_KPR_EDATA, dir, 0, NULL, "no *%s files in the folder", SUFFIX);
        goto out;
    }
    qsort(files, n, sizeof *files, file_cmp);
    for (size_t i = 0; i < n; i++) {
        if (i > 0 && files[i].frame == files[i - 1].frame) {
            gs_kpread_fail(err, GS_KPR_EDATA, files[i].name, 0, NULL,
                           "frame %llu also in %s", (unsigned long long)files[i].frame,
                           files[i - 1].name);
            goto out;
        }
        if (!parse_file(files[i].name, files[i].frame, people, err))
            goto out;
    }
    ok = true;
out:
    closedir(d);
    for (size_t i = 0; i < n; i++)
        free(files[i].name);
    free(files);
    return ok;
}
