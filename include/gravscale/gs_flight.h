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
#include "gs_feet.h"

typedef enum {
    GS_FS_IDLE = 0,   /* no reliable samples yet / lost */
    GS_FS_GROUND,     /* on the ground (standing or moving) */
    GS_FS_AIRBORNE    /* a flight candidate is open */
} gs_flight_state;

const char *gs_flight_state_name(gs_flight_state s);

#define GS_STAND_KEEP 32  /* standing size samples kept for the size estimate */

/* The flight's sample indices are 32-bit offsets from a 64-bit base, which moves up once
 * the ring's head is twice this past it (the ring must hold fewer samples than this).
 * GS_NO_IDX: no sample. */
#ifndef GS_FLIGHT_IDX_KEEP
#define GS_FLIGHT_IDX_KEEP (1u << 30)
#endif
#define GS_NO_IDX UINT32_MAX

/* Times inside the flight's window (names ending _lus) are int32 microseconds from a
 * 64-bit base (gs_flight.tb_us) 2^27 us before the ring's newest sample, set when the
 * samples are examined (a close keeps the base it began with: no sample is examined
 * while it is pending). Held samples are less than 2^31 us older than the newest, so each
 * one's local time is exact, and so is a time up to 2^27 us beyond them. GS_LT_NONE: none. */
#define GS_LT_NONE INT32_MIN
/* configured spans (gaps, flight lengths, latency) beyond this (67 s; the config checks
 * allow at most 5 s) are refused: a span of local times is then exact in 32 bits */
#define GS_FLIGHT_SPAN_MAX_US (1 << 26)

typedef void (*gs_event_fn)(void *ctx, const gs_event *ev);

/* Frames a flight's close may spread over, one robust fit or boundary search a frame (and
 * at most 60 ms): the flight module then lags the stream by that many frames and holds
 * their feet (GS_FEET_POINTS points, the size and the time: 32 B a frame). 0: every close
 * runs whole in its landing's frame (the firmware: its state budget has no room for the lag). */
#ifndef GS_CLOSE_LAG_FRAMES
#define GS_CLOSE_LAG_FRAMES 8
#endif

#if GS_CLOSE_LAG_FRAMES > 0
/* The last robust fit of a decision (gs_flight.c): the same window fitted again gets its result */
typedef struct {
    bool valid;
    uint32_t first, count;
    float min_scale;
    gs_fit_method method;
    gs_status st;
    gs_fit_result r;
} gs_fit_memo;
#endif

/* A flight's close in steps, each bounded: one robust fit or the boundary search */
typedef enum {
    GS_CLOSE_NONE = 0,  /* nothing pending */
    GS_CLOSE_REFIT,     /* rebuild the running fit over the flight */
    GS_CLOSE_START,     /* solve it and start the take-off side's walk */
    GS_CLOSE_GROW,      /* the walk (an alarm's refit a step) */
    GS_CLOSE_GROWN,     /* refit the grown flight */
    GS_CLOSE_BOUNDS,    /* the take-off and landing times */
    GS_CLOSE_FINAL,     /* the final fit and the event */
    GS_CLOSE_SEED       /* not a close: a seed's widest core */
} gs_close_stage;

/* A flight's close in progress (or a seed's widest core): where it stands and what its
 * steps pass on. */
typedef struct {
    uint8_t stage;             /* gs_close_stage */
    bool truncated;            /* the flight ended without its landing (a gap, the stream's end) */
    bool feet;                 /* the feet timed the flight (F0_us, F1_us) */
    bool feet_contradict, fell;
    uint32_t newest;           /* the newest sample examined when the flight ended */
    uint32_t head;             /* the ring's head then: contact samples are looked for below it */
    uint32_t right_alarm, left_alarm; /* the contact alarms after and before the flight, GS_NO_IDX none */
    uint32_t walk_i, clean, outliers; /* the take-off side's walk (grow_left) */
    uint32_t in_lo, in_hi;     /* the final fit's samples */
    gs_real cusum;             /* ... the walk's */
    float floor_off_px, floor_on_px, floor_before_px;
    int32_t t_prev_lus;        /* ... the walk's */
    int32_t T0_lus, T1_lus, F0_lus, F1_lus; /* the boundaries */
    gs_fit_result r;           /* the flight's fit as grown */
#if GS_CLOSE_LAG_FRAMES > 0
    uint32_t low;              /* the oldest sample it may read (it must stay in the ring) */
    int64_t t_end_us;          /* the time of the sample newest */
    bool alarm_due;            /* the take-off side's walk stopped at an alarm awaiting its refit */
    uint32_t apex;             /* a seed's apex (GS_CLOSE_SEED: its widest core is tried in a frame of its own) */
    uint8_t width;             /* ... the core width to try */
    /* while it waits: no frame it holds back may be one the standing tracker takes */
    uint32_t checked;          /* the next waiting sample to check */
    uint32_t n_ground;         /* the usable samples among those checked */
    uint32_t dt_q4;            /* the frame interval as the checked samples will leave it */
    int64_t t_last_us;         /* ... and the time of the newest present one */
    int64_t still_after_us;    /* a stillness can only begin after this, GS_T_NONE unknown */
#endif
} gs_close;

#if GS_CLOSE_LAG_FRAMES > 0
typedef struct {               /* a frame's feet (gs_flight_feet) held while a close is pending */
    int64_t t_us;
    float x_px[GS_FEET_POINTS], y_px[GS_FEET_POINTS], size_px;
} gs_feet_frame;
#endif

typedef struct {
    const gs_core_config *cfg;
    const gs_ring *ring;
    uint32_t *keep;            /* ring->capacity bits: the robust fits' inlier flags */
    gs_event_fn on_event;
    void *ctx;
    bool trace;
    bool rigid;                /* object size is measured in every frame (ball), not while standing */
    uint32_t track;            /* reported in every event (several objects: one pipeline each) */
    gs_real g_m_s2;
    /* the configured spans in microseconds (gs_time_us_of_cfg_s; at most GS_FLIGHT_SPAN_MAX_US) */
    int32_t min_flight_us, max_flight_us, max_gap_us, landing_latency_us;

    gs_flight_state state;
    uint64_t base;             /* ring index of offset 0: the indices below are offsets from it */
    int64_t tb_us;             /* time of local 0: the _lus times are microseconds from it */
    uint32_t next;             /* next index to examine */
    uint32_t quiet_from;       /* first index after the last closed candidate */
    int64_t last_t_us;         /* time of the last valid sample, GS_T_NONE none */
    uint32_t last_idx;

    gs_real up_x, up_y;        /* image direction against gravity (unit) */
    uint32_t up_n;             /* body-axis samples averaged into it */
    bool up_from_flight;       /* set from fitted flights (else body axis or image up) */

    gs_real noise_px;          /* robust COM noise (1 axis), from ground phases; NaN until known */
    float noise_init[9];       /* first |second differences| (NOISE_INIT_N; sorted once their median is taken) */
    uint32_t noise_n;
    gs_real u_hist[3];         /* last three u of valid samples (for a median of 3) */
    uint32_t i_hist[3];
    int64_t t_hist_us[3];
    uint32_t n_hist;

    gs_real blk_min_cur, blk_min_prev; /* running minimum of u over the last ~0.5-1 s */
    int64_t blk_t0_us;
    gs_real peak_u;            /* running maximum once the rise is significant */
    uint32_t peak_idx;

    /* the open flight candidate */
    gs_fit fit;                /* streaming fit of the accepted in-flight samples */
    uint32_t fl_first, fl_last;   /* accepted range so far */
    uint32_t seed_idx;
    gs_real cusum;             /* one-sided CUSUM of the deviation against gravity */
    uint32_t pend_ok;          /* bit k: pending sample fl_last+1+k is no gross outlier */
    uint32_t outliers_run;     /* consecutive gross outliers */
    uint32_t dt_med_q4;        /* typical frame interval in 1/16 us, 0 unknown (integer: frame counts are taken from it) */

    float stand_size[GS_STAND_KEEP];
    uint32_t stand_n, stand_next;
    float loose_size[GS_STAND_KEEP]; /* still, roughly upright frames: a fallback */
    uint32_t loose_n, loose_next;
    int64_t stand_last_us;     /* time of the newest standing size, GS_T_NONE none */
    int64_t still_since_us;    /* start of the current still, upright stretch, GS_T_NONE none */

    gs_real last_a_px_s2;      /* last accepted acceleration, NaN none */
    gs_real last_g_dir_deg;
    uint32_t n_flights;

    /* the feet (body layouts): take-off and landing times, the floor, drop jumps */
    bool feet_on;              /* the layout shows feet (gs_flight_use_feet) */
    gs_feet feet;
    float stand_floor_px;      /* the feet's floor level while the kept standing sizes were taken, NaN unknown */
    uint16_t stand_floor_epoch;/* ... measured in this epoch of the feet's direction */
    int64_t last_land_us;      /* the latest landing (of a jump or a fall), GS_T_NONE none */
    int64_t feet_wait_us;      /* the COM landed: wait until then for the feet, GS_T_NONE not waiting */
    uint32_t wait_alarm;       /* ... the contact alarm it landed with */
#if GS_CLOSE_LAG_FRAMES > 0
    gs_close close;            /* the pending close: no sample is examined until it is done */
    gs_fit_memo memo;          /* the last robust fit of the current decision (a close's may span frames) */
    bool close_whole;          /* every close runs whole in its landing's frame */
    gs_feet_frame feet_held[GS_CLOSE_LAG_FRAMES]; /* the feet of the frames since, oldest first */
    uint32_t feet_held_n;
#endif
} gs_flight;

/* A build with a baked profile (src/core/gs_cfg_in.h) refuses any other cfg (GS_EINVAL). */
gs_status gs_flight_init(gs_flight *f, const gs_core_config *cfg, const gs_ring *ring,
                         uint32_t *keep, bool rigid, gs_event_fn on_event, void *ctx);
/* Time flights by the feet: two foot points per frame (gs_flight_feet), lifting delta_rel
 * x stature above their rest when the foot leaves; stop_touch: see gs_feet.h. A build
 * without the point layout (gs_features.h) tracks bodies only and times every flight by the
 * feet: call this after gs_flight_init (gs_pipeline does). */
void gs_flight_use_feet(gs_flight *f, float delta_rel, bool stop_touch);
/* The frame at t_us's two foot points (NaN missing) and the body's size this frame (NaN
 * unknown), before the frame's sample is examined (gs_flight_update). */
void gs_flight_feet(gs_flight *f, int64_t t_us, const float x_px[GS_FEET_POINTS],
                    const float y_px[GS_FEET_POINTS], float size_px);
/* Examine every sample pushed to the ring since the last call. Emits GS_EV_JUMP
 * events through on_event (and trace events when f->trace). Call it once per pushed
 * sample: a pending close takes one step, and the samples wait in the ring (its event
 * leaves up to GS_CLOSE_LAG_FRAMES frames or 60 ms later, the same events in the same order). */
void gs_flight_update(gs_flight *f);
/* The stream pauses longer than the ring's time span (GS_RING_SPAN_US): close
 * an open candidate now, while the ring still holds its samples. */
void gs_flight_break(gs_flight *f);
/* End of stream: close any open candidate. */
void gs_flight_finish(gs_flight *f);
/* The standing size this sample added (NaN when the sample at t_us was no still, upright frame). */
gs_real gs_flight_stand_at(const gs_flight *f, int64_t t_us);
/* Someone else: forget the standing sizes (and the body axis) learnt so far. */
void gs_flight_forget_body(gs_flight *f);

#endif
