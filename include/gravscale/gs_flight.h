/* gs_flight.h - online flight detection: a state machine over the COM samples
 * in the ring (standing -> moving -> airborne -> landed) that finds every free
 * flight with bounded delay, fits it robustly and reports a jump. */
#ifndef GS_FLIGHT_H
#define GS_FLIGHT_H

#include "gs_types.h"
#include "gs_ring.h"
#include "gs_fit.h"
#include "gs_config.h"
#include "gs_event.h"

typedef enum {
    GS_FS_IDLE = 0,   /* no reliable samples yet / lost */
    GS_FS_GROUND,     /* on the ground (standing or moving) */
    GS_FS_AIRBORNE    /* a flight candidate is open */
} gs_flight_state;

const char *gs_flight_state_name(gs_flight_state s);

#define GS_STAND_KEEP 32  /* standing size samples kept for the size estimate */

typedef void (*gs_event_fn)(void *ctx, const gs_event *ev);

typedef struct {
    const gs_core_config *cfg;
    const gs_ring *ring;
    float *scratch_w;          /* ring->capacity floats */
    gs_event_fn on_event;
    void *ctx;
    bool trace;
    double g_m_s2;

    gs_flight_state state;
    uint64_t cand_first;       /* absolute index of the first sample of the open candidate */
    uint64_t last_seen;        /* next ring index to examine */
    uint64_t quiet_from;       /* index after the last reported flight's landing */

    /* adaptive levels, in the "up" coordinate along -gravity */
    double up_x, up_y;         /* current estimate of the image up direction (unit) */
    bool up_from_flight;       /* estimated from a fitted flight (else body axis / image) */
    double ground_u;           /* adaptive ground (standing) level of the COM along up */
    double noise_px;           /* adaptive COM noise level */
    double size_px_ref;        /* typical object size (for thresholds) */

    float stand_size[GS_STAND_KEEP];
    double stand_t[GS_STAND_KEEP];
    uint32_t stand_n, stand_next;

    double last_a_px_s2;       /* last accepted acceleration, NaN none */
    uint32_t n_flights;
} gs_flight;

gs_status gs_flight_init(gs_flight *f, const gs_core_config *cfg, const gs_ring *ring,
                         float *scratch_w, gs_event_fn on_event, void *ctx);
/* Examine every sample pushed to the ring since the last call. Emits GS_EV_JUMP
 * events through on_event (and trace events when f->trace). */
void gs_flight_update(gs_flight *f);
/* End of stream: close any open candidate. */
void gs_flight_finish(gs_flight *f);

#endif
