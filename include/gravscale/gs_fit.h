/* gs_fit.h - streaming weighted least-squares fit of x(t) and y(t) to quadratics,
 * by Givens-rotation updates of a 3x3 triangular factor in centred, scaled time
 * tau = (t - t0) / tscale (no t^4 sums), plus a robust refit over a ring window. */
#ifndef GS_FIT_H
#define GS_FIT_H

#include "gs_types.h"
#include "gs_ring.h"

typedef struct {
    int64_t t0_us;         /* centre of the time axis */
    gs_real tscale_s;      /* its unit, seconds */
    gs_real r[6];          /* upper triangle of R, row-major: r00 r01 r02 r11 r12 r22 */
    gs_real zx[3], zy[3];  /* Q^T * sqrt(w) * x and y */
    gs_real ssr_x, ssr_y;  /* weighted residual sum of squares */
    gs_real sum_w;
    uint32_t n;           /* samples with w > 0 */
} gs_fit;

typedef struct {
    int64_t t0_us;            /* reference time of the coefficients */
    gs_real x0_px, vx_px_s, ax_px_s2;  /* x(t) = x0 + vx*(t-t0) + ax/2*(t-t0)^2 */
    gs_real y0_px, vy_px_s, ay_px_s2;
    gs_real a_px_s2;          /* |(ax, ay)| */
    gs_real a_se_px_s2;       /* standard error of a_px_s2 */
    gs_real g_dir_deg;        /* direction of (ax, ay) from image down (+y), positive toward +x */
    gs_real rms_px;           /* weighted RMS of the 2D residual */
    uint32_t n;
} gs_fit_result;

/* Start an empty fit. t0_us: a time inside the expected window (e.g. its
 * centre); tscale_us > 0: about the window's length. */
void gs_fit_init(gs_fit *f, int64_t t0_us, int64_t tscale_us);
/* Add one sample with weight w >= 0 (w == 0 or non-finite values are ignored). */
void gs_fit_add(gs_fit *f, int64_t t_us, gs_real x_px, gs_real y_px, gs_real w);
/* Solve. GS_EINVAL when fewer than 3 weighted samples or the design is singular
 * (e.g. fewer than 3 distinct times). With exactly 3 the exact parabola is
 * returned and a_se_px_s2 is NaN (no degrees of freedom). */
gs_status gs_fit_solve(const gs_fit *f, gs_fit_result *out);

typedef enum {
    GS_FIT_IRLS = 0,  /* Tukey-biweight iteratively reweighted LS on the 2D residual: default */
    GS_FIT_RANSAC,    /* the paper's: RANSAC (deterministic PRNG) then LS on inliers */
    GS_FIT_PLAIN      /* weighted LS once */
} gs_fit_method;

const char *gs_fit_method_name(gs_fit_method m);
bool gs_fit_method_from_name(const char *s, size_t len, gs_fit_method *out);

/* Robust fit of the ring samples [first, first+count) using each sample's w as
 * prior weight. keep: caller memory for `count` bits ((count + 31) / 32 words);
 * on return bit i is set when sample first+i kept a positive final weight
 * (clear = rejected as outlier or unusable). min_scale_px: floor for the
 * residual scale (keeps perfect data from rejecting everything). No other
 * caller memory; hosts unpack up to 256 window samples on the stack (22 KB), a
 * size-optimised build (the firmware) reads them from the ring (gs_fit.c).
 * Returns GS_EINVAL when a sample is missing from the ring or < 3 remain
 * (with 3 the SE is NaN, as in gs_fit_solve). */
gs_status gs_fit_robust(const gs_ring *ring, uint64_t first, uint32_t count,
                        gs_fit_method method, float min_scale_px,
                        uint32_t *keep, gs_fit_result *out);
/* Bit i of a keep set from gs_fit_robust (false for a NULL set). */
bool gs_fit_kept(const uint32_t *keep, uint32_t i);

#endif
