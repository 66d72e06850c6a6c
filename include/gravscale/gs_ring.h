/* gs_ring.h - fixed-capacity ring of gs_sample in caller storage. Oldest samples
 * are overwritten when full; absolute sample indices keep counting so that a
 * flight window can be addressed as [first, first+count). */
#ifndef GS_RING_H
#define GS_RING_H

#include "gs_types.h"

typedef struct {
    gs_sample *buf;
    uint32_t capacity;   /* power of two */
    uint32_t mask;
    uint64_t head;       /* absolute index of the next sample to write */
} gs_ring;

/* Compile-time helper for static storage: GS_RING_STORAGE(name, 512). */
#define GS_RING_STORAGE(name, cap) \
    _Static_assert(((cap) & ((cap) - 1)) == 0 && (cap) >= 8, "ring capacity must be a power of two >= 8"); \
    static gs_sample name[(cap)]

/* capacity must be a power of two >= 8. */
gs_status gs_ring_init(gs_ring *r, gs_sample *storage, uint32_t capacity);
void gs_ring_push(gs_ring *r, const gs_sample *s);
/* Absolute index of the oldest sample still held (== head when empty). */
uint64_t gs_ring_oldest(const gs_ring *r);
uint64_t gs_ring_head(const gs_ring *r);
uint32_t gs_ring_count(const gs_ring *r);
/* Sample at absolute index i, NULL when i is not held any more (or not yet). */
const gs_sample *gs_ring_at(const gs_ring *r, uint64_t i);

#endif
