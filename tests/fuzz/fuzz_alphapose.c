/* fuzz_alphapose.c - libFuzzer harness for the AlphaPose reader
 * (src/io/gs_kp_alphapose.c and the person choice in gs_kpread.c) and the core
 * behind it: the first byte picks --fps, --track and the core's fit, the rest
 * is the result list. Properties: no crash or leak; errors name the file; frames
 * come in increasing frame order with t = frame / fps, confidences in 0..1,
 * coordinates NaN or finite; every core event formats (fuzz_pipe.h).
 * Built by tests/fuzz/run.sh (clang), not by CMake. */
#include "gs_kpread.h"
#include "fuzz_pipe.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    uint8_t sel = data[0];
    static const double fps_tab[] = {30.0, 25.0, 1e-3, 1e6};
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    o.format = GS_KPF_ALPHAPOSE;
    o.fps = fps_tab[sel & 3u];
    o.track = (sel >> 2) & 1u ? (long)((sel >> 3) & 3u) : -1;
    const char *path = fz_write_temp(data + 1, size - 1, ".json");

    gs_kpread_error err;
    memset(&err, 0x5a, sizeof err);
    gs_kpread *r = gs_kpread_open(path, &o, &err);
    if (!r) {
        FZ_CHECK(err.status == GS_KPR_EDATA);
        FZ_CHECK(memchr(err.text, 0, sizeof err.text) && memchr(err.field, 0, sizeof err.field));
        FZ_CHECK(strncmp(err.text, path, strlen(path)) == 0);
        return 0;
    }
    FZ_CHECK(gs_kpread_layout(r) == GS_LAYOUT_COCO17);
    fz_pipe fp;
    fz_pipe_begin(&fp, GS_LAYOUT_COCO17, sel >> 5);
    gs_kpframe f;
    bool first = true;
    uint64_t last_frame = 0;
    gs_kpr_status st;
    while ((st = gs_kpread_next(r, &f, &err)) == GS_KPR_FRAME) {
        FZ_CHECK(first || f.frame > last_frame);
        first = false;
        last_frame = f.frame;
        FZ_CHECK(f.t_s == (double)f.frame / o.fps);
        for (int k = 0; k < 17; k++) {
            const gs_kp *kp = &f.kp[k];
            FZ_CHECK(kp->c >= 0.0f && kp->c <= 1.0f);
            FZ_CHECK(isnan(kp->x_px) || isfinite(kp->x_px));
            FZ_CHECK(isnan(kp->y_px) || isfinite(kp->y_px));
        }
        fz_pipe_push(&fp, GS_LAYOUT_COCO17, f.kp, f.t_s, f.size_px);
    }
    FZ_CHECK(st == GS_KPR_EOF); /* the whole file was checked at open */
    fz_pipe_end(&fp);
    gs_kpread_close(r);
    return 0;
}
