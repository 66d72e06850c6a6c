/* gs_fit.c - streaming weighted quadratic fit by Givens rotations, and robust
 * (IRLS / RANSAC / plain) refits over a window of ring samples. */
#include "gravscale/gs_fit.h"

#include <math.h>
#include <string.h>
#include <tgmath.h>  /* sqrt, fabs, atan2 follow gs_real */

#include "gs_finite.h"
#include "gs_inline.h"
#include "gs_select.h"


/* A diagonal of R below this fraction of its column's norm means the column is
 * (numerically) a combination of the previous ones: the design is singular. */
#define GS_FIT_SINGULAR_REL (sizeof(gs_real) < sizeof(double) ? GS_R(1e-5) : GS_R(1e-9))

/* A robust fit passes over its window some twenty times (medians, reweightings,
 * candidate starts): where the build optimises for speed, its first GS_FIT_CACHE
 * samples are unpacked once on the stack with their last residuals, medians select
 * from a buffer, and LMS candidates that cannot win are dropped by a count. Where
 * it optimises for size (-Os: the firmware, whose code budget is full) none of
 * that is compiled: the same results from the compact code (samples read from the
 * ring, medians by counting passes); QEMU's lines equal the host float build's. */
#ifdef __OPTIMIZE_SIZE__
#define GS_FIT_FAST 0
#else
#define GS_FIT_FAST 1
#endif

/* Hosts: GCC's straight-line vectoriser pairs a sample's sums and shuffles them for
 * every sample (more instructions, not fewer) */
#if GS_FIT_FAST && defined(__GNUC__) && !defined(__clang__)
#define GS_NO_SLP __attribute__((optimize("no-tree-slp-vectorize")))
#else
#define GS_NO_SLP
#endif

#if GS_FIT_FAST && defined(__GNUC__)
/* two doubles, for the hot loops over a cached window (element-wise IEEE, as scalars) */
typedef double gs_v2d __attribute__((vector_size(16)));
typedef long long gs_v2l __attribute__((vector_size(16))); /* a comparison's lanes: -1 true, 0 false */
#endif

/* x86-64 hosts whose CPU has AVX2 take the loops over a fully usable cached window
 * four samples to a register: the same IEEE operations lane by lane, no fused
 * multiply-add (not enabled), sums still added sample after sample */
#if GS_FIT_FAST && GS_SELECT_AVX2
#define GS_FIT_AVX2 1
#define fit_avx2 gs_select_avx2
#else
#define GS_FIT_AVX2 0
#endif

/* Tukey biweight tuning constant (95 % Gaussian efficiency in 1D). */
#define GS_FIT_TUKEY_C GS_R(4.685)
/* Consistency factor that turns a median absolute residual into a Gaussian SD. */
#define GS_FIT_MAD_K GS_R(1.4826)
/* Bounded work for the robust starts: at most this many sample triples. */
#define GS_FIT_TRIPLES 60u  /* all-inlier triple among 60 fails with p < 1e-6 at 40 % gross outliers */
/* IRLS stops after this many reweightings even if the weights still move. */
#define GS_FIT_IRLS_MAX_ITER 10
/* Fixed PRNG seeds keep every robust fit reproducible. */
#define GS_FIT_SEED_IRLS 0x9E3779B9u
#define GS_FIT_SEED_RANSAC 0x2545F491u
/* Internal floor on the residual scale so that a zero scale cannot divide by 0. */
#define GS_FIT_TINY_SCALE_PX GS_R(1e-6)

static const gs_real rad_to_deg = GS_R(57.29577951308232);

/* An empty fit at a valid centre and scale (> 0 s): all sums and R zero (all-zero bits are +0.0). */
static void fit_start(gs_fit *f, int64_t t0_us, gs_real tscale_s)
{
#if GS_FIT_FAST
    /* field by field: a few vector stores where the memset of the whole is a rep stos */
    int k;
    for (k = 0; k < 6; k++) {
        f->r[k] = GS_R(0.0);
    }
    for (k = 0; k < 3; k++) {
        f->zx[k] = f->zy[k] = GS_R(0.0);
    }
    f->ssr_x = f->ssr_y = f->sum_w = GS_R(0.0);
    f->n = 0;
    f->t0_us = t0_us;
    f->tscale_s = tscale_s;
#else
    memset(f, 0, sizeof *f);
    f->t0_us = t0_us;
    f->tscale_s = tscale_s;
#endif
}

void gs_fit_init(gs_fit *f, int64_t t0_us, int64_t tscale_us)
{
    if (!f) {
        return;
    }
    /* A bad scale would make every tau NaN; 1 s keeps the fit usable. */
    fit_start(f, gs_time_ok(t0_us) ? t0_us : 0, gs_time_span_s(tscale_us > 0 ? tscale_us : GS_US_PER_S, 0));
}

/* The centred, scaled time of t_us: the exact integer span over the scale, both in microseconds. */
static gs_real fit_tau(int64_t t_us, int64_t t0_us, gs_real tscale_us)
{
    return gs_time_span_us(t_us, t0_us) / tscale_us;
}

/* Rotate pair (e, v) by (c, s): the Givens step of one entry of [R | zx zy]. */
static void rot(gs_real *e, gs_real *v, gs_real c, gs_real s)
{
    gs_real rkj = *e;
    *e = c * rkj + s * *v;
    *v = c * *v - s * rkj;
}

/* Rotate the weighted row (1, tau, tau^2 | x, y) into [R | zx zy]; w > 0 and all values finite. */
static void add_row(gs_fit *f, gs_real tau, gs_real x_px, gs_real y_px, gs_real w)
{
    gs_real v[5], sw, *rk = f->r; /* row k of R, packed: R(k, j) at rk[j - k] */
    int k, j;
    sw = sqrt((gs_real)w);
    v[0] = sw;
    v[1] = sw * tau;
    v[2] = sw * tau * tau;
    v[3] = sw * (gs_real)x_px;
    v[4] = sw * (gs_real)y_px;
#if GS_FIT_FAST
#pragma GCC unroll 3 /* hosts: every index constant, no branch per entry (the firmware keeps the loops) */
#endif
    for (k = 0; k < 3; rk += 3 - k, k++) {
        gs_real a = rk[0];
        gs_real b = v[k];
        gs_real rho, c, sn;
        if (b == GS_R(0.0)) {
            continue;
        }
        rho = sqrt(a * a + b * b);
        c = a / rho;
        sn = b / rho;
#if GS_FIT_FAST
#pragma GCC unroll 5
#endif
        for (j = k; j < 5; j++) {
            rot(j < 3 ? &rk[j - k] : j == 3 ? &f->zx[k] : &f->zy[k], &v[j], c, sn);
        }
    }
    /* What is left of the row after eliminating its basis part is its residual. */
    f->ssr_x += v[3] * v[3];
    f->ssr_y += v[4] * v[4];
    f->sum_w += (gs_real)w;
    f->n++;
}

void gs_fit_add(gs_fit *f, int64_t t_us, gs_real x_px, gs_real y_px, gs_real w)
{
    if (!f || !(w > GS_R(0.0)) || !gs_finite3_r(w, x_px, y_px) || !gs_time_ok(t_us)) {
        return;
    }
    add_row(f, fit_tau(t_us, f->t0_us, f->tscale_s * GS_R(1e6)), x_px, y_px, w);
}

/* No curve yet: the result's count and centre, every value NaN (one copy for both callers;
 * the count before the 64-bit centre keeps every argument in a register on a 32-bit core) */
static NOINLINE void empty_result(gs_fit_result *out, uint32_t n, int64_t t0_us)
{
    const gs_real nan = (gs_real)NAN;
    out->t0_us = t0_us;
    out->n = n;
    out->x0_px = out->vx_px_s = out->ax_px_s2 = nan;
    out->y0_px = out->vy_px_s = out->ay_px_s2 = nan;
    out->a_px_s2 = out->a_se_px_s2 = out->g_dir_deg = out->rms_px = nan;
}

/* Solve R c = z for the upper-triangular packed R. */
static void back_sub(const gs_real r[6], const gs_real z[3], gs_real c[3])
{
    c[2] = z[2] / r[5];
    c[1] = (z[1] - r[4] * c[2]) / r[3];
    c[0] = (z[0] - r[1] * c[1] - r[2] * c[2]) / r[0];
}

/* A parabola in tau for both axes: x = c[0] + c[1] tau + c[2] tau^2, y likewise in c[3..5]. */
typedef struct {
    gs_real c[6];
} gs_par;

/* R can be solved: each diagonal entry nonzero and not negligible against its column's norm
 * (the column norms of R equal those of the weighted design: Q is orthogonal) */
static bool r_regular(const gs_fit *f)
{
    gs_real col[3];
    const gs_real *rk = f->r; /* row k of R: its diagonal first */
    col[0] = fabs(f->r[0]);
    col[1] = sqrt(f->r[1] * f->r[1] + f->r[3] * f->r[3]);
    col[2] = sqrt(f->r[2] * f->r[2] + f->r[4] * f->r[4] + f->r[5] * f->r[5]);
    for (int k = 0; k < 3; rk += 3 - k, k++) {
        /* (an infinite diagonal makes its column's norm infinite or NaN: refused too) */
        gs_real d = fabs(*rk);
        if (!(col[k] > GS_R(0.0)) || !(d > GS_FIT_SINGULAR_REL * col[k])) {
            return false;
        }
    }
    return true;
}

/* gs_fit_solve, and on success the tau-basis parabola to *p (when p is not NULL); with
 * base, f fitted the samples less base: base is added back. */
static gs_status solve_par(const gs_fit *f, gs_fit_result *out, gs_par *p, const gs_par *base)
{
    gs_par par;
    gs_real *cx = &par.c[0], *cy = &par.c[3], ts, ts2, ssr;
    int k;
    if (!f || !out) {
        return GS_EINVAL;
    }
    empty_result(out, f->n, f->t0_us);
    if (f->n < 3 || !r_regular(f)) {
        return GS_EINVAL;
    }
    back_sub(f->r, f->zx, cx);
    back_sub(f->r, f->zy, cy);
    for (k = 0; base && k < 6; k++) {
        par.c[k] += base->c[k];
    }
    ts = f->tscale_s;
    ts2 = ts * ts;
    {
        /* the results are gs_real too (gs_fit_result) */
        gs_real ax = GS_R(2.0) * cx[2] / ts2, ay = GS_R(2.0) * cy[2] / ts2;
        out->x0_px = (gs_real)cx[0];
        out->vx_px_s = (gs_real)(cx[1] / ts);
        out->ax_px_s2 = (gs_real)ax;
        out->y0_px = (gs_real)cy[0];
        out->vy_px_s = (gs_real)(cy[1] / ts);
        out->ay_px_s2 = (gs_real)ay;
        out->a_px_s2 = (gs_real)sqrt(ax * ax + ay * ay);
        out->g_dir_deg = GS_REAL_IS_FLOAT ? (gs_real)(gs_atan2f((float)ax, (float)ay) * (float)rad_to_deg)
                                         : (gs_real)(atan2(ax, ay) * rad_to_deg);
    }
    ssr = f->ssr_x + f->ssr_y;
    out->rms_px = (gs_real)sqrt(ssr / f->sum_w);
    if (f->n > 3) {
        /* Pooled over both axes: 2n residuals, 6 coefficients. */
        gs_real sigma2 = ssr / (GS_R(2.0) * ((gs_real)f->n - GS_R(3.0)));
        /* Row 2 of R^-1 is (0, 0, 1/r22), so [(R^T R)^-1]_22 = 1/r22^2. */
        gs_real se_c2 = sqrt(sigma2) / fabs(f->r[5]);
        /* var(ax) = var(ay), so the magnitude's variance is the same. */
        out->a_se_px_s2 = GS_R(2.0) * se_c2 / ts2;
    }
    if (p) {
        *p = par;
    }
    return GS_OK;
}

#if GS_FIT_FAST
/* solve_par's verdict and parabola without the result's fields (an IRLS step needs only
 * the curve): the same checks and the same arithmetic */
static gs_status solve_par_only(const gs_fit *f, gs_par *p, const gs_par *base)
{
    int k;
    if (f->n < 3 || !r_regular(f)) {
        return GS_EINVAL;
    }
    back_sub(f->r, f->zx, &p->c[0]);
    back_sub(f->r, f->zy, &p->c[3]);
    for (k = 0; base && k < 6; k++) {
        p->c[k] += base->c[k];
    }
    return GS_OK;
}
#endif

gs_status gs_fit_solve(const gs_fit *f, gs_fit_result *out)
{
    return solve_par(f, out, NULL, NULL);
}

const char *gs_fit_method_name(gs_fit_method m)
{
    switch (m) {
    case GS_FIT_IRLS:
        return "irls";
    case GS_FIT_RANSAC:
        return "ransac";
    case GS_FIT_PLAIN:
        return "plain";
    }
    return "unknown";
}

bool gs_fit_method_from_name(const char *s, size_t len, gs_fit_method *out)
{
    static const gs_fit_method all[3] = {GS_FIT_IRLS, GS_FIT_RANSAC, GS_FIT_PLAIN};
    size_t i, k;
    if (!s || !out) {
        return false;
    }
    for (i = 0; i < 3; i++) {
        const char *name = gs_fit_method_name(all[i]);
        for (k = 0; k < len && name[k] != '\0' && name[k] == s[k]; k++) {
        }
        if (k == len && name[k] == '\0' && (GS_WITH_RANSAC || all[i] != GS_FIT_RANSAC)) {
            *out = all[i];
            return true;
        }
    }
    return false;
}

/* ---- robust fits over a ring window ------------------------------------------ */

/* What a fit reads of a usable ring sample, unpacked. */
typedef struct {
    gs_real tau;    /* centred, scaled time in the window */
    float xy_px[2]; /* x, y: indexed by axis like the parabola's coefficients */
    float w;        /* prior weight (> 0); 0 marks a cached sample the fits skip */
} gs_fsamp;

/* Window samples unpacked on the stack by a fast build (2.3 KB with their residuals
 * and keys where gs_real is float, 22 KB in double) */
#define GS_FIT_CACHE (GS_REAL_IS_FLOAT ? 64u : 256u)
/* Fast builds: LMS triples already drawn, one bit each, for windows with at most this many */
#define GS_FIT_SEEN_BITS 4096u

typedef struct {
    const gs_ring *ring;
    uint64_t first;
    uint32_t count;
    uint32_t m; /* usable samples in the window */
    uint32_t *keep;           /* the caller's flags, a bit per sample (gs_fit_robust) */
    int64_t t0_us;            /* the window's centre */
    gs_real tscale_us_r;      /* its length in us (> 0, below the ring's 2^31 us span; exact below 2^24 us in float) */
    gs_real tscale_s;         /* the same in seconds: its fits' scale (gs_time_span32_s) */
    gs_fsamp *cache;          /* samples [0, min(count, GS_FIT_CACHE)) */
    gs_real *r2;              /* their squared residuals from the last median_resid */
    gs_real *exy;             /* fast double builds: ... and their x and y residuals (2 rows of GS_FIT_CACHE) */
    uint32_t *key;            /* the median's selection scratch */
    float *med_key;           /* fast builds: the last median's squared residual, as a float */
    uint32_t *med_at;         /* fast builds: and its index among the keys */
    gs_real *soa;             /* fast double builds: the usable cached samples' tau, x, y, w (4 rows of m) */
    struct gs_wlast *last;    /* fast builds: the last reweighting's sums, solved in full only at the end */
} gs_win;

/* A reweighting's fit and, when based, the curve its sums were taken about. */
typedef struct gs_wlast {
    gs_fit f;
    gs_par base;
    bool based;
} gs_wlast;

static uint32_t xorshift32(uint32_t *state)
{
    uint32_t x = *state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *state = x;
    return x;
}

/* Uniform integer in [0, n) for n >= 1 (the modulo bias is irrelevant here). */
static uint32_t rand_below(uint32_t *state, uint32_t n)
{
    return xorshift32(state) % n;
}

#if GS_FIT_FAST && defined(__SIZEOF_INT128__)
#define GS_FIT_LMS_TABLE 1
/* The LMS start's GS_FIT_TRIPLES * 3 draws, xorshift32 from GS_FIT_SEED_IRLS in order:
 * the same numbers without the generator's dependent shifts */
static const uint32_t lms_draws[3u * GS_FIT_TRIPLES] = {
    0x510C4619u, 0xE02E553Eu, 0x7BB98F3Au, 0x0183A8B5u, 0xE6336D1Fu, 0xF989D237u,
    0xBA2529D0u, 0xFCFBEDBFu, 0xA8C5EE39u, 0xB55A53B8u, 0x1A88A9EEu, 0xF918A8B4u,
    0x6DC588D3u, 0x472F513Cu, 0x0C1870B8u, 0x43E1465Fu, 0x0E78EA8Au, 0x761DC0DEu,
    0x0ECA9C7Du, 0xF5E7493Fu, 0x84D44CBFu, 0xA536E9DEu, 0x79AFAED8u, 0x02E9F4A2u,
    0xB3C8F91Cu, 0x318EC249u, 0xD13543EAu, 0x504FD68Eu, 0xF9563BE1u, 0xFB6A9A74u,
    0xACAD82A6u, 0x83D0D79Au, 0xBD58BA6Bu, 0xE8A46341u, 0xFD4255C7u, 0x48A7297Au,
    0x1C8FC87Eu, 0x558F2D7Eu, 0xB43618AEu, 0x935F84DFu, 0x1B4EF29Du, 0x66BB3273u,
    0x1E5F1329u, 0x7B73EBB4u, 0xC6A87E76u, 0xE5BD8265u, 0xEBD01B3Du, 0xFE4E23A6u,
    0x7D6529DBu, 0xD39A9B74u, 0x9E7F3ACEu, 0x5DFE0DFDu, 0x147D987Du, 0x493F1344u,
    0xC1AF1B0Fu, 0x7B13A768u, 0xF02AB277u, 0x6AE429E5u, 0x14C73F29u, 0x976EB1B8u,
    0x6A6BB394u, 0x9F3E8E98u, 0x9358942Eu, 0xBA7F8CC0u, 0x37128F53u, 0xB9E359CFu,
    0x8980C4E2u, 0xB28541ECu, 0x4DA15AB0u, 0xB81A50ABu, 0xB3E67C2Cu, 0xF01B81BDu,
    0x85A054CBu, 0x681719B7u, 0xEF1638C7u, 0x29D754C0u, 0xAAA99987u, 0xAABF9C2Bu,
    0x7E60C676u, 0xB3689101u, 0x8854D505u, 0x4C7BF39Fu, 0x730959FBu, 0x5EF4A9E0u,
    0xB2D14C84u, 0xF371A5A4u, 0x3F6D8E86u, 0x591C32D8u, 0x37ACF21Bu, 0x94171B6Cu,
    0x982EBAF1u, 0xA1671469u, 0x3EA8A61Cu, 0x670D5609u, 0x744E0D0Fu, 0x081948F8u,
    0x01CD571Bu, 0xCEE2330Cu, 0x98FD1EEDu, 0x5F34CCDDu, 0x134EFECAu, 0x5E6CC8A1u,
    0x2869E8BDu, 0xBAB60242u, 0x2531989Du, 0xD264420Cu, 0x1E980CDEu, 0xFF7BA8BFu,
    0xC7EDBCA9u, 0x7F6C3635u, 0xCCF7B6E0u, 0x7F5ED555u, 0x1B70D24Fu, 0x261F68B3u,
    0xAA24CBD7u, 0x58987D78u, 0xB1DD8A83u, 0x1130B265u, 0xE8FE2ABBu, 0x9882D18Fu,
    0x94D94A16u, 0x0EE14FBBu, 0xC5D1BA30u, 0xA06FAC1Bu, 0xE8703B4Du, 0x0C2474E1u,
    0xD5BAA21Du, 0xBED11EC1u, 0x3C2778E5u, 0xB44D9E78u, 0xF7D12A99u, 0x82CE18D8u,
    0x7B723E72u, 0xAB3065ACu, 0x57337BAEu, 0x3092562Du, 0x30AEABC6u, 0x5F153C8Du,
    0xE818F92Fu, 0x10913491u, 0xF662FD90u, 0x93C58678u, 0x4258685Du, 0xA52E1174u,
    0x8714FC74u, 0x0BD47719u, 0x23D5A5C2u, 0x7AD860F4u, 0xAE1DA977u, 0x7D5BD92Eu,
    0xC9BD5831u, 0x35D264ECu, 0x50B4D12Bu, 0x98AB5803u, 0x86C37B16u, 0xDD983706u,
    0xB46BCDFAu, 0x77498910u, 0x8B1EEE85u, 0x8F02D9A2u, 0x52E88499u, 0x0D0B3124u,
    0x0EDF12D3u, 0x7C2596B1u, 0x1089E8C8u, 0x9F8F3E00u, 0x71AF46C7u, 0xB78AA5FCu,
    0x859FD8A6u, 0xAFEFDB83u, 0xC76DA84Cu, 0x3EE63EBEu, 0xDF01C6E6u, 0x1C73D408u,
    0xB8AE0951u, 0x4906A7F3u, 0x22E9A8EFu, 0xE97C21B5u, 0xC41C5510u, 0x99703BAFu,
};

/* a % n through n's 64-bit reciprocal magic = UINT64_MAX / n + 1 (exact for every 32-bit a, n >= 1) */
static inline uint32_t mod_by(uint32_t a, uint64_t magic, uint32_t n)
{
    return (uint32_t)(((unsigned __int128)(magic * a) * n) >> 64);
}
#else
#define GS_FIT_LMS_TABLE 0
#endif

/* A held sample with a weight and a position takes part in the fits. */
static bool sample_usable(const gs_sample *s)
{
    /* w_q > 0 is gs_sample_w(s) > 0 without the division */
    return s->w_q > 0u && gs_finite2_f(s->x_px, s->y_px);
}

/* Window sample i unpacked into *out when it is held and usable; false otherwise. */
static bool win_usable(const gs_win *wn, uint32_t i, gs_fsamp *out)
{
    const gs_sample *s = gs_ring_at(wn->ring, wn->first + i);
    if (!s || !sample_usable(s)) {
        return false;
    }
    /* the span from the centre, exact from the 32-bit times (a usable sample lies in the
     * window, which spans less than 2^31 us: win_open); the centred, unit-length tau fits a float */
    out->tau = (gs_real)(int32_t)(s->t_us - (uint32_t)(uint64_t)wn->t0_us) / wn->tscale_us_r;
    out->xy_px[0] = s->x_px;
    out->xy_px[1] = s->y_px;
    out->w = gs_sample_w(s);
    return true;
}

/* Window sample i when usable: from the cache, else unpacked into *buf; NULL otherwise. */
static const gs_fsamp *win_at(const gs_win *wn, uint32_t i, gs_fsamp *buf)
{
    if (GS_FIT_FAST && i < GS_FIT_CACHE) {
        return wn->cache[i].w > 0.0f ? &wn->cache[i] : NULL;
    }
    return win_usable(wn, i, buf) ? buf : NULL;
}

bool gs_fit_kept(const uint32_t *keep, uint32_t i)
{
    return keep && ((keep[i >> 5] >> (i & 31u)) & 1u) != 0u;
}

static void keep_set(uint32_t *keep, uint32_t i, bool on)
{
    uint32_t bit = 1u << (i & 31u);
    keep[i >> 5] = on ? (keep[i >> 5] | bit) : (keep[i >> 5] & ~bit);
}

/* Squared 2D distance of a sample from the parabola, in px^2. */
static gs_real resid2(const gs_par *p, const gs_fsamp *s)
{
    gs_real tau = s->tau;
    gs_real ex = (gs_real)s->xy_px[0] - (p->c[0] + tau * (p->c[1] + tau * p->c[2]));
    gs_real ey = (gs_real)s->xy_px[1] - (p->c[3] + tau * (p->c[4] + tau * p->c[5]));
    return ex * ex + ey * ey;
}

/* 2D distance of a sample from the parabola, in px. */
static gs_real resid_norm(const gs_par *p, const gs_fsamp *s)
{
    return sqrt(resid2(p, s));
}

/* The parabola through three samples (Newton divided differences). Two at one time
 * divide by zero: c2 of each axis is then infinite or NaN (par_finite). */
static void par_through(const gs_fsamp *a, const gs_fsamp *b, const gs_fsamp *c, gs_par *p)
{
    gs_real ta = a->tau, tb = b->tau, tc = c->tau;
    gs_real dab = tb - ta, dac = tc - ta, dbc = tc - tb;
    int axis;
#if GS_FIT_FAST && defined(__GNUC__)
    if (!GS_REAL_IS_FLOAT) {
        /* fast double builds: both axes side by side, the same operations */
        gs_v2d va = {a->xy_px[0], a->xy_px[1]}, vb = {b->xy_px[0], b->xy_px[1]}, vc = {c->xy_px[0], c->xy_px[1]};
        gs_v2d sab = (vb - va) / (gs_v2d){dab, dab}, sac = (vc - va) / (gs_v2d){dac, dac};
        gs_v2d c2 = (sac - sab) / (gs_v2d){dbc, dbc};
        gs_v2d c1 = sab - c2 * (gs_v2d){ta + tb, ta + tb};
        gs_v2d c0 = va - (gs_v2d){ta, ta} * (c1 + c2 * (gs_v2d){ta, ta});
        p->c[0] = c0[0], p->c[1] = c1[0], p->c[2] = c2[0];
        p->c[3] = c0[1], p->c[4] = c1[1], p->c[5] = c2[1];
        return;
    }
#endif
    for (axis = 0; axis < 2; axis++) {
        gs_real va = a->xy_px[axis];
        gs_real vb = b->xy_px[axis];
        gs_real vc = c->xy_px[axis];
        gs_real sab = (vb - va) / dab;
        gs_real sac = (vc - va) / dac;
        gs_real c2 = (sac - sab) / dbc;
        gs_real c1 = sab - c2 * (ta + tb);
        gs_real c0 = va - ta * (c1 + c2 * ta);
        p->c[3 * axis + 0] = c0;
        p->c[3 * axis + 1] = c1;
        p->c[3 * axis + 2] = c2;
    }
}

/* Every coefficient of p finite: a curve, not a degenerate triple's. */
static bool par_finite(const gs_par *p)
{
    int k;
    for (k = 0; k < 6; k++) {
        if (!gs_finite_r(p->c[k])) {
            return false;
        }
    }
    return true;
}


/* The k-th smallest of n float bit patterns (non-negative floats order like their
 * bits; key may be reordered): Wirth's selection, partitions about the k-th slot until
 * it holds the key a sort would put there. The same float as sorting. *at: the rank
 * selection's hint (gs_select_rank_avx2). */
static float select_key(uint32_t *key, uint32_t n, uint32_t k, uint32_t *at)
{
    int32_t l = 0, r = (int32_t)n - 1, kk = (int32_t)k; /* n <= GS_FIT_CACHE */
    float v;
    (void)at;
#if GS_FIT_AVX2
    if (n <= 32u && n > 0u && fit_avx2()) {
        /* a short window's median: the partitions' branches would go either way at random */
        uint32_t b = gs_select_rank_avx2(key, n, k, at);
        memcpy(&v, &b, sizeof v);
        return v;
    }
#endif
    while (l < r) {
        uint32_t x = key[kk];
        int32_t i = l, j = r;
        do {
            while (key[i] < x) {
                i++;
            }
            while (x < key[j]) {
                j--;
            }
            if (i <= j) {
                uint32_t t = key[i];
                key[i] = key[j];
                key[j] = t;
                i++;
                j--;
            }
        } while (i <= j);
        if (j < kk) {
            l = i;
        }
        if (kk < i) {
            r = j;
        }
    }
    memcpy(&v, &key[kk], sizeof v);
    return v;
}

#if GS_FIT_AVX2
/* select_near's pass four keys at a time: the keys x with lo_b <= x < lo_b + span
 * (unsigned) to buf in order, the ones below lo_b counted. Returns the keys it did. */
GS_AVX2 static uint32_t near_keys_avx2(const uint32_t *key, uint32_t *buf, uint32_t n, uint32_t lo_b, uint32_t span,
                                       uint32_t *below, uint32_t *m)
{
    /* the lanes of a 4-bit set, in order, a byte each */
    static const uint32_t pick[16] = {0u,      0x00u,     0x01u,     0x0100u,   0x02u,     0x0200u,
                                      0x0201u, 0x020100u, 0x03u,     0x0300u,   0x0301u,   0x030100u,
                                      0x0302u, 0x030200u, 0x030201u, 0x03020100u};
    __m128i vlo = _mm_set1_epi32((int)lo_b), vspan = _mm_set1_epi32((int)span);
    uint32_t i;
    for (i = 0; i + 4u <= n; i += 4u) {
        __m128i x = _mm_loadu_si128((const __m128i *)(const void *)&key[i]), d = _mm_sub_epi32(x, vlo);
        unsigned ge = (unsigned)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_max_epu32(x, vlo), x)));
        unsigned out = (unsigned)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_max_epu32(d, vspan), d)));
        unsigned in = ~out & 15u;
        __m128i lanes = _mm_cvtepu8_epi32(_mm_cvtsi32_si128((int)pick[in]));
        *below += 4u - (uint32_t)__builtin_popcount(ge);
        _mm_storeu_ps((float *)(void *)&buf[*m], _mm_permutevar_ps(_mm_castsi128_ps(x), lanes));
        *m += (uint32_t)__builtin_popcount(in);
    }
    return i;
}
#endif

#if GS_FIT_FAST
/* select_key with a guess: the keys within a quarter of hint_key's value either way go
 * to buf, the ones below are counted; when the k-th lies among them it is selected from
 * those few (every key below ranks before them, every key above after), else from all.
 * The same key either way. */
static float select_near(uint32_t *key, uint32_t *buf, uint32_t n, uint32_t k, float hint_key, uint32_t *at)
{
    uint32_t none = UINT32_MAX; /* no hint for the few gathered keys */
    float lo = hint_key * 0.75f, hi = hint_key * 1.25f;
    uint32_t lo_b, hi_b, below = 0, m = 0, i;
    if (n < 16u || !(hint_key > 0.0f) || !(hi < (float)INFINITY)) { /* (few keys: the pass costs what it saves) */
        return select_key(key, n, k, at);
    }
    memcpy(&lo_b, &lo, sizeof lo_b);
    memcpy(&hi_b, &hi, sizeof hi_b);
    i = 0;
#if GS_FIT_AVX2
    if (fit_avx2()) {
        i = near_keys_avx2(key, buf, n, lo_b, hi_b - lo_b, &below, &m);
    }
#endif
    for (; i < n; i++) {
        uint32_t x = key[i];
        below += (uint32_t)(x < lo_b);
        buf[m] = x;
        m += (uint32_t)(x - lo_b < hi_b - lo_b); /* lo_b <= x < hi_b (below lo_b wraps high) */
    }
    if (below <= k && k < below + m) {
        return select_key(buf, m, k - below, &none);
    }
    return select_key(key, n, k, at);
}
#endif

#if GS_FIT_AVX2
/* Lanes [0, n) of four set (n <= 4), as doubles' and as floats' masks. */
static const int64_t lanes64[8] = {-1, -1, -1, -1, 0, 0, 0, 0};
static const int32_t lanes32[8] = {-1, -1, -1, -1, 0, 0, 0, 0};
#define GS_LANES64(n) _mm256_loadu_si256((const __m256i *)(const void *)&lanes64[4u - (n)])
/* the window's rows as doubles: the kernels below run only where gs_real is double (their
 * callers test GS_REAL_IS_FLOAT), the float build compiles them as dead code */
#define GS_D(rows) ((double *)(void *)(rows))
#define GS_LANES32(n) _mm_loadu_si128((const __m128i *)(const void *)&lanes32[4u - (n)])

/* The parabola's residuals of four samples of a fully usable cached window (lanes
 * past the window's end read as 0), rows t, x, y; the x and y residual to *ex, *ey. */
GS_AVX2 static inline __m256d resid4_avx2(const gs_win *wn, const __m256d c[6], uint32_t i, __m256i lanes,
                                          __m256d *ex, __m256d *ey)
{
    const double *t = GS_D(wn->soa), *x = t + GS_FIT_CACHE, *y = t + 2u * GS_FIT_CACHE;
    __m256d tau = _mm256_maskload_pd(&t[i], lanes);
    *ex = _mm256_sub_pd(_mm256_maskload_pd(&x[i], lanes),
                        _mm256_add_pd(c[0], _mm256_mul_pd(tau, _mm256_add_pd(c[1], _mm256_mul_pd(tau, c[2])))));
    *ey = _mm256_sub_pd(_mm256_maskload_pd(&y[i], lanes),
                        _mm256_add_pd(c[3], _mm256_mul_pd(tau, _mm256_add_pd(c[4], _mm256_mul_pd(tau, c[5])))));
    return _mm256_add_pd(_mm256_mul_pd(*ex, *ex), _mm256_mul_pd(*ey, *ey));
}

GS_AVX2 static inline void par_lanes_avx2(const gs_par *p, __m256d c[6])
{
    c[0] = _mm256_set1_pd(p->c[0]);
    c[1] = _mm256_set1_pd(p->c[1]);
    c[2] = _mm256_set1_pd(p->c[2]);
    c[3] = _mm256_set1_pd(p->c[3]);
    c[4] = _mm256_set1_pd(p->c[4]);
    c[5] = _mm256_set1_pd(p->c[5]);
}

/* median_resid's pass over a fully usable cached window, four samples at a time:
 * each sample's x, y residual and squared norm to the rows, its float to the keys. */
GS_AVX2 static void resid_rows_avx2(const gs_win *wn, const gs_par *p)
{
    __m256d c[6], ex, ey, r2;
    uint32_t i;
    par_lanes_avx2(p, c);
    for (i = 0; i + 4u <= wn->count; i += 4u) {
        r2 = resid4_avx2(wn, c, i, GS_LANES64(4u), &ex, &ey);
        _mm256_storeu_pd(&GS_D(wn->r2)[i], r2);
        _mm256_storeu_pd(&GS_D(wn->exy)[i], ex);
        _mm256_storeu_pd(&GS_D(wn->exy)[GS_FIT_CACHE + i], ey);
        _mm_storeu_ps((float *)(void *)&wn->key[i], _mm256_cvtpd_ps(r2));
    }
    if (i < wn->count) {
        __m256i lanes = GS_LANES64(wn->count - i);
        r2 = resid4_avx2(wn, c, i, lanes, &ex, &ey);
        _mm256_maskstore_pd(&GS_D(wn->r2)[i], lanes, r2);
        _mm256_maskstore_pd(&GS_D(wn->exy)[i], lanes, ex);
        _mm256_maskstore_pd(&GS_D(wn->exy)[GS_FIT_CACHE + i], lanes, ey);
        _mm_maskstore_ps((float *)(void *)&wn->key[i], GS_LANES32(wn->count - i), _mm256_cvtpd_ps(r2));
    }
}

/* median_below_cached's count, eight samples at a time: the same verdict, which only counts. */
GS_AVX2 static bool median_below_avx2(const gs_win *wn, const gs_par *p, double T, uint32_t need, uint32_t room)
{
    __m256d c[6], vT = _mm256_set1_pd(T), ex, ey;
    __m256i all = GS_LANES64(4u);
    uint32_t m = wn->m, less = 0, j;
    unsigned bits;
    par_lanes_avx2(p, c);
    for (j = 0; j + 8u <= m; j += 8u) {
        bits = (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(resid4_avx2(wn, c, j, all, &ex, &ey), vT, _CMP_LT_OQ)) |
               (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(resid4_avx2(wn, c, j + 4u, all, &ex, &ey), vT, _CMP_LT_OQ))
                   << 4;
        less += (uint32_t)__builtin_popcount(bits);
        if (less >= need) {
            return true;
        }
        if (j + 8u - less > room) {
            return false;
        }
    }
    for (; j < m; j += 4u) {
        uint32_t left = m - j < 4u ? m - j : 4u;
        bits = (unsigned)_mm256_movemask_pd(
            _mm256_cmp_pd(resid4_avx2(wn, c, j, GS_LANES64(left), &ex, &ey), vT, _CMP_LT_OQ));
        less += (uint32_t)__builtin_popcount(bits & ((1u << left) - 1u));
    }
    return less >= need;
}

/* Adds the four samples' (a, b, c, d) to acc's four sums, sample after sample. */
GS_AVX2 static inline __m256d add4_avx2(__m256d acc, __m256d a, __m256d b, __m256d c, __m256d d)
{
    __m256d ab02 = _mm256_unpacklo_pd(a, b), ab13 = _mm256_unpackhi_pd(a, b);
    __m256d cd02 = _mm256_unpacklo_pd(c, d), cd13 = _mm256_unpackhi_pd(c, d);
    acc = _mm256_add_pd(acc, _mm256_permute2f128_pd(ab02, cd02, 0x20));
    acc = _mm256_add_pd(acc, _mm256_permute2f128_pd(ab13, cd13, 0x20));
    acc = _mm256_add_pd(acc, _mm256_permute2f128_pd(ab02, cd02, 0x31));
    return _mm256_add_pd(acc, _mm256_permute2f128_pd(ab13, cd13, 0x31));
}

/* sum + the four lanes of v, one after the other. */
GS_AVX2 static inline double add_lanes_avx2(double sum, __m256d v)
{
    __m128d lo = _mm256_castpd256_pd128(v), hi = _mm256_extractf128_pd(v, 1);
    sum += _mm_cvtsd_f64(lo);
    sum += _mm_cvtsd_f64(_mm_unpackhi_pd(lo, lo));
    sum += _mm_cvtsd_f64(hi);
    return sum + _mm_cvtsd_f64(_mm_unpackhi_pd(hi, hi));
}

/* wsums_cached's IRLS step over a fully usable cached window, four samples at a time:
 * the Tukey weights from the median's residuals, the same products, each sum taken in
 * sample order. A rejected sample's lanes are zeroed and add +0 or -0, which leaves a
 * sum as it is (a sum that starts at +0 is never -0). s: g0..g4, bx0..2, by0..2, eex,
 * eey; the kept bits to keep (bits past count keep their values). The residuals are
 * the median's (wn->r2, wn->exy). Returns the samples kept. */
GS_AVX2 static uint32_t wsums_tukey_avx2(const gs_win *wn, double cut, uint32_t *keep, double s[13])
{
    const double *r2 = GS_D(wn->r2);
    const double *t = GS_D(wn->soa), *wp = GS_D(wn->soa) + 3u * GS_FIT_CACHE, *ex_row = GS_D(wn->exy), *ey_row = GS_D(wn->exy) + GS_FIT_CACHE;
    __m256d vcut = _mm256_set1_pd(cut), one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd();
    __m256d g = zero, b01 = zero, b2e = zero; /* (g0 g1 g2 g3), (bx0 by0 bx1 by1), (bx2 by2 eex eey) */
    double g4 = 0.0, v[12];
    uint32_t n = 0, word = 0, i;
    for (i = 0; i < wn->count; i += 4u) {
        uint32_t left = wn->count - i < 4u ? wn->count - i : 4u;
        __m256i lanes = GS_LANES64(left);
        __m256d r = _mm256_sqrt_pd(_mm256_maskload_pd(&r2[i], lanes));
        __m256d in = _mm256_and_pd(_mm256_cmp_pd(r, vcut, _CMP_LT_OQ), _mm256_castsi256_pd(lanes));
        __m256d u = _mm256_div_pd(r, vcut), w, ex, ey, tau, wt1, wt2, wt3, wx, wy;
        unsigned bits;
        u = _mm256_sub_pd(one, _mm256_mul_pd(u, u));
        w = _mm256_cvtps_pd(_mm256_cvtpd_ps(_mm256_mul_pd(_mm256_maskload_pd(&wp[i], lanes), _mm256_mul_pd(u, u))));
        in = _mm256_and_pd(in, _mm256_cmp_pd(w, zero, _CMP_GT_OQ));
        bits = (unsigned)_mm256_movemask_pd(in);
        word |= bits << (i & 31u);
        if (((i + 4u) & 31u) == 0u || i + left == wn->count) {
            uint32_t end = (i & 31u) + left, mask = end == 32u ? ~0u : (1u << end) - 1u;
            keep[i >> 5] = (keep[i >> 5] & ~mask) | word;
            word = 0;
        }
        if (bits == 0u) {
            continue; /* nothing to add */
        }
        n += (uint32_t)__builtin_popcount(bits);
        w = _mm256_and_pd(w, in);
        ex = _mm256_and_pd(_mm256_maskload_pd(&ex_row[i], lanes), in);
        ey = _mm256_and_pd(_mm256_maskload_pd(&ey_row[i], lanes), in);
        tau = _mm256_maskload_pd(&t[i], lanes);
        wt1 = _mm256_mul_pd(w, tau);
        wt2 = _mm256_mul_pd(wt1, tau);
        wt3 = _mm256_mul_pd(wt2, tau);
        wx = _mm256_mul_pd(w, ex);
        wy = _mm256_mul_pd(w, ey);
        g = add4_avx2(g, w, wt1, wt2, wt3);
        b01 = add4_avx2(b01, wx, wy, _mm256_mul_pd(wt1, ex), _mm256_mul_pd(wt1, ey));
        b2e = add4_avx2(b2e, _mm256_mul_pd(wt2, ex), _mm256_mul_pd(wt2, ey), _mm256_mul_pd(wx, ex),
                        _mm256_mul_pd(wy, ey));
        g4 = add_lanes_avx2(g4, _mm256_mul_pd(wt3, tau));
    }
    _mm256_storeu_pd(&v[0], g);
    _mm256_storeu_pd(&v[4], b01);
    _mm256_storeu_pd(&v[8], b2e);
    s[0] = v[0], s[1] = v[1], s[2] = v[2], s[3] = v[3], s[4] = g4;
    s[5] = v[4], s[6] = v[6], s[7] = v[8];  /* bx0 bx1 bx2 */
    s[8] = v[5], s[9] = v[7], s[10] = v[9]; /* by0 by1 by2 */
    s[11] = v[10], s[12] = v[11];           /* eex eey */
    return n;
}

/* tukey_loss over a fully usable cached window: the terms four at a time, summed in
 * sample order. */
GS_AVX2 static double tukey_loss_avx2(const gs_win *wn, const gs_par *p, double cut)
{
    const double *wp = GS_D(wn->soa) + 3u * GS_FIT_CACHE;
    __m256d c[6], vcut = _mm256_set1_pd(cut), one = _mm256_set1_pd(1.0), ex, ey;
    double loss = 0.0;
    uint32_t i;
    par_lanes_avx2(p, c);
    for (i = 0; i < wn->count; i += 4u) {
        uint32_t left = wn->count - i < 4u ? wn->count - i : 4u;
        __m256i lanes = GS_LANES64(left);
        __m256d u = _mm256_div_pd(_mm256_sqrt_pd(resid4_avx2(wn, c, i, lanes, &ex, &ey)), vcut);
        __m256d v = _mm256_sub_pd(one, _mm256_mul_pd(u, u));
        __m256d rho = _mm256_blendv_pd(one, _mm256_sub_pd(one, _mm256_mul_pd(_mm256_mul_pd(v, v), v)),
                                       _mm256_cmp_pd(u, one, _CMP_LT_OQ));
        __m256d term = _mm256_mul_pd(_mm256_maskload_pd(&wp[i], lanes), rho);
        if (left == 4u) {
            loss = add_lanes_avx2(loss, term);
        } else {
            double tv[4];
            uint32_t k;
            _mm256_storeu_pd(tv, term);
            for (k = 0; k < left; k++) {
                loss += tv[k];
            }
        }
    }
    return loss;
}
#endif

/* Median residual norm of the usable samples: the lower median of the squared
 * residuals as floats (squares order like norms: one sqrt for the median). The
 * keys sharing a prefix go to the buffer for select_key; while more than
 * GS_FIT_CACHE share it (long windows), a counting pass over the samples (no
 * storage) narrows it by 4 bits. The cached samples' residuals are kept for the
 * reweighting that follows. An open window has m >= 3 usable samples (win_open). */
static gs_real median_resid(const gs_win *wn, const gs_par *p)
{
    uint32_t prefix = 0, mask = 0, k, i, left = wn->m;
    int shift = 32;
    float v;
#if GS_FIT_FAST
    if (wn->count <= GS_FIT_CACHE) {
        /* every usable sample cached: one pass collects all keys (no prefix yet) */
        const gs_fsamp *c = wn->cache;
        gs_real c0 = p->c[0], c1 = p->c[1], c2 = p->c[2], c3 = p->c[3], c4 = p->c[4], c5 = p->c[5];
        uint32_t n = 0;
#if defined(__GNUC__)
        if (!GS_REAL_IS_FLOAT && wn->m == wn->count) {
            /* every sample usable: the rows of median_below_cached, four or two at a time */
            const gs_real *t = wn->soa, *x = wn->soa + GS_FIT_CACHE, *y = wn->soa + 2u * GS_FIT_CACHE;
            gs_v2d v0 = {c0, c0}, v1 = {c1, c1}, v2 = {c2, c2}, v3 = {c3, c3}, v4 = {c4, c4}, v5 = {c5, c5};
            i = 0;
#if GS_FIT_AVX2
            if (fit_avx2()) {
                resid_rows_avx2(wn, p);
                i = wn->count;
            }
#endif
            for (; i + 1u < wn->count; i += 2u) {
                gs_v2d tau, vx, vy, ex, ey, r2;
                float f0, f1;
                memcpy(&tau, &t[i], sizeof tau);
                memcpy(&vx, &x[i], sizeof vx);
                memcpy(&vy, &y[i], sizeof vy);
                ex = vx - (v0 + tau * (v1 + tau * v2));
                ey = vy - (v3 + tau * (v4 + tau * v5));
                r2 = ex * ex + ey * ey;
                memcpy(&wn->r2[i], &r2, sizeof r2);
                memcpy(&wn->exy[i], &ex, sizeof ex);
                memcpy(&wn->exy[GS_FIT_CACHE + i], &ey, sizeof ey);
                f0 = (float)r2[0];
                f1 = (float)r2[1];
                memcpy(&wn->key[i], &f0, sizeof f0);
                memcpy(&wn->key[i + 1u], &f1, sizeof f1);
            }
            n = i;
        }
#endif
        for (i = n; i < wn->count; i++) {
            if (c[i].w > 0.0f) {
                gs_real tau = c[i].tau;
                gs_real ex = (gs_real)c[i].xy_px[0] - (c0 + tau * (c1 + tau * c2));
                gs_real ey = (gs_real)c[i].xy_px[1] - (c3 + tau * (c4 + tau * c5));
                gs_real r2 = ex * ex + ey * ey;
                float f = (float)r2;
                wn->r2[i] = r2;
                wn->exy[i] = ex;
                wn->exy[GS_FIT_CACHE + i] = ey;
                memcpy(&wn->key[n++], &f, sizeof f);
            }
        }
        v = select_near(wn->key, wn->key + GS_FIT_CACHE, n, (n - 1) / 2, *wn->med_key, wn->med_at);
        *wn->med_key = v;
        return sqrt((gs_real)v);
    }
#endif
    k = (left - 1) / 2; /* lower median: exact for odd m, robust enough for even m */
    while (mask != ~0u) {
        uint32_t cnt[16] = {0};
        uint32_t d = 0, n = 0;
        bool collect = GS_FIT_FAST && left <= GS_FIT_CACHE;
        shift -= 4;
        for (i = 0; i < wn->count; i++) {
            gs_fsamp b;
            const gs_fsamp *s = win_at(wn, i, &b);
            if (s) {
                gs_real r2 = resid2(p, s);
                float f = (float)r2;
                uint32_t key;
                memcpy(&key, &f, sizeof key);
                if (GS_FIT_FAST && i < GS_FIT_CACHE) {
                    wn->r2[i] = r2;
                }
                if ((key & mask) != prefix) {
                    continue;
                }
                if (collect) {
                    wn->key[n++] = key;
                } else {
                    cnt[(key >> (uint32_t)shift) & 15u]++;
                }
            }
        }
        if (collect) {
            uint32_t none = UINT32_MAX;
            return sqrt((gs_real)select_key(wn->key, n, k, &none));
        }
        while (d < 15u && k >= cnt[d]) {
            k -= cnt[d];
            d++;
        }
        prefix |= d << (uint32_t)shift;
        mask |= 15u << (uint32_t)shift;
        left = cnt[d];
    }
    memcpy(&v, &prefix, sizeof v); /* more keys than the buffer holds share every bit */
    return sqrt((gs_real)v);
}

#if GS_FIT_FAST
/* p's median residual (median_resid) is below med: at least k + 1 of the m usable
 * samples lie nearer than med (sqrt is monotone), counted with early exits. */
static bool median_below(const gs_win *wn, const gs_par *p, gs_real med)
{
    uint32_t need = (wn->m - 1) / 2 + 1, room = wn->m - need, i;
    for (i = 0; i < wn->count; i++) {
        gs_fsamp b;
        const gs_fsamp *s = win_at(wn, i, &b);
        if (!s) {
            continue;
        }
        if (sqrt((gs_real)(float)resid2(p, s)) < med) {
            if (--need == 0u) {
                return true;
            }
        } else if (room-- == 0u) {
            return false;
        }
    }
    return false;
}
#endif

#if GS_FIT_FAST
/* The double T with r < T exactly when (float)r < key, for r >= 0 and key a float
 * >= 0: (float)r falls below key when r lies below the midpoint of key and the float
 * before it, or on it when that float is even (ties round to even). Both floats and
 * their midpoint are exact in double. */
static double below_key(float key)
{
    uint32_t kb;
    uint64_t mb;
    float lo;
    double mid;
    memcpy(&kb, &key, sizeof kb);
    if (kb == 0u) {
        return 0.0; /* nothing rounds below +0 */
    }
    kb--;
    memcpy(&lo, &kb, sizeof lo);
    mid = ((double)lo + (double)key) * 0.5;
    if ((kb & 1u) == 0u) {
        memcpy(&mb, &mid, sizeof mb);
        mb++; /* the next double up: r < it when r <= mid */
        memcpy(&mid, &mb, sizeof mid);
    }
    return mid;
}

/* median_below over a window the cache holds, in double: sqrt((double)a) < sqrt((double)b)
 * exactly when a < b for floats a, b >= 0 (adjacent floats differ by far more than a
 * double's rounding), so each squared residual's float is compared with the median's
 * through T = below_key(the median's float), which the caller takes once per best
 * median (without the conversion). The usable samples in rows, two at a time
 * where the compiler has vectors; the decision only counts, in any order. */
static bool median_below_cached(const gs_win *wn, const gs_par *p, double T)
{
    const gs_real *t = wn->soa, *x = wn->soa + GS_FIT_CACHE, *y = wn->soa + 2u * GS_FIT_CACHE;
    gs_real c0 = p->c[0], c1 = p->c[1], c2 = p->c[2], c3 = p->c[3], c4 = p->c[4], c5 = p->c[5];
    uint32_t m = wn->m, need = (m - 1) / 2 + 1, room = m - need, less = 0, j = 0;
#if GS_FIT_AVX2
    if (fit_avx2()) {
        return median_below_avx2(wn, p, T, need, room);
    }
#endif
#if defined(__GNUC__)
    gs_v2d v0 = {c0, c0}, v1 = {c1, c1}, v2 = {c2, c2}, v3 = {c3, c3}, v4 = {c4, c4}, v5 = {c5, c5}, vT = {T, T};
    for (; j + 3u < m; j += 4u) {
        gs_v2d ta, tb, xa, xb, ya, yb, exa, exb, eya, eyb;
        gs_v2l lt;
        memcpy(&ta, &t[j], sizeof ta);
        memcpy(&tb, &t[j + 2u], sizeof tb);
        memcpy(&xa, &x[j], sizeof xa);
        memcpy(&xb, &x[j + 2u], sizeof xb);
        memcpy(&ya, &y[j], sizeof ya);
        memcpy(&yb, &y[j + 2u], sizeof yb);
        exa = xa - (v0 + ta * (v1 + ta * v2));
        exb = xb - (v0 + tb * (v1 + tb * v2));
        eya = ya - (v3 + ta * (v4 + ta * v5));
        eyb = yb - (v3 + tb * (v4 + tb * v5));
        lt = (exa * exa + eya * eya < vT) + (exb * exb + eyb * eyb < vT);
        less -= (uint32_t)(lt[0] + lt[1]);
        if (less >= need) {
            return true;
        }
        if (j + 4u - less > room) {
            return false;
        }
    }
    for (; j + 1u < m; j += 2u) {
        gs_v2d tau, vx, vy, ex, ey, r2;
        gs_v2l lt;
        memcpy(&tau, &t[j], sizeof tau);
        memcpy(&vx, &x[j], sizeof vx);
        memcpy(&vy, &y[j], sizeof vy);
        ex = vx - (v0 + tau * (v1 + tau * v2));
        ey = vy - (v3 + tau * (v4 + tau * v5));
        r2 = ex * ex + ey * ey;
        lt = r2 < vT;
        less -= (uint32_t)(lt[0] + lt[1]);
        if (less >= need) {
            return true;
        }
        if (j + 2u - less > room) {
            return false;
        }
    }
#endif
    for (; j < m; j++) {
        gs_real tau = t[j];
        gs_real ex = x[j] - (c0 + tau * (c1 + tau * c2));
        gs_real ey = y[j] - (c3 + tau * (c4 + tau * c5));
        less += (uint32_t)(ex * ex + ey * ey < T);
        if (less >= need) {
            return true;
        }
        if (j + 1u - less > room) {
            return false;
        }
    }
    return false;
}
#endif

/* Tukey biweight of a residual norm r with cut-off cut. */
static gs_real tukey(gs_real r, gs_real cut)
{
    gs_real u;
    if (!(r < cut)) {
        return GS_R(0.0);
    }
    u = r / cut;
    u = GS_R(1.0) - u * u;
    return u * u;
}

/* Final weight of one sample under a model: prior * robust factor, as a float. */
typedef enum { W_PRIOR, W_TUKEY, W_INLIER } w_mode;

static float sample_weight(const gs_fsamp *s, const gs_par *p, w_mode mode, gs_real cut, const gs_real *r2)
{
    gs_real r;
    if (mode == W_PRIOR) {
        return s->w;
    }
    r = r2 ? sqrt(*r2) : resid_norm(p, s);
    if (mode == W_INLIER) {
        return r <= cut ? s->w : 0.0f;
    }
    return (float)((gs_real)s->w * tukey(r, cut));
}

/* The fit of the weighted sums of the samples less a base curve: the 3x3 Gram matrix
 * G = sum w (1, tau, tau^2)^T (1, tau, tau^2) and b = sum w e (1, tau, tau^2) per axis.
 * Its Cholesky factor is the R of the Givens QR (both upper triangular with a positive
 * diagonal, R^T R = G) and R^-T b its z, so solve_par reads it like a streamed fit. */
typedef struct {
    gs_real g[5];      /* sum w tau^k, k = 0..4 */
    gs_real b[2][3];   /* sum w e tau^k per axis, k = 0..2 */
    gs_real ee[2];     /* sum w e^2 per axis */
    uint32_t n;
} gs_wsums;

static void wsums_add(gs_wsums *a, gs_real tau, gs_real ex, gs_real ey, gs_real w)
{
    gs_real wt = w;  /* w tau^k */
    int k;
    a->ee[0] += w * ex * ex;
    a->ee[1] += w * ey * ey;
    for (k = 0; k < 5; k++) {
        a->g[k] += wt;
        if (k < 3) {
            a->b[0][k] += wt * ex;
            a->b[1][k] += wt * ey;
        }
        wt *= tau;
    }
    a->n++;
}

/* The sums into the fit f (started at the window's centre and scale); a singular G
 * leaves a zero or NaN diagonal that solve_par refuses. */
static void wsums_to_fit(const gs_wsums *a, gs_fit *f)
{
    gs_real *r = f->r, d;
    int axis;
    if (a->n == 0u) {
        return;
    }
    r[0] = sqrt(a->g[0]);
    r[1] = a->g[1] / r[0];
    r[2] = a->g[2] / r[0];
    d = a->g[2] - r[1] * r[1];
    r[3] = d > GS_R(0.0) ? sqrt(d) : GS_R(0.0);
    r[4] = (a->g[3] - r[1] * r[2]) / r[3];
    d = a->g[4] - r[2] * r[2] - r[4] * r[4];
    r[5] = d > GS_R(0.0) ? sqrt(d) : GS_R(0.0);
    for (axis = 0; axis < 2; axis++) {
        const gs_real *b = a->b[axis];
        gs_real *z = axis == 0 ? f->zx : f->zy, ssr;
        z[0] = b[0] / r[0];
        z[1] = (b[1] - r[1] * z[0]) / r[3];
        z[2] = (b[2] - r[2] * z[0] - r[4] * z[1]) / r[5];
        /* what the fit leaves of the sum of squares (small: e is taken about a near curve) */
        ssr = a->ee[axis] - (z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
        *(axis == 0 ? &f->ssr_x : &f->ssr_y) = ssr > GS_R(0.0) ? ssr : GS_R(0.0);
    }
    f->sum_w = a->g[0];
    f->n = a->n;
}

#if GS_FIT_FAST
/* wsums_add over a window the cache holds, in double: the same products summed in the
 * same order, in registers, and the kept bits set a word at a time. */
GS_NO_SLP static void wsums_cached(const gs_win *wn, const gs_par *model, const gs_par *base, w_mode mode, gs_real cut,
                         uint32_t *keep, const gs_real *r2, gs_wsums *a)
{
    gs_real g0 = GS_R(0.0), g1 = GS_R(0.0), g2 = GS_R(0.0), g3 = GS_R(0.0), g4 = GS_R(0.0);
    gs_real bx0 = g0, bx1 = g0, bx2 = g0, by0 = g0, by1 = g0, by2 = g0, eex = g0, eey = g0;
    uint32_t n = 0, word = 0, i;
#if defined(__GNUC__)
    gs_v2d p0 = {base->c[0], base->c[3]}, p1 = {base->c[1], base->c[4]}, p2 = {base->c[2], base->c[5]};
    gs_v2d ee = {g0, g0}, v0 = ee, v1 = ee, v2 = ee;
    i = 0;
#if GS_FIT_AVX2
    if (mode == W_TUKEY && r2 && wn->m == wn->count && fit_avx2()) {
        double s[13];
        n = wsums_tukey_avx2(wn, cut, keep, s); /* r2 is the median's: wn->r2 */
        i = wn->count;
        g0 = s[0], g1 = s[1], g2 = s[2], g3 = s[3], g4 = s[4];
        v0 = (gs_v2d){s[5], s[8]};
        v1 = (gs_v2d){s[6], s[9]};
        v2 = (gs_v2d){s[7], s[10]};
        ee = (gs_v2d){s[11], s[12]};
    } else
#endif
    if (mode == W_TUKEY && r2) {
        /* an IRLS step: the residuals from model (= base) the median left, 32 samples a word */
        uint32_t i0;
        for (i0 = 0; i0 < wn->count; i0 += 32u) {
            uint32_t end = wn->count - i0 < 32u ? wn->count : i0 + 32u, mask;
            word = 0;
            for (i = i0; i < end; i++) {
                float w = wn->cache[i].w;
                gs_real r, u, tau, wr, wt;
                gs_v2d wv, wtv, e;
                if (!(w > 0.0f)) {
                    continue;
                }
                r = sqrt(r2[i]);
                if (!(r < cut)) {
                    continue;
                }
                u = r / cut;
                u = GS_R(1.0) - u * u;
                w = (float)((gs_real)w * (u * u));
                if (!(w > 0.0f)) {
                    continue;
                }
                tau = wn->cache[i].tau;
                wr = (gs_real)w;
                word |= 1u << (i - i0);
                wv = (gs_v2d){wr, wr};
                e = (gs_v2d){wn->exy[i], wn->exy[GS_FIT_CACHE + i]};
                ee += wv * e * e;
                g0 += wr;
                v0 += wv * e;
                wt = wr * tau;
                wtv = (gs_v2d){wt, wt};
                g1 += wt;
                v1 += wtv * e;
                wt *= tau;
                wtv = (gs_v2d){wt, wt};
                g2 += wt;
                v2 += wtv * e;
                wt *= tau;
                g3 += wt;
                wt *= tau;
                g4 += wt;
                n++;
            }
            mask = end - i0 == 32u ? ~0u : (1u << (end - i0)) - 1u;
            keep[i0 >> 5] = (keep[i0 >> 5] & ~mask) | word;
        }
        i = wn->count; /* the general loop below has nothing left */
    }
#else
    i = 0;
#endif
    for (; i < wn->count; i++) {
        const gs_fsamp *s = &wn->cache[i];
        float w = s->w;
        if (!(w > 0.0f)) {
            w = 0.0f;
        } else if (mode == W_TUKEY && r2) {
            /* sample_weight's Tukey weight from the residual the median kept */
            gs_real r = sqrt(r2[i]), u;
            if (!(r < cut)) {
                w = 0.0f;
            } else {
                u = r / cut;
                u = GS_R(1.0) - u * u;
                w = (float)((gs_real)s->w * (u * u));
            }
        } else if (mode != W_PRIOR) {
            w = sample_weight(s, model, mode, cut, r2 ? &r2[i] : NULL);
        }
        if (w > 0.0f) {
            gs_real tau = s->tau, wr = (gs_real)w, wt;
            word |= 1u << (i & 31u);
#if defined(__GNUC__)
            {
                /* x and y side by side: the same operations on each */
                gs_v2d tv = {tau, tau}, wv = {wr, wr}, wtv;
                gs_v2d e = (gs_v2d){(gs_real)s->xy_px[0], (gs_real)s->xy_px[1]} - (p0 + tv * (p1 + tv * p2));
                ee += wv * e * e;
                g0 += wr;
                v0 += wv * e;
                wt = wr * tau;
                wtv = (gs_v2d){wt, wt};
                g1 += wt;
                v1 += wtv * e;
                wt *= tau;
                wtv = (gs_v2d){wt, wt};
                g2 += wt;
                v2 += wtv * e;
            }
#else
            {
                gs_real ex = (gs_real)s->xy_px[0] - (base->c[0] + tau * (base->c[1] + tau * base->c[2]));
                gs_real ey = (gs_real)s->xy_px[1] - (base->c[3] + tau * (base->c[4] + tau * base->c[5]));
                eex += wr * ex * ex;
                eey += wr * ey * ey;
                g0 += wr;
                bx0 += wr * ex;
                by0 += wr * ey;
                wt = wr * tau;
                g1 += wt;
                bx1 += wt * ex;
                by1 += wt * ey;
                wt *= tau;
                g2 += wt;
                bx2 += wt * ex;
                by2 += wt * ey;
            }
#endif
            wt *= tau;
            g3 += wt;
            wt *= tau;
            g4 += wt;
            n++;
        }
        if ((i & 31u) == 31u || i + 1u == wn->count) {
            /* bits past count keep their values, as keep_set leaves them */
            uint32_t mask = (i & 31u) == 31u ? ~0u : (1u << ((i & 31u) + 1u)) - 1u;
            keep[i >> 5] = (keep[i >> 5] & ~mask) | word;
            word = 0;
        }
    }
#if defined(__GNUC__)
    eex = ee[0];
    eey = ee[1];
    bx0 = v0[0];
    by0 = v0[1];
    bx1 = v1[0];
    by1 = v1[1];
    bx2 = v2[0];
    by2 = v2[1];
#endif
    a->g[0] = g0;
    a->g[1] = g1;
    a->g[2] = g2;
    a->g[3] = g3;
    a->g[4] = g4;
    a->b[0][0] = bx0;
    a->b[0][1] = bx1;
    a->b[0][2] = bx2;
    a->b[1][0] = by0;
    a->b[1][1] = by1;
    a->b[1][2] = by2;
    a->ee[0] = eex;
    a->ee[1] = eey;
    a->n = n;
}
#endif

/* Weighted LS over the window; flags each sample with a positive weight in keep, the
 * tau-basis parabola to p. r2: the samples' squared residuals from model, or NULL.
 * In double the normal equations (sums about model, when there is one) lose nothing
 * and cost a fraction of the Givens rows; in float (the firmware) the rows keep the
 * fit accurate in single precision. */
static gs_status window_fit(const gs_win *wn, const gs_par *model, w_mode mode, gs_real cut, gs_par *p,
                            gs_fit_result *out, const gs_real *r2)
{
    uint32_t *keep = wn->keep;
    gs_fit f;
    gs_wsums a;
    gs_par base;
    uint32_t i;
#if GS_FIT_FAST
    base = model && !GS_REAL_IS_FLOAT ? *model : (gs_par){{0}};
#else
    if (!GS_REAL_IS_FLOAT) { /* (float fits rotate the rows: no sums, no base) */
        memset(&base, 0, sizeof base);
        if (model) {
            base = *model;
        }
    }
#endif
    fit_start(&f, wn->t0_us, wn->tscale_s);
#if GS_FIT_FAST
    if (!GS_REAL_IS_FLOAT && wn->count <= GS_FIT_CACHE) {
        wsums_cached(wn, model, &base, mode, cut, keep, r2, &a); /* sets every sum */
        wsums_to_fit(&a, &f);
        if (!out) {
            /* an IRLS step: the curve now, the result from the kept sums when the run ends */
            wn->last->f = f;
            wn->last->base = base;
            wn->last->based = true;
            return solve_par_only(&f, p, &base);
        }
        return solve_par(&f, out, p, &base);
    }
#endif
    if (!GS_REAL_IS_FLOAT) {
        memset(&a, 0, sizeof a);
    }
    for (i = 0; i < wn->count; i++) {
        gs_fsamp b;
        const gs_fsamp *s = win_at(wn, i, &b);
        float w = s ? sample_weight(s, model, mode, cut, GS_FIT_FAST && r2 && i < GS_FIT_CACHE ? &r2[i] : NULL) : 0.0f;
        keep_set(keep, i, w > 0.0f);
        if (!(w > 0.0f)) {
            continue;
        }
        if (GS_REAL_IS_FLOAT) {
            /* as gs_fit_add would: the fit shares the window's centre and scale */
            add_row(&f, s->tau, s->xy_px[0], s->xy_px[1], (gs_real)w);
        } else {
            gs_real tau = s->tau;
            gs_real ex = (gs_real)s->xy_px[0] - (base.c[0] + tau * (base.c[1] + tau * base.c[2]));
            gs_real ey = (gs_real)s->xy_px[1] - (base.c[3] + tau * (base.c[4] + tau * base.c[5]));
            wsums_add(&a, tau, ex, ey, (gs_real)w);
        }
    }
    if (!GS_REAL_IS_FLOAT) {
        wsums_to_fit(&a, &f);
    }
#if GS_FIT_FAST
    if (!out) {
        wn->last->f = f;
        wn->last->base = base;
        wn->last->based = !GS_REAL_IS_FLOAT;
        return solve_par_only(&f, p, GS_REAL_IS_FLOAT ? NULL : &base);
    }
#endif
    return solve_par(&f, out, p, GS_REAL_IS_FLOAT ? NULL : &base);
}

/* The k-th usable sample (win_at, unpacked into *buf); count must cover it. */
static NOINLINE const gs_fsamp *usable_at(const gs_win *wn, uint32_t k, gs_fsamp *buf)
{
    uint32_t i;
    if (wn->m == wn->count) {
        return win_at(wn, k, buf); /* the common case: no scan needed */
    }
    for (i = 0; i < wn->count; i++) {
        const gs_fsamp *s = win_at(wn, i, buf);
        if (s) {
            if (k == 0) {
                return s;
            }
            k--;
        }
    }
    return win_at(wn, wn->count - 1, buf);
}

/* The parabola through the usable samples of ranks k[0], k[1] and k[2] (par_through). */
static void par_through_usable(const gs_win *wn, const uint32_t k[3], gs_par *p)
{
    gs_fsamp buf[3];
    const gs_fsamp *s[3];
    int j;
    for (j = 0; j < 3; j++) {
        /* every sample usable and cached: no scan (else the window was checked to be held) */
        s[j] = GS_FIT_FAST && wn->m == wn->count && wn->count <= GS_FIT_CACHE ? &wn->cache[k[j]]
                                                                             : usable_at(wn, k[j], &buf[j]);
    }
    par_through(s[0], s[1], s[2], p);
}

/* Least-median-of-squares start: of up to GS_FIT_TRIPLES triples, one sample
 * from each third of the usable samples (well spread in time, so the exact
 * parabola is well conditioned), keep the one with the smallest median
 * residual. Tolerates almost half the samples being gross outliers. */
static bool lmeds_start(const gs_win *wn, uint32_t m, gs_par *best, gs_real *best_med)
{
    uint32_t state = GS_FIT_SEED_IRLS;
    uint32_t third = m / 3, k, j;
    bool found = false;
#if GS_FIT_FAST
    double best_T = 0.0; /* below_key of *best_med's squared residual as a float, once found */
    /* a short window draws the same triple again and again: its curve, median and
     * verdict are the ones already had, so it is skipped (a bit per possible triple) */
    uint32_t span_c = m - 2 * third, n_triples = third * third * span_c;
    uint32_t seen[GS_FIT_SEEN_BITS / 32u];
    bool dedup = n_triples <= GS_FIT_SEEN_BITS;
    if (n_triples <= 256u) {
        memset(seen, 0, 8u * sizeof seen[0]); /* short windows: two stores, not a rep stos */
    } else if (dedup) {
        memset(seen, 0, ((n_triples + 31u) / 32u) * sizeof seen[0]);
    }
#endif
    /* par_through_usable's common case, decided once */
    bool all_cached = GS_FIT_FAST && wn->m == wn->count && wn->count <= GS_FIT_CACHE;
#if GS_FIT_LMS_TABLE
    uint64_t magic_ab = UINT64_MAX / third + 1u, magic_c = UINT64_MAX / (m - 2 * third) + 1u;
    (void)state, (void)j;
#endif
    *best_med = (gs_real)INFINITY;
    for (k = 0; k < GS_FIT_TRIPLES; k++) {
        uint32_t kt[3]; /* the ranks of the triple's samples, one from each third */
        gs_par p;
        gs_real med;
#if GS_FIT_LMS_TABLE
        kt[0] = mod_by(lms_draws[3u * k], magic_ab, third);
        kt[1] = third + mod_by(lms_draws[3u * k + 1u], magic_ab, third);
        kt[2] = 2 * third + mod_by(lms_draws[3u * k + 2u], magic_c, m - 2 * third);
#else
        for (j = 0; j < 3; j++) {
            kt[j] = j * third + rand_below(&state, j < 2 ? third : m - 2 * third);
        }
#endif
#if GS_FIT_FAST
        if (dedup) {
            uint32_t t = (kt[0] * third + (kt[1] - third)) * span_c + (kt[2] - 2 * third);
            if (seen[t >> 5] & (1u << (t & 31u))) {
                continue;
            }
            seen[t >> 5] |= 1u << (t & 31u);
        }
#endif
        /* (a degenerate triple's curve leaves every usable sample's residual infinite or NaN:
         * so is its median, which is never below the best) */
        if (all_cached) {
            par_through(&wn->cache[kt[0]], &wn->cache[kt[1]], &wn->cache[kt[2]], &p);
        } else {
            par_through_usable(wn, kt, &p);
        }
#if GS_FIT_FAST
        if (found && (!GS_REAL_IS_FLOAT && wn->count <= GS_FIT_CACHE ? !median_below_cached(wn, &p, best_T)
                                                                       : !median_below(wn, &p, *best_med))) {
            continue; /* cannot win: no median needed (m > 3 here: m = 3 stops at the first) */
        }
#endif
        med = median_resid(wn, &p);
        if (med < *best_med) {
            *best_med = med;
            *best = p;
            found = true;
#if GS_FIT_FAST
            best_T = below_key(*wn->med_key);
#endif
        }
        if (m == 3) {
            break;
        }
    }
    return found;
}

/* The largest distance between two curves at the window's start, centre and end (tau -1/2, 0, 1/2), px. */
static gs_real par_max_shift_px(const gs_par *a, const gs_par *b)
{
    gs_real worst = GS_R(0.0), diff[6];
    int k;
    for (k = 0; k < 6; k++) {
        diff[k] = a->c[k] - b->c[k]; /* the curves' difference, a parabola too */
    }
    for (k = 0; k < 3; k++) {
        gs_real t = GS_R(0.5) * (gs_real)(k - 1); /* the window's start, centre and end */
        gs_real dx = diff[0] + t * (diff[1] + t * diff[2]);
        gs_real dy = diff[3] + t * (diff[4] + t * diff[5]);
        gs_real d = sqrt(dx * dx + dy * dy);
        if (!(d <= worst)) {
            worst = d;
        }
    }
    return worst;
}

/* Robust loss of a curve: prior-weighted Tukey rho at the noise floor's cut-off
 * (1 for a rejected sample), comparable between two candidate solutions. */
static gs_real tukey_loss(const gs_win *wn, const gs_par *p, gs_real floor_px)
{
    gs_real cut = GS_FIT_TUKEY_C * floor_px, loss = GS_R(0.0);
    uint32_t i;
#if GS_FIT_AVX2
    if (!GS_REAL_IS_FLOAT && wn->count <= GS_FIT_CACHE && wn->m == wn->count && fit_avx2()) {
        return tukey_loss_avx2(wn, p, cut);
    }
#endif
#if GS_FIT_FAST
    if (wn->count <= GS_FIT_CACHE) {
        /* the same sum over the cache, the curve in registers */
        const gs_fsamp *c = wn->cache;
        gs_real c0 = p->c[0], c1 = p->c[1], c2 = p->c[2], c3 = p->c[3], c4 = p->c[4], c5 = p->c[5];
        for (i = 0; i < wn->count; i++) {
            gs_real tau, ex, ey, u, v;
            if (!(c[i].w > 0.0f)) {
                continue;
            }
            tau = c[i].tau;
            ex = (gs_real)c[i].xy_px[0] - (c0 + tau * (c1 + tau * c2));
            ey = (gs_real)c[i].xy_px[1] - (c3 + tau * (c4 + tau * c5));
            u = sqrt(ex * ex + ey * ey) / cut;
            v = GS_R(1.0) - u * u;
            loss += (gs_real)c[i].w * (u < GS_R(1.0) ? GS_R(1.0) - v * v * v : GS_R(1.0));
        }
        return loss;
    }
#endif
    for (i = 0; i < wn->count; i++) {
        gs_fsamp b;
        const gs_fsamp *s = win_at(wn, i, &b);
        gs_real u;
        if (!s) {
            continue;
        }
        u = sqrt(resid2(p, s)) / cut;
        loss += (gs_real)s->w * (u < GS_R(1.0) ? GS_R(1.0) - (GS_R(1.0) - u * u) * (GS_R(1.0) - u * u) * (GS_R(1.0) - u * u) : GS_R(1.0));
    }
    return loss;
}

/* Tukey biweight IRLS from a start, its flags and result to wn->keep and out: the robust loss
 * of the curve it settles on (tukey_loss), infinite when a reweighting leaves no fit. */
static gs_real irls_from(const gs_win *wn, const gs_par *start, gs_real floor_px, gs_fit_result *out)
{
    gs_par fin = *start, next;
    gs_real med, scale;
    int it;
    gs_status st = GS_OK;
    bool settled;
    for (it = 0; it < GS_FIT_IRLS_MAX_ITER; it++) {
        med = median_resid(wn, &fin);
        /* Residuals are deviations from the model (zero centred), so the MAD is the median norm. */
        scale = GS_FIT_MAD_K * med;
        if (!(scale >= floor_px)) {
            scale = floor_px;
        }
        /* the median just computed the residuals from fin that the weights need */
#if GS_FIT_FAST
        st = window_fit(wn, &fin, W_TUKEY, GS_FIT_TUKEY_C * scale, &next, NULL, wn->r2);
#else
        st = window_fit(wn, &fin, W_TUKEY, GS_FIT_TUKEY_C * scale, &next, out, NULL);
#endif
        if (st != GS_OK) {
            break;
        }
        /* Settled when the curve moves by far less than the noise. */
        settled = par_max_shift_px(&fin, &next) <= GS_R(1e-6) * scale;
        fin = next;
        if (settled) {
            break;
        }
    }
#if GS_FIT_FAST
    st = solve_par(&wn->last->f, out, NULL, wn->last->based ? &wn->last->base : NULL);
#endif
    return st == GS_OK ? tukey_loss(wn, &fin, floor_px) : (gs_real)INFINITY;
}

/* IRLS from two starts, the least-median-of-squares one (survives many gross
 * outliers) and the plain weighted fit (on clean data a few samples can fit a
 * chance subset better than all of them): the smaller robust loss wins. */
static gs_status fit_irls(const gs_win *wn, uint32_t m, gs_real floor_px, gs_fit_result *out)
{
    uint32_t *keep = wn->keep;
    enum { LMS, PLAIN, N_STARTS };
    gs_par start[N_STARTS];
    gs_real med, loss[N_STARTS] = {(gs_real)INFINITY, (gs_real)INFINITY};
    bool have[N_STARTS];
    int k;
    have[LMS] = lmeds_start(wn, m, &start[LMS], &med);
    have[PLAIN] = window_fit(wn, NULL, W_PRIOR, GS_R(0.0), &start[PLAIN], out, NULL) == GS_OK;
    /* a fast build keeps the plain run's flags and result (a few words for windows the cache holds) */
    uint32_t plain_keep[GS_FIT_FAST ? GS_FIT_CACHE / 32u : 1u];
    gs_fit_result plain_out;
    uint32_t words = (wn->count + 31u) / 32u, i;
    bool saved = false;
    /* the plain start first: the LMS run, which wins more often, leaves keep and out as its result */
    for (k = PLAIN; k >= LMS; k--) {
        if (have[k]) {
            loss[k] = irls_from(wn, &start[k], floor_px, out);
        }
        if (GS_FIT_FAST && k == PLAIN && loss[PLAIN] < (gs_real)INFINITY && have[LMS] && wn->count <= GS_FIT_CACHE) {
            for (i = 0; i < words; i++) {
                plain_keep[i] = keep[i];
            }
            plain_out = *out;
            saved = true;
        }
    }
    /* (no loss is NaN: a settled run's terms are each at most its weight, <= 1; a failed
     * run's loss is INFINITY) */
    if (!(loss[PLAIN] <= loss[LMS])) {
        return GS_OK; /* the LMS run won */
    }
    if (!(loss[PLAIN] < (gs_real)INFINITY)) {
        return GS_EINVAL; /* neither start gave a fit */
    }
    if (saved) {
        /* the plain run won: its flags and result back (whole words: bits past count never changed) */
        for (i = 0; i < words; i++) {
            keep[i] = plain_keep[i];
        }
        *out = plain_out;
        return GS_OK;
    }
    /* the plain run won: run it again so keep and out hold its weights (where no LMS start ran
     * after it they hold them already: the same deterministic run, the same finite loss) */
    (void)irls_from(wn, &start[PLAIN], floor_px, out);
    return GS_OK;
}

static gs_status fit_ransac(const gs_win *wn, uint32_t m, gs_real floor_px, gs_fit_result *out)
{
    uint32_t state = GS_FIT_SEED_RANSAC;
    gs_real thr = GS_R(3.0) * floor_px;
    gs_real best_cost = (gs_real)INFINITY;
    uint32_t best_in = 0, k, i;
    gs_par best;
    bool found = false;
    for (k = 0; k < GS_FIT_TRIPLES; k++) {
        uint32_t kt[3], j;
        gs_par p;
        uint32_t n_in = 0;
        gs_real cost = GS_R(0.0);
        for (j = 0; j < 3; j++) {
            kt[j] = rand_below(&state, m);
        }
        if (kt[0] == kt[1] || kt[0] == kt[2] || kt[1] == kt[2]) {
            continue;
        }
        par_through_usable(wn, kt, &p);
        if (!par_finite(&p)) {
            continue;
        }
        for (i = 0; i < wn->count; i++) {
            gs_fsamp b;
            const gs_fsamp *s = win_at(wn, i, &b);
            gs_real r2;
            if (!s) {
                continue;
            }
            r2 = resid2(&p, s);
            if (r2 <= thr * thr) {
                n_in++;
                cost += r2;
            }
        }
        /* Most inliers wins; ties go to the tighter consensus. */
        if (n_in > best_in || (n_in == best_in && n_in > 0 && cost < best_cost)) {
            best_in = n_in;
            best_cost = cost;
            best = p;
            found = true;
        }
    }
    if (!found) {
        return GS_EINVAL;
    }
    return window_fit(wn, &best, W_INLIER, thr, NULL, out, NULL);
}

/* Opens the window [first, first+count): GS_EINVAL when a sample is no longer held
 * or fewer than 3 usable ones at distinct times remain. */
static gs_status win_open(gs_win *wn, const gs_ring *ring, uint64_t first, uint32_t count)
{
    const gs_sample *lo, *hi; /* the first and the last usable sample (set once m > 0) */
    int32_t span_us;
    uint32_t i, m = 0;
    for (i = 0; i < count; i++) {
        const gs_sample *s = gs_ring_at(ring, first + i);
        if (!s) {
            /* Overwritten or not yet written: the window is gone. */
            return GS_EINVAL;
        }
        if (sample_usable(s)) {
            if (m == 0) {
                lo = s;
            }
            hi = s;
            m++;
        }
    }
    if (m < 3) {
        return GS_EINVAL;
    }
    /* the ring's times never decrease: the first usable is the earliest, the last the latest,
     * less than 2^31 us later (held samples): their 32-bit times' difference is exact */
    span_us = (int32_t)(hi->t_us - lo->t_us);
    if (!(span_us > 0)) {
        return GS_EINVAL;
    }
    wn->ring = ring;
    wn->first = first;
    wn->count = count;
    wn->m = m;
    /* Centred, unit-length tau keeps the basis well conditioned (and float-friendly). */
    wn->t0_us = gs_ring_sample_t_us(ring, lo) + (span_us >> 1);  /* (> 0: a shift halves it) */
    wn->tscale_us_r = (gs_real)span_us;  /* gs_time_span_us of it, which does not saturate */
    wn->tscale_s = gs_time_span32_s(span_us);
    for (i = 0; GS_FIT_FAST && i < count && i < GS_FIT_CACHE; i++) {
        if (!win_usable(wn, i, &wn->cache[i])) {
            wn->cache[i].w = 0.0f;
        }
    }
#if GS_FIT_FAST
    if (!GS_REAL_IS_FLOAT && count <= GS_FIT_CACHE) {
        uint32_t n = 0;
        for (i = 0; i < count; i++) {
            if (wn->cache[i].w > 0.0f) {
                wn->soa[n] = wn->cache[i].tau;
                wn->soa[GS_FIT_CACHE + n] = (gs_real)wn->cache[i].xy_px[0];
                wn->soa[2u * GS_FIT_CACHE + n] = (gs_real)wn->cache[i].xy_px[1];
                wn->soa[3u * GS_FIT_CACHE + n] = (gs_real)wn->cache[i].w;
                n++;
            }
        }
    }
#endif
    return GS_OK;
}

static gs_status fit_window(const gs_win *wn, gs_fit_method method, float min_scale_px, gs_fit_result *out)
{
    gs_real floor_px = (gs_finite_f(min_scale_px) && min_scale_px > 0.0f) ? (gs_real)min_scale_px : GS_FIT_TINY_SCALE_PX;
    switch (method) {
    case GS_FIT_PLAIN:
        return window_fit(wn, NULL, W_PRIOR, GS_R(0.0), NULL, out, NULL);
    case GS_FIT_IRLS:
        return fit_irls(wn, wn->m, floor_px, out);
    case GS_FIT_RANSAC: /* unknown where left out of the build (gs_features.h) */
        return GS_WITH_RANSAC ? fit_ransac(wn, wn->m, floor_px, out) : GS_EINVAL;
    }
    return GS_EINVAL;
}

gs_status gs_fit_robust(const gs_ring *ring, uint64_t first, uint32_t count, gs_fit_method method,
                        float min_scale_px, uint32_t *keep, gs_fit_result *out)
{
#if GS_FIT_FAST
    gs_fsamp cache[GS_FIT_CACHE];
    gs_real r2[GS_FIT_CACHE];
    uint32_t key[2u * GS_FIT_CACHE]; /* the keys, and select_near's few */
    float med_key = 0.0f;
    uint32_t med_at = 0;
    gs_real soa[GS_REAL_IS_FLOAT ? 1u : 4u * GS_FIT_CACHE];
    gs_real exy[2u * GS_FIT_CACHE];
    gs_wlast last;
#endif
    gs_win wn;
    uint32_t i;
    gs_status st;
#if GS_FIT_FAST
    /* (the compact code reads none of the buffers) */
    wn.cache = cache;
    wn.r2 = r2;
    wn.key = key;
    wn.med_key = &med_key;
    wn.med_at = &med_at;
    wn.soa = soa;
    wn.exy = exy;
    wn.last = &last;
#endif
    if (!out) {
        return GS_EINVAL;
    }
    empty_result(out, 0, GS_T_NONE);
    if (!ring || !keep) {
        return GS_EINVAL; /* (an empty window is refused by win_open: fewer than 3 usable samples) */
    }
    wn.keep = keep;
    st = win_open(&wn, ring, first, count);
    if (st == GS_OK) {
        st = fit_window(&wn, method, min_scale_px, out);
    }
    if (st != GS_OK) {
        for (i = 0; i < count; i++) {
            keep_set(keep, i, false);
        }
    }
    /* On success out->n already counts the kept samples: each window fit flags exactly
     * the samples it adds, and the last one decides both. */
    return st;
}
