/* gs_ring.c - fixed-capacity ring of packed 16-byte samples in caller storage,
 * addressed by absolute sample index (head keeps counting past the capacity). */
#ifdef __OPTIMIZE_SIZE__
#define GS_RING_DEFINE  /* the accessors' one out-of-line copy (gs_ring.h) */
#endif
#include "gravscale/gs_ring.h"

#include <math.h>

#define SIZE_FINE_Q 0x8000u      /* codes below: 1/16 px steps */
#define SIZE_FINE_PX 2048.0f     /* ... up to here, then 1/4 px steps */
#define SIZE_UNKNOWN 0xFFFFu
#define UPRIGHT_STEPS 250.0f
#define UPRIGHT_UNKNOWN 255u

gs_status gs_ring_init(gs_ring *r, gs_sample *storage, uint32_t capacity)
{
    if (!r || !storage || capacity < 8u || (capacity & (capacity - 1u)) != 0u) {
        return GS_EINVAL;
    }
    r->buf = storage;
    r->capacity = capacity;
    r->mask = capacity - 1u;
    r->head = 0;
    r->valid_from = 0;
    r->t_last_us = GS_T_NONE;
    r->last_up_x = NAN;
    r->last_up_y = NAN;
    return GS_OK;
}

static uint16_t size_pack(float size_px)
{
    if (!(size_px >= 0.0f)) {
        return SIZE_UNKNOWN;
    }
    if (size_px < SIZE_FINE_PX - 1.0f / 32.0f) {
        return (uint16_t)(size_px * 16.0f + 0.5f);
    }
    /* size_px >= SIZE_FINE_PX - 1/32 (exact differences near it): q >= 0.375 */
    float q = (size_px - SIZE_FINE_PX) * 4.0f + 0.5f;
    /* larger than any sensor: unknown rather than a wrong number */
    if (!(q < (float)(SIZE_UNKNOWN - SIZE_FINE_Q))) {
        return SIZE_UNKNOWN;
    }
    return (uint16_t)(SIZE_FINE_Q + (uint32_t)q);
}

float gs_sample_size_px(const gs_sample *s)
{
    uint32_t q = s->size_q;
    if (q == SIZE_UNKNOWN) {
        return NAN;
    }
    if (q < SIZE_FINE_Q) {
        return (float)q / 16.0f;
    }
    return SIZE_FINE_PX + (float)(q - SIZE_FINE_Q) / 4.0f;
}

static uint8_t w_pack(float w)
{
    if (!(w > 0.0f)) {
        return 0;
    }
    if (!(w < 1.0f)) {
        return 255;
    }
    uint32_t q = (uint32_t)(w * 255.0f + 0.5f);
    return (uint8_t)(q == 0u ? 1u : q);  /* a usable frame stays usable */
}

static uint8_t upright_pack(float u)
{
    if (isnan(u)) {
        return UPRIGHT_UNKNOWN;
    }
    if (u <= 0.0f) {
        return 0;
    }
    if (u >= 1.0f) {
        return (uint8_t)UPRIGHT_STEPS;
    }
    /* floored: u >= 0.7 exactly when the code is >= 175 */
    return (uint8_t)(u * UPRIGHT_STEPS);
}

float gs_sample_upright(const gs_sample *s)
{
    return s->upright_q == UPRIGHT_UNKNOWN ? NAN : (float)s->upright_q / UPRIGHT_STEPS;
}

gs_status gs_ring_push(gs_ring *r, const gs_sample_full *s)
{
    if (!r || !s || !r->buf || !gs_time_ok(s->t_us)) {
        return GS_EINVAL;
    }
    if (s->t_us < r->t_last_us) {  /* (GS_T_NONE before the first: the lowest int64) */
        return GS_EORDER;
    }
    gs_ring_store(r, s);
    return GS_OK;
}

void gs_ring_store(gs_ring *r, const gs_sample_full *s)
{
    int64_t t = s->t_us;
    uint32_t head = (uint32_t)r->head;  /* (slots from the low 32 bits of the index) */
    uint32_t held = (uint32_t)(r->head - r->valid_from);  /* at most the capacity */
    /* t - newest as uint64: exact for any two accepted times (up to 2^63); at least 2^62
     * before the first sample (GS_T_NONE, the lowest int64), when nothing is held */
    if ((uint64_t)t - (uint64_t)r->t_last_us >= (uint64_t)GS_RING_SPAN_US) {
        held = 0;  /* everything held is too old to tell apart after a wrap */
    }
    /* a full ring overwrites its oldest sample (the capacity newest stay held), and the
     * samples that reached the span leave: ages are exact below 2^32 us (the newest is
     * less than 2^31 us old), and never grow from one sample to the next */
    uint32_t lo = (uint32_t)(uint64_t)t;
    while (held > 0u && (held >= r->capacity ||
                         (uint32_t)(lo - r->buf[(head - held) & r->mask].t_us) >= (uint32_t)GS_RING_SPAN_US)) {
        held--;
    }
    r->valid_from = r->head - held;
    gs_sample *d = &r->buf[head & r->mask];
    d->t_us = (uint32_t)(uint64_t)t;  /* modulo 2^32: read back relative to the newest */
    d->x_px = s->x_px;
    d->y_px = s->y_px;
    d->size_q = size_pack(s->size_px);
    d->w_q = w_pack(s->w);
    d->upright_q = upright_pack(s->upright);
    r->t_last_us = t;
    r->last_up_x = s->up_x;
    r->last_up_y = s->up_y;
    r->head++;
}

bool gs_ring_get(const gs_ring *r, uint64_t i, gs_sample_full *out)
{
    const gs_sample *s = gs_ring_at(r, i);
    if (!s || !out) {
        return false;
    }
    out->t_us = gs_ring_sample_t_us(r, s);
    out->x_px = s->x_px;
    out->y_px = s->y_px;
    out->w = gs_sample_w(s);
    out->size_px = gs_sample_size_px(s);
    bool newest = i + 1u == r->head;
    out->up_x = newest ? r->last_up_x : NAN;
    out->up_y = newest ? r->last_up_y : NAN;
    out->upright = gs_sample_upright(s);
    return true;
}
