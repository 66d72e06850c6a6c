/* gs_event.h - what the core reports. Unknown values are NaN, unknown times GS_T_NONE
 * (both emitted as null). Times are microseconds (gs_time.h), printed as seconds. */
#ifndef GS_EVENT_H
#define GS_EVENT_H

#include "gs_types.h"
#include "gs_time.h"

typedef enum {
    GS_EV_START = 0, /* written by the program that owns the source (it knows the fps) */
    GS_EV_JUMP,      /* one flight, accepted or rejected */
    GS_EV_HEIGHT,    /* running aggregate after each accepted flight */
    GS_EV_SUMMARY,   /* end of stream: the run's final answer */
    GS_EV_SESSION,   /* a person's visit started or ended (body layouts) */
    GS_EV_WARNING,   /* guidance: a condition started (camera moved, body left the frame); from the front end */
    GS_EV_STATE,     /* trace: state machine change */
    GS_EV_SAMPLE,    /* trace: one COM sample */
    GS_EV_FIT        /* trace: one fit attempt (window and result) */
} gs_event_type;

typedef enum {
    GS_REJ_NONE = 0,
    GS_REJ_FEW_SAMPLES,     /* "few_samples" */
    GS_REJ_LARGE_RESIDUAL,  /* "large_residual" */
    GS_REJ_IMPLAUSIBLE_A,   /* "implausible_acceleration" */
    GS_REJ_NO_SIZE,         /* "no_size": no standing pixel size known around the flight */
    GS_REJ_UNCERTAIN_A,     /* "uncertain_acceleration": relative SE of a too large */
    GS_REJ_GAP,             /* "gap": frames missing inside the flight */
    GS_REJ_OTHER_MOTION,    /* "other_motion": from the front end: something else moved beside the body through much of the flight */
    GS_REJ_NOT_PLANAR,      /* "not_planar": from the front end: the acceleration changes along the flight (camera tilted toward the fall, motion in depth) */
    GS_REJ_GRAVITY_DIR,     /* "gravity_direction": the fitted gravity disagrees with the standing body's axis or earlier flights beyond its standard error */
    GS_REJ_FALL,            /* "fall": landed on a floor lower than it left (a step off a box): a free fall, not a jump */
    GS_REJ_NO_FEET_FLIGHT   /* "no_feet_flight": the feet, seen throughout, did not leave the floor together and land around the COM's flight */
} gs_reject_reason;

/* warning bits of a jump */
#define GS_WARN_FEW_SAMPLES   0x01u /* "few_samples": accepted but short */
#define GS_WARN_GRAVITY_TILT  0x02u /* "gravity_tilt": fitted gravity direction far from the body axis / previous flights */
#define GS_WARN_SIZE_CHANGED  0x04u /* "size_changed": standing size before and after differ */
#define GS_WARN_OUTLIERS      0x08u /* "outliers": many samples rejected by the robust fit */
#define GS_WARN_CLIPPED       0x10u /* "edge_truncated": flight window cut by a gap or the stream's end */
/* set by the front end that owns the frames (the core cannot see them) */
#define GS_WARN_CAMERA_MOVED  0x20u /* "camera_moved": the background moved during the flight (not a static camera) */
#define GS_WARN_LEFT_FRAME    0x40u /* "left_frame": the body touched the frame's border during the flight */
#define GS_WARN_OUT_OF_PLANE  0x80u /* "out_of_plane": the body moved toward or away from the camera */
#define GS_WARN_OTHER_MOTION  0x100u /* "other_motion": something else moved right beside the body during the flight */
/* set by the core (body layouts) */
#define GS_WARN_NO_SIZE       0x200u /* "no_size": no standing size known: the flight is measured, its height unknown */
#define GS_WARN_DEPTH_CHANGED 0x400u /* "depth_changed": the body stood elsewhere (its feet on another floor row): height left out */
#define GS_WARN_COM_TIMED     0x800u /* "com_timed": the feet were not seen leaving or meeting the floor: times from the COM alone */
#define GS_WARN_COM_MISMATCH  0x1000u /* "com_mismatch": the COM at landing sits far from its height at take-off (posture or timing) */

const char *gs_reject_reason_name(gs_reject_reason r);

typedef struct {
    const char *version;
    const char *config;       /* config file name or "default" */
    gs_real fps_source;       /* NaN unknown */
    const char *fps_origin;   /* "timestamps", "container", "metadata", "cli", ... or NULL */
    const char *layout;       /* layout name or NULL */
} gs_ev_start;

typedef struct {
    uint32_t track;           /* 0 unless several objects are tracked */
    uint32_t index;           /* 0-based flight counter of the run */
    int64_t t_takeoff_us, t_land_us, t_apex_us;  /* GS_T_NONE unknown */
    gs_real flight_time_s;
    gs_real a_px_s2, a_px_se_s2, g_dir_deg, q_m_per_px;
    gs_real size_px;          /* pixel size used (standing stature, ball diameter) */
    gs_real height_m, height_se_m;
    gs_real jump_height_m;    /* g T^2 / 8 from the flight time (contact mats, apps) */
    gs_real takeoff_velocity_m_s;  /* the COM's vertical speed at take-off, g (t_apex - t_takeoff) */
    gs_real com_rise_m;       /* the COM's rise from take-off to the apex, v0^2 / 2g (force plates) */
    gs_real contact_time_s;   /* ground contact before this take-off since the last landing (drop and repeated jumps), NaN none */
    gs_real rsi;              /* reactive strength index: jump_height_m / contact_time_s, NaN none */
    uint32_t n_samples, n_outliers;
    gs_real rms_px;
    bool accepted;
    gs_reject_reason reason;
    uint32_t warnings;        /* GS_WARN_* bits */
} gs_ev_jump;

typedef struct {
    uint32_t track;
    gs_real height_m, ci95_lo_m, ci95_hi_m;
    uint32_t n_jumps, n_rejected;
} gs_ev_height;  /* also the summary */

typedef struct {
    uint32_t track;
    uint32_t session;          /* 1-based visit number */
    bool ended;                /* false: it started */
    const char *reason;        /* end: "absence", "new_body", "end_of_stream"; NULL at the start */
    int64_t t_start_us, t_end_us; /* t_end_us GS_T_NONE at the start */
    gs_real stature_m, ci95_lo_m, ci95_hi_m;   /* the visit's aggregate, NaN unknown */
    uint32_t n_jumps, n_rejected;
    gs_real best_jump_m, mean_jump_m, best_flight_s, mean_flight_s, mean_takeoff_velocity_m_s;
} gs_ev_session;

typedef struct {
    uint32_t track;
    int64_t t_us;
    uint32_t warnings;         /* GS_WARN_* bits that started at t_us */
} gs_ev_warning;

typedef struct {
    int64_t t_us;
    const char *from, *to;
} gs_ev_state;

typedef struct {
    int64_t t_us;
    float x_px, y_px, w, size_px, upright;
} gs_ev_sample;

typedef struct {
    int64_t t_first_us, t_last_us;
    uint32_t n;
    gs_real a_px_s2, g_dir_deg, rms_px;
    const char *purpose;      /* e.g. "flight", "extend", "final" */
} gs_ev_fit;

typedef struct {
    gs_event_type type;
    union {
        gs_ev_start start;
        gs_ev_jump jump;
        gs_ev_height height;   /* GS_EV_HEIGHT and GS_EV_SUMMARY */
        gs_ev_session session;
        gs_ev_warning warning;
        gs_ev_state state;
        gs_ev_sample sample;
        gs_ev_fit fit;
    } u;
} gs_event;

#endif
