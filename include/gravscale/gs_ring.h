/* gs_ring.h - fixed-capacity ring of 16-byte gs_sample in caller storage. Oldest
 * samples are overwritten when full; absolute sample indices keep counting so
 * that a flight window can be addressed as [first, first+count). Times are kept
 * as their microseconds modulo 2^32 and read back relative to the newest
 * sample's (kept whole), so the 32-bit field may wrap
 * (every 71.6 min) at any point: the ring holds only samples less than
 * GS_RING_SPAN_US older than the newest (older ones leave it as if
 * overwritten), and a time difference inside it is always exact. */
#ifndef GS_RING_H
#define GS_RING_H

#include "gs_types.h"
#include "gs_time.h"

/* Samples this much older than the newest leave the ring (2^31 us = 35.8 min). */
#define GS_RING_SPAN_US 2147483648LL

typedef struct {
    gs_sample *buf;
    uint32_t capacity;   /* power of two */
    uint32_t mask;
    uint64_t head;       /* absolute index of the next sample to write */
    uint64_t valid_from; /* the oldest held: samples before it were overwritten or fell out of the time span */
    int64_t t_last_us;   /* newest sample's time, GS_T_NONE before the first */
    float last_up_x, last_up_y;  /* newest sample's body axis (not kept per sample) */
} gs_ring;

/* Compile-time helper for static storage: GS_RING_STORAGE(name, 512). */
#define GS_RING_STORAGE(name, cap) \
    _Static_assert(((cap) & ((cap) - 1)) == 0 && (cap) >= 8, "ring capacity must be a power of two >= 8"); \
    static gs_sample name[(cap)]

/* capacity must be a power of two >= 8. */
gs_status gs_ring_init(gs_ring *r, gs_sample *storage, uint32_t capacity);
/* Store s (packed). GS_EINVAL: NULL or a time that is not gs_time_ok (GS_T_NONE,
 * beyond GS_T_MAX_US); GS_EORDER: s is older than the newest sample (an equal
 * time is stored). */
gs_status gs_ring_push(gs_ring *r, const gs_sample_full *s);
/* gs_ring_push without its checks, for a caller that made them (r initialised, s->t_us
 * gs_time_ok and not older than the newest sample). */
void gs_ring_store(gs_ring *r, const gs_sample_full *s);

/* The accessors below are read per sample by the fits and the flight: inline where
 * the build optimises for speed (hosts), one out-of-line copy in gs_ring.c where it
 * optimises for size (-Os: the firmware, whose code budget every call site would cost). */
#ifdef __OPTIMIZE_SIZE__
uint64_t gs_ring_oldest(const gs_ring *r);
uint64_t gs_ring_head(const gs_ring *r);
uint32_t gs_ring_count(const gs_ring *r);
const gs_sample *gs_ring_at(const gs_ring *r, uint64_t i);
int64_t gs_ring_sample_t_us(const gs_ring *r, const gs_sample *s);
float gs_sample_w(const gs_sample *s);
#endif
#if !defined(__OPTIMIZE_SIZE__) || defined(GS_RING_DEFINE)
#ifdef GS_RING_DEFINE
#define GS_RING_FN
#else
#define GS_RING_FN static inline
#endif
/* Absolute index of the oldest sample still held (== head when empty). */
GS_RING_FN uint64_t gs_ring_oldest(const gs_ring *r)
{
    return r ? r->valid_from : 0;
}

GS_RING_FN uint64_t gs_ring_head(const gs_ring *r)
{
    return r ? r->head : 0;
}

GS_RING_FN uint32_t gs_ring_count(const gs_ring *r)
{
    return r ? (uint32_t)(r->head - gs_ring_oldest(r)) : 0u;
}

/* Packed sample at absolute index i, NULL when i is not held any more (or not yet). */
GS_RING_FN const gs_sample *gs_ring_at(const gs_ring *r, uint64_t i)
{
    /* (a ring gs_ring_init did not set up holds nothing: zeroed, head is 0) */
    if (!r || i >= r->head || i < gs_ring_oldest(r)) {
        return NULL;
    }
    return &r->buf[(uint32_t)(i & r->mask)];
}

/* Absolute time of a held sample (s from gs_ring_at of the same ring): held samples
 * are less than 2^31 us older than the newest, so the modular difference is their
 * exact age, across any wrap of the 32-bit field. */
GS_RING_FN int64_t gs_ring_sample_t_us(const gs_ring *r, const gs_sample *s)
{
    uint32_t age = (uint32_t)(uint64_t)r->t_last_us - s->t_us;
    return r->t_last_us - (int64_t)age;  /* the time that was pushed: no overflow */
}

GS_RING_FN float gs_sample_w(const gs_sample *s)
{
    return (float)s->w_q / 255.0f;
}
#undef GS_RING_FN
#endif

/* Sample i unpacked into *out; false (out untouched) when not held. */
bool gs_ring_get(const gs_ring *r, uint64_t i, gs_sample_full *out);
float gs_sample_size_px(const gs_sample *s);  /* NaN unknown */
float gs_sample_upright(const gs_sample *s);  /* NaN unknown */

#endif
