/* fuzz_pipe.h - the reader harnesses feed every frame they get into the core
 * (gs_pipeline) as `gravscale replay` does, so the core meets whatever a reader
 * lets through, and every event must format: JSON Lines within GS_EMIT_MAX,
 * valid JSON and UTF-8; NMEA checksummed and <= 82 characters. Header-only. */
#ifndef GS_FUZZ_PIPE_H
#define GS_FUZZ_PIPE_H

#include "fuzz_util.h"
#include "gravscale/gravscale.h"

#define FZ_PIPE_MAX_FRAMES 4000 /* keeps one input fast; flights need far fewer */

typedef struct {
    gs_pipeline p;
    bool on;
    uint32_t summaries;
    uint64_t frames;
} fz_pipe;

static void fz_pipe_event(void *ctx, const gs_event *ev)
{
    fz_pipe *fp = ctx;
    char buf[GS_EMIT_MAX];
    size_t n = gs_emit_json(ev, buf, sizeof buf);
    FZ_CHECK(n > 0); /* the app would lose this event */
    fz_check_json_line(buf, n);
    if (getenv("FZ_PRINT") && ev->type != GS_EV_SAMPLE) fputs(buf, stderr); /* to look at one input */
    n = gs_emit_nmea(ev, buf, sizeof buf);
    if (ev->type == GS_EV_STATE || ev->type == GS_EV_SAMPLE || ev->type == GS_EV_FIT) FZ_CHECK(n == 0);
    else fz_check_nmea_line(buf, n);
    if (ev->type == GS_EV_SUMMARY) fp->summaries++;
    if (ev->type == GS_EV_JUMP && ev->u.jump.accepted) {
        /* an accepted flight has a finite, positive scale and jump; its height is unknown
         * (NaN) only when it says why: no standing size, or one at another depth */
        const uint32_t sizeless = GS_WARN_NO_SIZE | GS_WARN_DEPTH_CHANGED;
        if (ev->u.jump.warnings & sizeless) FZ_CHECK(isnan(ev->u.jump.height_m));
        else FZ_CHECK(isfinite(ev->u.jump.height_m) && ev->u.jump.height_m > 0.0);
        FZ_CHECK(isfinite(ev->u.jump.q_m_per_px) && ev->u.jump.q_m_per_px > 0.0);
        FZ_CHECK(isfinite(ev->u.jump.flight_time_s) && ev->u.jump.flight_time_s > 0.0);
        FZ_CHECK(isfinite(ev->u.jump.jump_height_m) && ev->u.jump.jump_height_m > 0.0);
    }
}

/* sel picks the robust fit and the ring size, so all of them meet odd data */
static inline void fz_pipe_begin(fz_pipe *fp, gs_layout layout, uint8_t sel)
{
    static double storage[(65536 * (sizeof(gs_sample) + sizeof(float))) / sizeof(double) + 16];
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.fit_method = sel % 3 == 0 ? GS_FIT_IRLS : sel % 3 == 1 ? GS_FIT_RANSAC : GS_FIT_PLAIN;
    cfg.ring_capacity = (sel >> 2) & 1 ? 64 : 512;
    memset(fp, 0, sizeof *fp);
    size_t need = gs_pipeline_storage_bytes(&cfg);
    FZ_CHECK(need <= sizeof storage);
    FZ_CHECK(gs_pipeline_init(&fp->p, &cfg, layout, storage, need, fz_pipe_event, fp) == GS_OK);
    gs_pipeline_set_trace(&fp->p, (sel >> 3) & 1);
    fp->on = true;
}

static inline void fz_pipe_push(fz_pipe *fp, gs_layout layout, const gs_kp *kp, double t_s, float size_px)
{
    if (!fp->on || fp->frames >= FZ_PIPE_MAX_FRAMES) return;
    fp->frames++;
    if (layout == GS_LAYOUT_POINT) (void)gs_pipeline_push_point(&fp->p, t_s, kp[0].x_px, kp[0].y_px, kp[0].c, size_px);
    else (void)gs_pipeline_push_keypoints(&fp->p, t_s, kp);
}

static inline void fz_pipe_end(fz_pipe *fp)
{
    if (!fp->on) return;
    FZ_CHECK(gs_pipeline_flush(&fp->p) == GS_OK);
    FZ_CHECK(fp->summaries == 1);
    fp->on = false;
}

#endif
