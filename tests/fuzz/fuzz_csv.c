/* fuzz_csv.c - libFuzzer harness for the streamed CSV keypoint reader
 * (src/io/gs_kpread.c) and, behind it, the core: the first input byte picks
 * reader options (--layout, --fps) and the core's fit, the rest is the file.
 * Properties: open/next never crash; an error names the file and stays (sticky);
 * a frame has strictly increasing finite time, confidences in 0..1, and every
 * coordinate NaN (missing) or finite; every core event formats (fuzz_pipe.h).
 * Built by tests/fuzz/run.sh (clang), not by CMake. */
#include "gs_kpread.h"
#include "fuzz_pipe.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_error(const gs_kpread_error *err, const char *path)
{
    FZ_CHECK(err->status == GS_KPR_EDATA || err->status == GS_KPR_EUSAGE);
    FZ_CHECK(memchr(err->text, 0, sizeof err->text) && memchr(err->field, 0, sizeof err->field));
    FZ_CHECK(strncmp(err->text, path, strlen(path)) == 0 && err->text[strlen(path)] == ':');
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    uint8_t sel = data[0];
    static const double fps_tab[] = {NAN, 30.0, 59.94, 1e-3, 1e6, 120.0, NAN, NAN};
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    o.layout_set = sel & 1u;
    o.layout = (gs_layout)((sel >> 1) % 3u);
    o.fps = fps_tab[(sel >> 3) & 7u];
    const char *path = fz_write_temp(data + 1, size - 1, ".csv");

    gs_kpread_error err;
    memset(&err, 0x5a, sizeof err); /* no stale NUL may hide a missing terminator */
    gs_kpread *r = gs_kpread_open(path, &o, &err);
    if (!r) {
        check_error(&err, path);
        return 0;
    }
    gs_layout lay = gs_kpread_layout(r);
    if (o.layout_set) FZ_CHECK(lay == o.layout);
    size_t nkp = gs_layout_kp_count(lay);
    FZ_CHECK(nkp == 1 || nkp == 17 || nkp == 33);
    fz_pipe fp;
    fz_pipe_begin(&fp, lay, sel >> 6 | (sel & 4u) << 1);
    gs_kpframe f;
    double last_t = -INFINITY;
    gs_kpr_status st;
    while ((st = gs_kpread_next(r, &f, &err)) == GS_KPR_FRAME) {
        FZ_CHECK(isfinite(f.t_s) && f.t_s > last_t);
        last_t = f.t_s;
        for (size_t k = 0; k < nkp; k++) {
            const gs_kp *kp = &f.kp[k];
            FZ_CHECK(kp->c >= 0.0f && kp->c <= 1.0f);
            FZ_CHECK(isnan(kp->x_px) || isfinite(kp->x_px));
            FZ_CHECK(isnan(kp->y_px) || isfinite(kp->y_px));
            if (kp->c > 0.0f) FZ_CHECK(isfinite(kp->x_px) && isfinite(kp->y_px));
        }
        FZ_CHECK(isnan(f.size_px) || isfinite(f.size_px));
        uint64_t done, total;
        gs_kpread_progress(r, &done, &total);
        FZ_CHECK(done <= total);
        fz_pipe_push(&fp, lay, f.kp, f.t_s, f.size_px);
    }
    if (st == GS_KPR_EOF) {
        fz_pipe_end(&fp);
        FZ_CHECK(gs_kpread_next(r, &f, &err) == GS_KPR_EOF);
    } else {
        check_error(&err, path);
        gs_kpread_error again;
        FZ_CHECK(gs_kpread_next(r, &f, &again) == st && strcmp(again.text, err.text) == 0);
    }
    gs_kpread_close(r);
    return 0;
}
