/* gs_session.h - one person's visit in front of the camera (the kiosk's
 * "stand still, jump, results"). A session opens when a body appears and ends
 * after a long absence, or when after a gap a body of clearly other standing
 * size appears (someone else stepped in); its end reports the visit's
 * stature and jump results. Caller-owned state, no heap. */
#ifndef GS_SESSION_H
#define GS_SESSION_H

#include "gs_event.h"

#define GS_SESSION_REF_N 8u  /* standing frames that fix a session's reference size */

typedef struct {
    int64_t absence_us;      /* no body for this long ends the session */
    gs_real new_body_rel;    /* after a gap, a standing size this far (relative) from the reference: new body */
    int64_t gap_us;          /* an absence at least this long counts as a gap for the size test */

    uint32_t id;             /* last session number, 1-based; 0 before the first */
    bool open;
    int64_t t_start_us, t_seen_us; /* first and last frame with a body */
    bool gap_since_ref;      /* a gap happened since the reference size was fixed */
    float ref_acc[GS_SESSION_REF_N];
    uint32_t ref_n;
    gs_real ref_px;          /* the session's standing size, NaN until ref_n reaches GS_SESSION_REF_N */
    uint32_t odd_run;        /* consecutive standing frames off the reference after a gap */
    uint32_t n_jumps, n_rejected;
    gs_real best_jump_m, sum_jump_m, best_flight_s, sum_flight_s, sum_v_m_s;
    uint32_t n_jump_h, n_v, n_flight_t;  /* jumps with a known jump height / take-off velocity / flight time */
} gs_session;

/* What a frame did to the session (bits). */
#define GS_SESSION_ENDED   0x1u
#define GS_SESSION_STARTED 0x2u

void gs_session_init(gs_session *s, int64_t absence_us, gs_real new_body_rel);
/* One frame: present = a body was detected; stand_px = its standing size when
 * this frame was a still, upright one (NaN otherwise). Returns GS_SESSION_*
 * bits; on ENDED, *end_reason names why ("absence", "new_body"). */
uint32_t gs_session_frame(gs_session *s, int64_t t_us, bool present, gs_real stand_px, const char **end_reason);
/* A flight of this session (accepted or rejected). */
void gs_session_jump(gs_session *s, const gs_ev_jump *j);
/* Fill a GS_EV_SESSION event for the open session; stature from the caller's aggregate. */
void gs_session_event(const gs_session *s, bool ended, const char *reason, const gs_ev_height *stature,
                      uint32_t track, gs_event *ev);
/* Close the books of the open session (after its end event was emitted). */
void gs_session_close(gs_session *s);

#endif
