/* gs_agg.c - robust running aggregate of per-flight sizes: the median of the
 * newest GS_AGG_MAX accepted flights and a 95 % interval that stays honest
 * from one flight to many. See docs/anthropometry.md ("Aggregate") for the
 * derivation and the Monte Carlo check in tests/test_agg.c.
 * gs_real (float on an M4): the values are floats and the interval is a statistic;
 * hosts (double) keep their results. */
#include <math.h>

#include "gravscale/gs_agg.h"

#include "gs_finite.h"
#include "gs_median.h"

/* With one flight the between-flight scatter cannot be seen; a per-flight
 * relative scatter (pose, size and outlier flights the fit's SE misses) is
 * assumed instead: 3 % of the value, 5 cm at 1.75 m. */
#define SINGLE_FLIGHT_REL_SPREAD GS_R(0.03)

#define MAD_TO_SIGMA GS_R(1.4826) /* 1 / Phi^-1(0.75) */
#define MEDIAN_SE_FACTOR GS_R(1.2533) /* sqrt(pi/2): SE(median) / SE(mean), large n, normal data */

/* Small-sample correction of the MAD (Croux & Rousseeuw 1992), n = 2..9 from
 * k_mad_corr[0]; n / (n - 0.8) beyond. Values from memory of their table. */
static const gs_real k_mad_corr[8] = { 1.196, 1.495, 1.363, 1.206, 1.200, 1.140, 1.129, 1.107 };

/* SE(median) / (sigma / sqrt(n)) for normal data and small n, n = 2..5 from
 * k_median_se[0]: the median of 2 is the mean; exact small-n ratios up to 5, the
 * large-n value beyond. */
static const gs_real k_median_se[4] = { 1.0, 1.160, 1.092, 1.197 };

/* Student-t 97.5 % quantiles by degrees of freedom (whole numbers: a byte each). */
static const uint8_t k_t975_dof[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 12, 15, 20, 30, 40, 60, 120};
static const gs_real k_t975_q[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262,
                                   2.228,  2.179, 2.131, 2.086, 2.042, 2.021, 2.000, 1.980};
#define N_T975 (sizeof k_t975_dof / sizeof k_t975_dof[0])
_Static_assert(sizeof k_t975_q / sizeof k_t975_q[0] == N_T975, "one quantile per dof");

/* t quantile for a real dof >= 1, linear in 1/dof between table rows (exact
 * at the rows, 1.96 at infinity). */
static gs_real t975(gs_real dof)
{
    if (!(dof > GS_R(1.0))) {
        return k_t975_q[0];
    }
    for (size_t i = 1; i < N_T975; i++) {
        if (dof <= (gs_real)k_t975_dof[i]) {
            gs_real a = GS_R(1.0) / (gs_real)k_t975_dof[i - 1], b = GS_R(1.0) / (gs_real)k_t975_dof[i], x = GS_R(1.0) / dof;
            return k_t975_q[i - 1] + (k_t975_q[i] - k_t975_q[i - 1]) * (a - x) / (a - b);
        }
    }
    gs_real b = GS_R(1.0) / (gs_real)k_t975_dof[N_T975 - 1];
    return GS_R(1.96) + (k_t975_q[N_T975 - 1] - GS_R(1.96)) * (GS_R(1.0) / dof) / b;
}

static void sort_asc(gs_real *v, uint32_t n)
{
    for (uint32_t i = 1; i < n; i++) {
        gs_real x = v[i];
        uint32_t j = i;
        while (j > 0 && v[j - 1] > x) {
            v[j] = v[j - 1];
            j--;
        }
        v[j] = x;
    }
}

/* the median of v[0..n) sorted ascending (n >= 1) */
static gs_real median_sorted(const gs_real *v, uint32_t n)
{
    return (n & 1u) ? v[n / 2] : GS_R(0.5) * (v[n / 2 - 1] + v[n / 2]);
}

gs_real gs_sort_median(gs_real *v, uint32_t n)
{
    sort_asc(v, n);
    return median_sorted(v, n);
}

#ifndef __OPTIMIZE_SIZE__
/* The median of |v[i] - med| over v[0..n) sorted ascending: the deviations fall below med
 * and rise above it, two sorted runs merged (in dev) up to the median's rank instead of a
 * sort. The same value as gs_sort_median of them. */
static gs_real median_abs_dev_sorted(const gs_real *v, uint32_t n, gs_real med, gs_real *dev)
{
    uint32_t hi = 0, need = n / 2u + 1u;
    while (hi < n && v[hi] < med) hi++;
    uint32_t lo = hi;  /* v[lo - 1] is the next below med, v[hi] the next at or above it */
    for (uint32_t m = 0; m < need; m++) {
        gs_real below = lo > 0 ? GS_FABSR(v[lo - 1u] - med) : (gs_real)INFINITY;
        gs_real above = hi < n ? GS_FABSR(v[hi] - med) : (gs_real)INFINITY;
        if (below < above) {
            dev[m] = below;
            lo--;
        } else {
            dev[m] = above;
            hi++;
        }
    }
    return median_sorted(dev, n);
}
#endif

void gs_agg_init(gs_agg *a)
{
    if (!a) {
        return;
    }
    /* (value and se need no clearing: only the held slots, which gs_agg_add wrote, are read) */
    a->held = a->next = 0;
    a->n_accepted = a->n_rejected = 0;
}

void gs_agg_add(gs_agg *a, gs_real value_m, gs_real se_m)
{
    if (!a) {
        return;
    }
    /* A flight without a usable size (finite, > 0) was a flight that failed: count it as rejected. */
    if (!(value_m > GS_R(0.0) && gs_finite_r(value_m))) {
        a->n_rejected++;
        return;
    }
    a->value[a->next] = (float)value_m;
    /* finite and >= 0 (-0 included); an unknown SE is kept as NaN */
    bool se_ok = se_m >= GS_R(0.0) && gs_finite_r(se_m);
    a->se[a->next] = se_ok ? (float)se_m : NAN;
    a->next = (a->next + 1u) % GS_AGG_MAX;
    if (a->held < GS_AGG_MAX) {
        a->held++;
    }
    a->n_accepted++;
}

void gs_agg_reject(gs_agg *a)
{
    if (a) {
        a->n_rejected++;
    }
}

void gs_agg_get(const gs_agg *a, gs_ev_height *out)
{
    if (!out) {
        return;
    }
    out->height_m = out->ci95_lo_m = out->ci95_hi_m = NAN;
    out->n_jumps = 0;
    out->n_rejected = 0;
    if (!a) {
        return;
    }
    out->n_jumps = a->n_accepted;
    out->n_rejected = a->n_rejected;
    /* (gs_agg_add counts up to GS_AGG_MAX; clamped still, so a damaged struct cannot overrun v) */
    uint32_t n = a->held < GS_AGG_MAX ? a->held : GS_AGG_MAX;
    if (n == 0) {
        return;
    }

    gs_real v[GS_AGG_MAX];
    gs_real se2_sum = GS_R(0.0);
    uint32_t n_se = 0;
    for (uint32_t i = 0; i < n; i++) {
        v[i] = a->value[i];
        if (!isnan(a->se[i])) {
            se2_sum += (gs_real)a->se[i] * (gs_real)a->se[i];
            n_se++;
        }
    }
    gs_real med = gs_sort_median(v, n);
    out->height_m = med;
    /* the fits' SEs (their RMS: a sum of squares is never NaN), 0 when none is known */
    gs_real se_floor = n_se > 0 ? GS_SQRT(se2_sum / n_se) : GS_R(0.0);

    gs_real half;
    if (n == 1) {
        gs_real tau = SINGLE_FLIGHT_REL_SPREAD * med;
        half = GS_R(1.96) * GS_SQRT(se_floor * se_floor + tau * tau);
    } else {
        /* Between-flight spread: MAD, scaled to a normal sigma, small-sample corrected. */
#ifdef __OPTIMIZE_SIZE__
        for (uint32_t i = 0; i < n; i++) {
            v[i] = GS_FABSR(v[i] - med);  /* in place: the sizes are not read again */
        }
        gs_real mad = gs_sort_median(v, n);
#else
        gs_real dev[GS_AGG_MAX];
        gs_real mad = median_abs_dev_sorted(v, n, med, dev);
#endif
        gs_real corr = n < 10 ? k_mad_corr[n - 2u] : (gs_real)n / ((gs_real)n - GS_R(0.8));
        gs_real spread = MAD_TO_SIGMA * mad * corr;
        /* The fits' SEs are a floor: the spread of a few flights can be small by chance. */
        gs_real sigma = spread > se_floor ? spread : se_floor;
        /* Satterthwaite: only the part of sigma^2 beyond the known SEs is estimated
         * from the n flights (n-1 dof); all of it known -> normal quantile. */
        gs_real excess2 = spread * spread - se_floor * se_floor;
        gs_real q = GS_R(1.96);
        if (excess2 > GS_R(0.0)) {
            gs_real s4 = sigma * sigma * sigma * sigma;
            q = t975((gs_real)(n - 1u) * s4 / (excess2 * excess2));
        }
        gs_real k = n < 6 ? k_median_se[n - 2u] : MEDIAN_SE_FACTOR;
        half = q * k * sigma / GS_SQRT((gs_real)n);
    }
    if (gs_finite_r(half)) {
        out->ci95_lo_m = med - half;
        out->ci95_hi_m = med + half;
    }
}
