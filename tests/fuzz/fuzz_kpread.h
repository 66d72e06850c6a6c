/* fuzz_kpread.h - the checks the AlphaPose and OpenPose harnesses share: a
 * reader that refuses its input says so in a NUL-terminated error that starts
 * with the path; one that accepts it checked the whole input at open and gives
 * COCO-17 frames in increasing frame order at frame/fps seconds, each keypoint
 * a confidence in 0..1 and NaN or finite coordinates, all fed to the core
 * (fuzz_pipe.h). Header-only. */
#ifndef GS_FUZZ_KPREAD_H
#define GS_FUZZ_KPREAD_H

#include "fuzz_pipe.h"
#include "gs_kpread.h"

/* zero_c_unseen: a keypoint of confidence 0 has NaN coordinates (OpenPose's 0,0,0) */
static inline int fz_json_reader_run(const char *path, const gs_kpread_opts *o, uint8_t pipe_sel,
                                     bool zero_c_unseen)
{
    gs_kpread_error err;
    memset(&err, 0x5a, sizeof err);
    gs_kpread *r = gs_kpread_open(path, o, &err);
    if (!r) {
        FZ_CHECK(err.status == GS_KPR_EDATA);
        FZ_CHECK(memchr(err.text, 0, sizeof err.text) && memchr(err.field, 0, sizeof err.field));
        FZ_CHECK(strncmp(err.text, path, strlen(path)) == 0);
        return 0;
    }
    FZ_CHECK(gs_kpread_layout(r) == GS_LAYOUT_COCO17);
    fz_pipe fp;
    fz_pipe_begin(&fp, GS_LAYOUT_COCO17, pipe_sel);
    gs_kpframe f;
    bool first = true;
    uint64_t last_frame = 0;
    gs_kpr_status st;
    while ((st = gs_kpread_next(r, &f, &err)) == GS_KPR_FRAME) {
        FZ_CHECK(first || f.frame > last_frame);
        first = false;
        last_frame = f.frame;
        FZ_CHECK(f.t_s == (double)f.frame / o->fps);
        for (int k = 0; k < 17; k++) {
            const gs_kp *kp = &f.kp[k];
            FZ_CHECK(kp->c >= 0.0f && kp->c <= 1.0f);
            FZ_CHECK(isnan(kp->x_px) || isfinite(kp->x_px));
            FZ_CHECK(isnan(kp->y_px) || isfinite(kp->y_px));
            if (zero_c_unseen && kp->c == 0.0f) FZ_CHECK(isnan(kp->x_px) && isnan(kp->y_px));
        }
        fz_pipe_push(&fp, GS_LAYOUT_COCO17, f.kp, f.t_s, f.size_px);
    }
    FZ_CHECK(st == GS_KPR_EOF); /* the whole input was checked at open */
    fz_pipe_end(&fp);
    gs_kpread_close(r);
    return 0;
}

#endif
