/* gs_median.h - the median of a few values (private to the core's files). */
#ifndef GS_MEDIAN_H
#define GS_MEDIAN_H

#include "gravscale/gs_types.h"

/* v[0..n) (n >= 1) sorted ascending in place, and its median */
gs_real gs_sort_median(gs_real *v, uint32_t n);

#endif
