/* gs_median.h - the median of a few values (private to the core's files). */
#ifndef GS_MEDIAN_H
#define GS_MEDIAN_H

#include "gravscale/gs_types.h"

/* v[0..n) (n >= 1) sorted ascending in place, and its median */
gs_real gs_sort_median(gs_real *v, uint32_t n);

#if !defined(__OPTIMIZE_SIZE__) && defined(__GNUC__) && defined(__x86_64__)
/* x86-64 hosts: x < y ? x : y and x > y ? x : y as minss/maxss, which they are bit for
 * bit (GCC may turn a median's compare-and-swap into a branch that noisy data mispredicts) */
static inline float gs_min_f(float x, float y) { __asm__("minss %1, %0" : "+x"(x) : "x"(y)); return x; }
static inline float gs_max_f(float x, float y) { __asm__("maxss %1, %0" : "+x"(x) : "x"(y)); return x; }
static inline double gs_min_d(double x, double y) { __asm__("minsd %1, %0" : "+x"(x) : "x"(y)); return x; }
static inline double gs_max_d(double x, double y) { __asm__("maxsd %1, %0" : "+x"(x) : "x"(y)); return x; }
#else
static inline float gs_min_f(float x, float y) { return x < y ? x : y; }
static inline float gs_max_f(float x, float y) { return x > y ? x : y; }
static inline double gs_min_d(double x, double y) { return x < y ? x : y; }
static inline double gs_max_d(double x, double y) { return x > y ? x : y; }
#endif

/* *a, *b in ascending order: gs_min_*(*b, *a) and gs_max_*(*a, *b), so a NaN leaves both */
#ifdef __OPTIMIZE_SIZE__
/* (a swap on one compare: the min and max would compare the pair twice) */
static inline void gs_order_f(float *a, float *b)
{
    if (*a > *b) {
        float t = *a;
        *a = *b;
        *b = t;
    }
}

static inline void gs_order_d(double *a, double *b)
{
    if (*a > *b) {
        double t = *a;
        *a = *b;
        *b = t;
    }
}
#else
/* (no branch for noisy data to mispredict) */
static inline void gs_order_f(float *a, float *b)
{
    float lo = gs_min_f(*b, *a);
    *b = gs_max_f(*a, *b);
    *a = lo;
}

static inline void gs_order_d(double *a, double *b)
{
    double lo = gs_min_d(*b, *a);
    *b = gs_max_d(*a, *b);
    *a = lo;
}
#endif

/* the median of three (a NaN gives what a compare-and-swap sort of a, b, c would) */
static inline float gs_med3_f(float a, float b, float c)
{
    gs_order_f(&a, &b);
    return gs_max_f(a, gs_min_f(c, b));
}

static inline double gs_med3_d(double a, double b, double c)
{
    gs_order_d(&a, &b);
    return gs_max_d(a, gs_min_d(c, b));
}

#endif
