/* gs_ring.c - fixed-capacity ring of gs_sample in caller storage, addressed by
 * absolute sample index (head keeps counting past the capacity). */
#include "gravscale/gs_ring.h"

gs_status gs_ring_init(gs_ring *r, gs_sample *storage, uint32_t capacity)
{
    if (!r || !storage || capacity < 8u || (capacity & (capacity - 1u)) != 0u) {
        return GS_EINVAL;
    }
    r->buf = storage;
    r->capacity = capacity;
    r->mask = capacity - 1u;
    r->head = 0;
    return GS_OK;
}

void gs_ring_push(gs_ring *r, const gs_sample *s)
{
    if (!r || !s || !r->buf) {
        return;
    }
    /* The mask maps the absolute index to its slot; the oldest slot is simply reused. */
    r->buf[(uint32_t)(r->head & r->mask)] = *s;
    r->head++;
}

uint64_t gs_ring_oldest(const gs_ring *r)
{
    if (!r) {
        return 0;
    }
    return r->head > r->capacity ? r->head - r->capacity : 0;
}

uint64_t gs_ring_head(const gs_ring *r)
{
    return r ? r->head : 0;
}

uint32_t gs_ring_count(const gs_ring *r)
{
    if (!r) {
        return 0;
    }
    return (uint32_t)(r->head - gs_ring_oldest(r));
}

const gs_sample *gs_ring_at(const gs_ring *r, uint64_t i)
{
    if (!r || !r->buf || i >= r->head || i < gs_ring_oldest(r)) {
        return NULL;
    }
    return &r->buf[(uint32_t)(i & r->mask)];
}
