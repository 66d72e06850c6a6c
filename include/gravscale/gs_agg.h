/* gs_agg.h - robust running aggregate of per-flight sizes: the median, with a
 * 95 % interval that combines each flight's standard error and the spread
 * between flights, honest with one flight as with ten. Bounded memory: the
 * newest GS_AGG_MAX accepted flights are kept. */
#ifndef GS_AGG_H
#define GS_AGG_H

#include "gs_event.h"

#define GS_AGG_MAX 64

typedef struct {
    float value[GS_AGG_MAX];  /* per-flight size, metres; slots [0, held) in use */
    float se[GS_AGG_MAX];     /* its standard error, metres */
    uint32_t held, next;      /* slots in use (up to GS_AGG_MAX), the next one to write */
    uint32_t n_accepted, n_rejected;
} gs_agg;

void gs_agg_init(gs_agg *a);
void gs_agg_add(gs_agg *a, gs_real value_m, gs_real se_m);
void gs_agg_reject(gs_agg *a);
/* Fill height_m, ci95_lo_m, ci95_hi_m, n_jumps, n_rejected; NaN when nothing accepted. */
void gs_agg_get(const gs_agg *a, gs_ev_height *out);

#endif
