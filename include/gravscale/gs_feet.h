/* gs_feet.h - when the feet leave the floor and meet it again, sub-frame, from two foot
 * keypoints per frame (the toes of BlazePose-33, the ankles of COCO-17), streaming.
 *
 * Each point's height along the image's up direction is followed. While it rests (still
 * for GS_FEET_REST_US) its floor level is learnt; it lifts when it rises `delta` above that
 * level (the height the point stands above its rest at the instant the foot leaves: a toe
 * rolls up on its tip, an ankle rides a plantarflexed foot) and the crossing is
 * interpolated between the frames around it. A touch is the mirror image: for toes where
 * the falling point is stopped by the floor (its level then known from the stop; the
 * instant from its speed in the air below the last frame surely above the floor, as the
 * interval around the impact mixes the fall with the standstill), for ankles where the
 * falling point passes its take-off level again (the heel comes down only later). The latest lifts and touches are kept with their levels for the flight
 * module, which picks those around each flight (gs_feet_takeoff, gs_feet_landing).
 * No heap; about 200 bytes. */
#ifndef GS_FEET_H
#define GS_FEET_H

#include "gs_types.h"
#include "gs_time.h"

#define GS_FEET_POINTS 2   /* left and right */
#define GS_FEET_HIST 10    /* frames of history per point (the stillness lag and the crossings; two wait) */
#define GS_FEET_LOG 2      /* lifts and touches kept per point */
#define GS_FEET_REST_US 100000  /* still this long: resting on the floor */
#define GS_FEET_SINK_REL 0.05f  /* a floor this x stature below the last one is a lower floor (a box's height) */

typedef struct {
    int64_t t_us;              /* GS_T_NONE: empty */
    float level_px;            /* the floor it left (lift) or met (touch) */
    float from_px;             /* touch: the floor it had rested on before (a lift's is not set) */
} gs_feet_event;

typedef struct {
    float u_px[GS_FEET_HIST];  /* heights along up, NaN missing (slot 2 + k: k frames before the newest examined;
                                * NaN for k at or past the frames held) */
    float rest_px;             /* current floor level, NaN unknown */
    float floor_px;            /* the level it last rested on long enough (armed), NaN none */
    uint32_t rest_for_us;      /* how long it has rested so far (0: not resting) */
    int64_t rested_from_us, rested_to_us; /* the latest run of frames on the floor (gs_feet_resting_at) */
    int64_t sank_us;           /* the latest frame it was well below the floor it had rested on, GS_T_NONE none */
    uint16_t rest_n;           /* samples averaged into rest_px (counted up to 32) */
    uint8_t armed;             /* rested long enough, at or near its level: a rise is a lift */
    uint8_t lift_pending;      /* armed and above its lift level last frame: a lift if this one is too */
    uint8_t lifted;            /* lifted and not back yet (for the recrossing touch) */
    uint8_t touch_unsure;      /* the newest touch awaits frames that stay at its level (1: a stop, 2: a recrossing) */
    uint8_t falling;           /* falling fast in the newest frame after a recrossing (then in the air, not on a heel) */
    float low_px;              /* its lowest height since its latest lift, NaN before one */
    float noise_px;            /* its jitter (1 sigma) while still, 0 unknown */
    gs_feet_event lift[GS_FEET_LOG], touch[GS_FEET_LOG];  /* newest first */
} gs_foot;

typedef struct {
    uint32_t t_us[GS_FEET_HIST];/* frame times of the history slots, microseconds modulo 2^32 */
    uint32_t n;                 /* frames examined, counted up to the GS_FEET_HIST - 2 held */
    uint8_t pending;            /* the newest frame waits for the next (outlier test) */
    int64_t pend_t_us;          /* its time (once examined, t_last_us; GS_T_NONE before a frame) */
    float pend_size_px;         /* its body size */
    int64_t t_last_us, t_prev_us; /* the newest frame's time and the one before, whole */
    int64_t unseen_us;          /* the latest frame with a point missing, GS_T_NONE none */
    float up_x, up_y;           /* direction the heights are measured along */
    uint16_t epoch;             /* counts the changes of that direction (levels of one epoch compare) */
    bool stop_touch;            /* touch where the point stops (toes), else where it recrosses (ankles) */
    float delta_rel;            /* lift at the instant of leaving, x stature */
    gs_foot pt[GS_FEET_POINTS];
} gs_feet;

/* delta_rel: the point's height above its rest when the foot leaves, as a fraction of
 * stature; stop_touch: see above (a build with one skeleton layout, gs_features.h, has its
 * touch only: by the stop without COCO-17, by the recrossing without BlazePose-33). */
void gs_feet_init(gs_feet *ft, float delta_rel, bool stop_touch);
/* One frame: the two points' image positions x_px[i], y_px[i] (NaN missing), the up
 * direction (unit) and the body's size in px (stature; NaN unknown: the frame is skipped).
 * A change of up by more than about a degree forgets the levels (they were measured along
 * the old direction). Frames must come in time order, less than 35 min apart. Each frame is
 * examined when the next arrives (a lone outlier is told by its neighbours): events lag
 * one frame; gs_feet_flush examines the last. */
void gs_feet_push(gs_feet *ft, int64_t t_us, const float x_px[GS_FEET_POINTS],
                  const float y_px[GS_FEET_POINTS], gs_real up_x, gs_real up_y, gs_real size_px);
/* The stream ends (or pauses): examine the frame that waits for the next. */
void gs_feet_flush(gs_feet *ft);
/* The take-off: both points' last lifts in [from_us, to_us), neither back on the floor
 * before the other left; the later of the two, their mean floor level in *level_px.
 * GS_T_NONE when not both lifted there. */
int64_t gs_feet_takeoff(const gs_feet *ft, int64_t from_us, int64_t to_us, float *level_px);
/* The landing: the earliest touch in (from_us, to_us], the floor level it met in *level_px
 * and the one that point had rested on before in *before_px. GS_T_NONE when none. */
int64_t gs_feet_landing(const gs_feet *ft, int64_t from_us, int64_t to_us, float *level_px, float *before_px);
/* Was a point on the floor at t_us: resting still, or a toe not yet risen clear of its floor
 * (ankles ride up and down on a plantarflexed foot: only resting counts)? */
bool gs_feet_resting_at(const gs_feet *ft, int64_t t_us);
/* Did a point sink well below the floor it had rested on (GS_FEET_SINK_REL x stature: a
 * step or a fall to a lower floor, which no jump does) at or after t_us? */
bool gs_feet_sank_since(const gs_feet *ft, int64_t t_us);
/* Is a point in the air (lifted and not yet back, or an ankle's recrossing not yet settled)? */
bool gs_feet_airborne(const gs_feet *ft);
/* The lowest height of the points since their latest lifts (NaN when none lifted). */
float gs_feet_low_px(const gs_feet *ft);
/* Were both points seen in every frame since t_us (and before it)? */
bool gs_feet_seen_since(const gs_feet *ft, int64_t t_us);
/* The floor the feet rest on now (the mean of the resting points' levels), NaN when neither rests. */
float gs_feet_floor_px(const gs_feet *ft);

#endif
