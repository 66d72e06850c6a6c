/* gs_com.c - whole-body centre of mass, standing stature in pixels, body axis
 * and an uprightness score from one frame of 2D keypoints (COCO-17 or
 * BlazePose-33). Segment model and landmark ratios: docs/anthropometry.md.
 * Plain C11, no heap, no stdio; float arithmetic for a Cortex-M4 FPU. */
#include <math.h>

#include "gravscale/gs_com.h"

#define DROPPED_SEGMENT_WEIGHT 0.02f /* weight factor of a frame whose COM lacks a whole segment */

/* ---- canonical keypoints (COCO-17 order first, BlazePose extras after) ---- */

enum {
    K_NOSE = 0, K_LEYE, K_REYE, K_LEAR, K_REAR,
    K_LSHO, K_RSHO, K_LELB, K_RELB, K_LWRI, K_RWRI,
    K_LHIP, K_RHIP, K_LKNE, K_RKNE, K_LANK, K_RANK,
    K_LHEEL, K_RHEEL, K_LTOE, K_RTOE,     /* BlazePose 29/30 heels, 31/32 foot index */
    K_LPINKY, K_RPINKY, K_LINDEX, K_RINDEX, /* BlazePose 17/18 pinky, 19/20 index knuckles */
    K_N
};

#if GS_WITH_POSE
/* BlazePose-33 index of each canonical keypoint (eye = the eye centre, 2/5). */
static const uint8_t k_blaze_index[K_N] = {
    0, 2, 5, 7, 8,
    11, 12, 13, 14, 15, 16,
    23, 24, 25, 26, 27, 28,
    29, 30, 31, 32,
    17, 18, 19, 20
};
#endif

/* ---- segment tables --------------------------------------------------------- */

typedef struct {
    float mass_pct[GS_SEG_COUNT]; /* published % of body mass, one side for limbs */
    float c_trunk;     /* trunk COM from the shoulder centre towards the hip centre */
    float c_upper_arm; /* from the shoulder */
    float c_forearm;   /* from the elbow */
    float c_thigh;     /* from the hip */
    float c_shank;     /* from the knee */
    float e_hand;      /* hand COM beyond the wrist, in forearm lengths */
    float c_foot;      /* foot COM along heel -> toe tip */
} seg_table;

static const seg_table k_tables[3] = {
    /* de Leva P. (1996) Adjustments to Zatsiorsky-Seluyanov's segment inertia
     * parameters. J Biomech 29:1223-30, Table 4, mean of male and female columns.
     * Trunk SUPR->MIDH (0.4486 M, 0.4151 F); hand 0.79/0.747 of WJC->MET3 turned
     * into forearm lengths; foot HEEL->TTIP. Female shank/hand values from memory. */
    { { 6.81f, 43.015f, 2.63f, 1.50f, 0.585f, 14.47f, 4.57f, 1.33f },
      0.4319f, 0.5763f, 0.4567f, 0.3854f, 0.4438f, 0.24f, 0.4215f },
    /* Clauser C.E., McConville J.T., Young J.W. (1969) Weight, volume and centre
     * of mass of segments of the human body. AMRL-TR-69-70, mean of 13 cadavers.
     * Trunk COM 38.0 % of trunk length read from the hip end (see the doc: read
     * from the top it puts the standing COM at 0.60 of stature); hand 18 % of
     * hand length = 0.13 forearm lengths beyond the wrist. */
    { { 7.3f, 50.7f, 2.6f, 1.6f, 0.7f, 10.3f, 4.3f, 1.5f },
      0.6197f, 0.513f, 0.390f, 0.372f, 0.371f, 0.13f, 0.449f },
    /* Dempster W.T. (1955) Space requirements of the seated operator, WADC-TR-55-159,
     * as tabulated by Winter D.A., Biomechanics and Motor Control of Human Movement,
     * Table 4.1. Head+neck COM at the ear canal; trunk glenohumeral -> trochanter 0.50;
     * hand 0.506 of wrist -> middle-finger knuckle = 0.27 forearm lengths;
     * foot 0.50 of malleolus -> metatarsal II, used as 0.50 heel -> toe. */
    { { 8.1f, 49.7f, 2.8f, 1.6f, 0.6f, 10.0f, 4.65f, 1.45f },
      0.50f, 0.436f, 0.430f, 0.433f, 0.433f, 0.27f, 0.50f },
};

/* ---- model constants (see docs/anthropometry.md) ---------------------------- */

#define SHOULDER_OVER_HIP_WIDTH 1.5f /* keypoint shoulder width / hip width, to rebuild one missing shoulder or hip */
#define MIRROR_MIN_WIDTH 0.35f       /* shoulder width / trunk length from which the view counts as frontal (yaw < ~60 deg) */
#define LATERAL_MAX_WIDTH 0.20f      /* ... and below which it counts as lateral (yaw > ~75 deg); blended between */
#define EARS_OVER_EYES_HALF 2.3f     /* half bitragion / half interpupillary breadth, to centre a lone ear */
#define WRIST_MCP_OVER_FOREARM 0.32f /* wrist->3rd knuckle / forearm length (de Leva male 86/269 mm) */
#define FOOT_BELOW_ANKLE 0.08f       /* foot COM below the ankle in shank lengths (no heel/toe keypoints) */

/* Landmark height above the floor / stature, standing adult. */
#define F_EYE 0.936f
#define F_EAR 0.927f
#define F_NOSE 0.910f
#define F_ANKLE 0.039f
#define F_HEEL 0.015f
#define F_TOE 0.012f
/* Prior trust of a landmark for stature: the nose sticks out and moves with head pitch. */
#define P_EYE 1.0f
#define P_EAR 0.8f
#define P_NOSE 0.25f
#define P_ANKLE 1.0f
#define P_HEEL 0.7f
#define P_TOE 0.4f

#define NOSE_ANKLE_FACTOR 1.17f /* the paper's c = 1.17 +/- 0.03 */

/* upright ramps, degrees and ratios */
#define KNEE_DEG_0 150.0f
#define KNEE_DEG_1 170.0f
#define HIP_DEG_0 140.0f
#define HIP_DEG_1 165.0f
#define TRUNK_TILT_DEG_1 10.0f
#define TRUNK_TILT_DEG_0 35.0f
#define LEG_TRUNK_0 1.1f  /* (thigh+shank)/trunk in the image: 1.7 standing, < 1 when thighs foreshorten in a squat */
#define LEG_TRUNK_1 1.4f

#define RAD_TO_DEG 57.29577951308232f

#if GS_WITH_POSE /* the skeleton model (gs_features.h); a point needs none of it */
/* ---- small vector helpers ---------------------------------------------------- */

typedef struct {
    float x, y;
} vec2;

static vec2 v_add(vec2 a, vec2 b) { return (vec2){ a.x + b.x, a.y + b.y }; }
static vec2 v_sub(vec2 a, vec2 b) { return (vec2){ a.x - b.x, a.y - b.y }; }
static vec2 v_scale(vec2 a, float s) { return (vec2){ a.x * s, a.y * s }; }
static vec2 v_mid(vec2 a, vec2 b) { return (vec2){ 0.5f * (a.x + b.x), 0.5f * (a.y + b.y) }; }
static vec2 v_lerp(vec2 a, vec2 b, float t) { return (vec2){ a.x + t * (b.x - a.x), a.y + t * (b.y - a.y) }; }
static float v_dot(vec2 a, vec2 b) { return a.x * b.x + a.y * b.y; }
static float v_len(vec2 a) { return sqrtf(a.x * a.x + a.y * a.y); }

/* Angle at b between b->a and b->c in degrees, NaN when a leg has no length. */
static float angle_deg(vec2 a, vec2 b, vec2 c)
{
    vec2 u = v_sub(a, b), v = v_sub(c, b);
    float lu = v_len(u), lv = v_len(v);
    if (!(lu > 0.0f) || !(lv > 0.0f)) {
        return NAN;
    }
    float cs = v_dot(u, v) / (lu * lv);
    cs = cs > 1.0f ? 1.0f : (cs < -1.0f ? -1.0f : cs);
    return GS_ACOSF(cs) * RAD_TO_DEG;
}

/* 0 at x0, 1 at x1 (either order), linear and clamped between. */
static float ramp(float x, float x0, float x1)
{
    float t = (x - x0) / (x1 - x0);
    return t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
}

/* ---- per-frame working state --------------------------------------------------- */

typedef struct {
    vec2 p[K_N];
    float c[K_N];
    bool obs[K_N];  /* detected with enough confidence */
    bool have[K_N]; /* observed or rebuilt */
    uint32_t used;  /* bit k: observed keypoint k entered the COM */
    float m_sum, m_obs, sx, sy;
} frame;

static void use(frame *f, int k)
{
    if (f->obs[k]) {
        f->used |= 1u << k;
    }
}

/* One segment's COM enters with its full mass; w counts a rebuilt segment at half. */
static void add_segment(frame *f, float mass, vec2 p, bool rebuilt)
{
    f->sx += mass * p.x;
    f->sy += mass * p.y;
    f->m_sum += mass;
    f->m_obs += rebuilt ? 0.5f * mass : mass;
}

static bool is_rebuilt(const frame *f, int a, int b)
{
    return !f->obs[a] || !f->obs[b];
}

static void load(frame *f, gs_layout layout, float min_conf, const gs_kp *kp)
{
    for (int k = 0; k < K_N; k++) {
        f->obs[k] = false;
        f->have[k] = false;
        f->c[k] = 0.0f;
        f->p[k] = (vec2){ NAN, NAN };
        int src = -1;
        if (GS_WITH_COCO17 && (!GS_WITH_BLAZEPOSE33 || layout == GS_LAYOUT_COCO17)) {
            src = k < 17 ? k : -1;
        } else if (GS_WITH_BLAZEPOSE33) {
            src = k_blaze_index[k];
        }
        if (src < 0) {
            continue;
        }
        const gs_kp *q = &kp[src];
        /* c == 0 is missing even with min_conf 0; non-finite input is missing too. */
        if (isfinite(q->c) && q->c > 0.0f && q->c >= min_conf && isfinite(q->x_px) && isfinite(q->y_px)) {
            f->obs[k] = true;
            f->have[k] = true;
            f->c[k] = q->c > 1.0f ? 1.0f : q->c;
            f->p[k] = (vec2){ q->x_px, q->y_px };
        }
    }
    f->used = 0;
    f->m_sum = f->m_obs = f->sx = f->sy = 0.0f;
}

/* Rebuild one missing shoulder from the hip pair (or a hip from the shoulders):
 * the two pairs are roughly parallel, so this also holds in lateral views. */
static void rebuild_trunk_corner(frame *f, int l, int r, int ol, int or_, float scale)
{
    if (f->obs[l] == f->obs[r] || !f->obs[ol] || !f->obs[or_]) {
        return;
    }
    vec2 across = v_scale(v_sub(f->p[or_], f->p[ol]), scale); /* left -> right */
    if (f->obs[l]) {
        f->p[r] = v_add(f->p[l], across);
        f->have[r] = true;
    } else {
        f->p[l] = v_sub(f->p[r], across);
        f->have[l] = true;
    }
}

/* Centre of a left/right pair: the mean, or the lone point (lateral view). */
static bool pair_centre(const frame *f, int l, int r, vec2 *out)
{
    if (f->have[l] && f->have[r]) {
        *out = v_mid(f->p[l], f->p[r]);
        return true;
    }
    if (f->have[l] || f->have[r]) {
        *out = f->have[l] ? f->p[l] : f->p[r];
        return true;
    }
    return false;
}

/* Missing distal joint = own proximal joint + the other side's limb vector
 * mirrored across the body's mid-plane. Seen from the front that mirror is a
 * reflection about the trunk axis (across = -1); seen from the side both sides
 * project onto one plane and the vector is copied (across = +1); oblique views
 * blend the across-axis part linearly. */
static void mirror_joint(frame *f, int prox, int dist, int oprox, int odist, vec2 axis, float across)
{
    if (f->have[dist] || !f->have[prox] || !f->obs[oprox] || !f->obs[odist]) {
        return;
    }
    vec2 v = v_sub(f->p[odist], f->p[oprox]);
    vec2 along = v_scale(axis, v_dot(v, axis));
    v = v_add(along, v_scale(v_sub(v, along), across));
    f->p[dist] = v_add(f->p[prox], v);
    f->have[dist] = true;
}

static bool head_centre(frame *f, vec2 *out, bool *rebuilt)
{
    *rebuilt = false;
    if (f->obs[K_LEAR] && f->obs[K_REAR]) {
        use(f, K_LEAR);
        use(f, K_REAR);
        *out = v_mid(f->p[K_LEAR], f->p[K_REAR]);
        return true;
    }
    if (f->obs[K_LEAR] || f->obs[K_REAR]) {
        int ear = f->obs[K_LEAR] ? K_LEAR : K_REAR;
        int eye = ear == K_LEAR ? K_LEYE : K_REYE;
        use(f, ear);
        *out = f->p[ear];
        if (f->obs[K_LEYE] && f->obs[K_REYE]) {
            /* shift the lone ear towards the mid-line by the eyes' half spread, scaled to ear breadth */
            vec2 half = v_sub(v_mid(f->p[K_LEYE], f->p[K_REYE]), f->p[eye]);
            *out = v_add(*out, v_scale(half, EARS_OVER_EYES_HALF));
            use(f, K_LEYE);
            use(f, K_REYE);
            *rebuilt = true;
        }
        return true;
    }
    if (f->obs[K_LEYE] || f->obs[K_REYE]) {
        pair_centre(f, K_LEYE, K_REYE, out);
        use(f, K_LEYE);
        use(f, K_REYE);
        *rebuilt = true; /* eyes sit in front of the head's centre */
        return true;
    }
    if (f->obs[K_NOSE]) {
        use(f, K_NOSE);
        *out = f->p[K_NOSE];
        *rebuilt = true;
        return true;
    }
    return false;
}

/* Arm or leg of one side: proximal (shoulder/hip), middle (elbow/knee), distal
 * (wrist/ankle) with segment masses and COM fractions; extremity handled by caller. */
static void add_limb(frame *f, int j0, int j1, int j2, float m_prox, float c_prox, float m_dist, float c_dist)
{
    if (f->have[j0] && f->have[j1]) {
        add_segment(f, m_prox, v_lerp(f->p[j0], f->p[j1], c_prox), is_rebuilt(f, j0, j1));
        use(f, j0);
        use(f, j1);
    }
    if (f->have[j1] && f->have[j2]) {
        add_segment(f, m_dist, v_lerp(f->p[j1], f->p[j2], c_dist), is_rebuilt(f, j1, j2));
        use(f, j1);
        use(f, j2);
    }
}

static void add_hand(frame *f, bool blaze, int elb, int wri, int pinky, int index, float m, float e_hand)
{
    if (!f->have[wri]) {
        return;
    }
    vec2 w = f->p[wri];
    if (blaze && (f->obs[pinky] || f->obs[index])) {
        vec2 mcp;
        if (f->obs[pinky] && f->obs[index]) {
            mcp = v_mid(f->p[pinky], f->p[index]);
        } else {
            mcp = f->obs[pinky] ? f->p[pinky] : f->p[index];
        }
        use(f, pinky);
        use(f, index);
        use(f, wri);
        add_segment(f, m, v_lerp(w, mcp, e_hand / WRIST_MCP_OVER_FOREARM), !f->obs[wri]);
    } else if (f->have[elb]) {
        use(f, wri);
        add_segment(f, m, v_add(w, v_scale(v_sub(w, f->p[elb]), e_hand)), is_rebuilt(f, elb, wri));
    } else {
        use(f, wri);
        add_segment(f, m, w, true);
    }
}

static void add_foot(frame *f, bool blaze, int kne, int ank, int heel, int toe, float m, float c_foot)
{
    if (!f->have[ank]) {
        return;
    }
    vec2 a = f->p[ank];
    if (blaze && f->obs[heel] && f->obs[toe]) {
        /* halfway between the ankle and the sole point at c_foot: foot COM is ~3 cm above the floor */
        vec2 sole = v_lerp(f->p[heel], f->p[toe], c_foot);
        use(f, heel);
        use(f, toe);
        use(f, ank);
        add_segment(f, m, v_mid(a, sole), !f->obs[ank]);
    } else if (f->have[kne]) {
        use(f, ank);
        add_segment(f, m, v_add(a, v_scale(v_sub(a, f->p[kne]), FOOT_BELOW_ANKLE)), is_rebuilt(f, kne, ank));
    } else {
        use(f, ank);
        add_segment(f, m, a, true);
    }
}

/* ---- stature and axis ---------------------------------------------------------- */

typedef struct {
    float sw, sx, sy, sf;
} group;

static void group_add(group *g, const frame *f, int k, float frac, float prior)
{
    if (!f->obs[k]) {
        return;
    }
    float w = f->c[k] * prior;
    g->sw += w;
    g->sx += w * f->p[k].x;
    g->sy += w * f->p[k].y;
    g->sf += w * frac;
}

/* Weighted head and foot landmark centroids with their mean height fractions;
 * stature = their distance along the body axis / the fraction difference.
 * Called before any keypoint is rebuilt (have == obs). */
static bool anthro_stature(const frame *f, float *stature_px, vec2 *up)
{
    group h = { 0 }, ft = { 0 };
    group_add(&h, f, K_LEYE, F_EYE, P_EYE);
    group_add(&h, f, K_REYE, F_EYE, P_EYE);
    group_add(&h, f, K_LEAR, F_EAR, P_EAR);
    group_add(&h, f, K_REAR, F_EAR, P_EAR);
    group_add(&h, f, K_NOSE, F_NOSE, P_NOSE);
    group_add(&ft, f, K_LANK, F_ANKLE, P_ANKLE);
    group_add(&ft, f, K_RANK, F_ANKLE, P_ANKLE);
    group_add(&ft, f, K_LHEEL, F_HEEL, P_HEEL);
    group_add(&ft, f, K_RHEEL, F_HEEL, P_HEEL);
    group_add(&ft, f, K_LTOE, F_TOE, P_TOE);
    group_add(&ft, f, K_RTOE, F_TOE, P_TOE);
    if (!(h.sw > 0.0f) || !(ft.sw > 0.0f)) {
        return false;
    }
    vec2 hc = { h.sx / h.sw, h.sy / h.sw };
    vec2 fc = { ft.sx / ft.sw, ft.sy / ft.sw };
    /* Axis along the posture plumb line ear -> ankle when seen: eyes, nose and
     * toes sit in front of it and would tilt it forward in a lateral view. */
    vec2 ha = hc, fa = fc;
    if (!pair_centre(f, K_LEAR, K_REAR, &ha) && !pair_centre(f, K_LEYE, K_REYE, &ha)) {
        ha = hc;
    }
    if (!pair_centre(f, K_LANK, K_RANK, &fa)) {
        fa = fc;
    }
    vec2 d = v_sub(ha, fa);
    float len = v_len(d);
    if (!(len > 0.0f)) {
        return false;
    }
    *up = v_scale(d, 1.0f / len);
    *stature_px = v_dot(v_sub(hc, fc), *up) / (h.sf / h.sw - ft.sf / ft.sw);
    return true;
}

/* The paper's baseline: 1.17 x distance nose -> mean of the visible ankles. */
static float nose_ankle_stature(const frame *f)
{
    vec2 a;
    if (!f->obs[K_NOSE]) {
        return NAN;
    }
    if (f->obs[K_LANK] && f->obs[K_RANK]) {
        a = v_mid(f->p[K_LANK], f->p[K_RANK]);
    } else if (f->obs[K_LANK] || f->obs[K_RANK]) {
        a = f->obs[K_LANK] ? f->p[K_LANK] : f->p[K_RANK];
    } else {
        return NAN;
    }
    return NOSE_ANKLE_FACTOR * v_len(v_sub(f->p[K_NOSE], a));
}

/* ---- uprightness --------------------------------------------------------------- */

static float min_nan(float acc, float v)
{
    if (isnan(v)) {
        return acc;
    }
    return (isnan(acc) || v < acc) ? v : acc;
}

static float upright_score(const frame *f, bool have_trunk, vec2 s, vec2 p, bool axis_from_body, vec2 up)
{
    static const int side[2][4] = { { K_LSHO, K_LHIP, K_LKNE, K_LANK }, { K_RSHO, K_RHIP, K_RKNE, K_RANK } };
    float knee = NAN, other = NAN;
    float trunk_len = have_trunk ? v_len(v_sub(s, p)) : 0.0f;
    for (int i = 0; i < 2; i++) {
        int sh = side[i][0], hp = side[i][1], kn = side[i][2], an = side[i][3];
        if (!f->obs[hp] || !f->obs[kn] || !f->obs[an]) {
            continue;
        }
        knee = min_nan(knee, ramp(angle_deg(f->p[hp], f->p[kn], f->p[an]), KNEE_DEG_0, KNEE_DEG_1));
        if (f->obs[sh]) {
            other = min_nan(other, ramp(angle_deg(f->p[sh], f->p[hp], f->p[kn]), HIP_DEG_0, HIP_DEG_1));
        }
        if (trunk_len > 0.0f) {
            float leg = v_len(v_sub(f->p[hp], f->p[kn])) + v_len(v_sub(f->p[kn], f->p[an]));
            other = min_nan(other, ramp(leg / trunk_len, LEG_TRUNK_0, LEG_TRUNK_1));
        }
    }
    if (isnan(knee)) {
        return NAN; /* legs missing: cannot tell */
    }
    if (axis_from_body && trunk_len > 0.0f) {
        float cs = v_dot(v_sub(s, p), up) / trunk_len;
        cs = cs > 1.0f ? 1.0f : (cs < -1.0f ? -1.0f : cs);
        other = min_nan(other, ramp(GS_ACOSF(cs) * RAD_TO_DEG, TRUNK_TILT_DEG_0, TRUNK_TILT_DEG_1));
    }
    return min_nan(knee, other);
}

#endif /* GS_WITH_POSE */

/* ---- public ---------------------------------------------------------------------- */

size_t gs_layout_kp_count(gs_layout layout)
{
    switch (layout) {
    /* a layout left out of the build (gs_features.h) is unknown */
    case GS_LAYOUT_POINT: return 1;
    case GS_LAYOUT_COCO17: return GS_WITH_COCO17 ? 17u : 0u;
    case GS_LAYOUT_BLAZEPOSE33: return GS_WITH_BLAZEPOSE33 ? 33u : 0u;
    default: return 0;
    }
}

static float table_total_pct(const seg_table *t)
{
    float s = t->mass_pct[GS_SEG_HEAD] + t->mass_pct[GS_SEG_TRUNK];
    for (int k = GS_SEG_UPPER_ARM; k < GS_SEG_COUNT; k++) {
        s += 2.0f * t->mass_pct[k];
    }
    return s;
}

float gs_mass_fraction(gs_mass_table t, gs_segment s)
{
    if ((unsigned)t > (unsigned)GS_MASS_DEMPSTER || (unsigned)s >= (unsigned)GS_SEG_COUNT) {
        return NAN;
    }
    const seg_table *tb = &k_tables[t];
    return tb->mass_pct[s] / table_total_pct(tb);
}

static void out_unknown(gs_com_out *out)
{
    out->x_px = out->y_px = NAN;
    out->w = 0.0f;
    out->stature_px = NAN;
    out->up_x = out->up_y = NAN;
    out->upright = NAN;
}

gs_status gs_com_compute(gs_layout layout, gs_mass_table table, gs_stature_method stature,
                         float min_conf, const gs_kp *kp, gs_com_out *out)
{
    if (out) {
        out_unknown(out);
    }
    if (!out || !kp || gs_layout_kp_count(layout) == 0 || (unsigned)table > (unsigned)GS_MASS_DEMPSTER ||
        (unsigned)stature > (unsigned)GS_STATURE_NOSE_ANKLE_117 || !(min_conf >= 0.0f && min_conf <= 1.0f)) {
        return GS_EINVAL;
    }

    if (layout == GS_LAYOUT_POINT) {
        out->upright = 1.0f; /* a rigid object is always "upright" */
        const gs_kp *q = &kp[0];
        if (isfinite(q->c) && q->c > 0.0f && q->c >= min_conf && isfinite(q->x_px) && isfinite(q->y_px)) {
            out->x_px = q->x_px;
            out->y_px = q->y_px;
            out->w = q->c > 1.0f ? 1.0f : q->c;
        }
        return GS_OK;
    }
#if GS_WITH_POSE
    const seg_table *tb = &k_tables[table];
    const float total = table_total_pct(tb);
    const bool blaze = GS_WITH_BLAZEPOSE33 && (!GS_WITH_COCO17 || layout == GS_LAYOUT_BLAZEPOSE33);
    frame f;
    load(&f, layout, min_conf, kp);

    /* Stature and body axis do not need the trunk. */
    vec2 up = { NAN, NAN };
    float st = NAN;
    bool axis_from_body = anthro_stature(&f, &st, &up);
    if (stature == GS_STATURE_NOSE_ANKLE_117) {
        st = nose_ankle_stature(&f);
    }
    out->stature_px = isfinite(st) ? st : NAN; /* absurd coordinates overflow float */
    if (!isfinite(up.x) || !isfinite(up.y)) {
        up = (vec2){ NAN, NAN };
        axis_from_body = false;
    }

    /* Trunk: rebuild a lone missing shoulder/hip, then the two centres. */
    rebuild_trunk_corner(&f, K_LSHO, K_RSHO, K_LHIP, K_RHIP, SHOULDER_OVER_HIP_WIDTH);
    rebuild_trunk_corner(&f, K_LHIP, K_RHIP, K_LSHO, K_RSHO, 1.0f / SHOULDER_OVER_HIP_WIDTH);
    vec2 s = { NAN, NAN }, p = { NAN, NAN };
    bool have_trunk = pair_centre(&f, K_LSHO, K_RSHO, &s) && pair_centre(&f, K_LHIP, K_RHIP, &p);

    if (!axis_from_body && have_trunk && v_len(v_sub(s, p)) > 0.0f) {
        vec2 d = v_sub(s, p); /* fallback axis: hip centre -> shoulder centre */
        up = v_scale(d, 1.0f / v_len(d));
    }
    if (!isnan(up.x)) {
        out->up_x = up.x;
        out->up_y = up.y;
    }
    out->upright = upright_score(&f, have_trunk, s, p, axis_from_body, up);

    if (!have_trunk) {
        return GS_OK; /* w = 0: without the trunk (half the mass) the COM is a guess */
    }

    /* Rebuild a lost limb joint from the other side (mirror across the mid-plane). */
    vec2 trunk = v_sub(s, p);
    float trunk_len = v_len(trunk);
    bool corners = f.obs[K_LSHO] && f.obs[K_RSHO] && f.obs[K_LHIP] && f.obs[K_RHIP];
    if (trunk_len > 0.0f) {
        float width = NAN; /* shoulder width / trunk length: ~0.7 frontal, ~0 lateral */
        if (f.obs[K_LSHO] && f.obs[K_RSHO]) {
            width = v_len(v_sub(f.p[K_LSHO], f.p[K_RSHO])) / trunk_len;
        } else if (f.obs[K_LHIP] && f.obs[K_RHIP]) {
            width = SHOULDER_OVER_HIP_WIDTH * v_len(v_sub(f.p[K_LHIP], f.p[K_RHIP])) / trunk_len;
        }
        /* no pair seen: one side hidden, i.e. a lateral view */
        float across = isnan(width) ? 1.0f : 1.0f - 2.0f * ramp(width, LATERAL_MAX_WIDTH, MIRROR_MIN_WIDTH);
        vec2 axis = v_scale(trunk, 1.0f / trunk_len);
        static const int chain[4][3] = {
            { K_LSHO, K_LELB, K_LWRI }, { K_RSHO, K_RELB, K_RWRI },
            { K_LHIP, K_LKNE, K_LANK }, { K_RHIP, K_RKNE, K_RANK } };
        for (int c = 0; c < 4; c++) {
            const int *own = chain[c], *oth = chain[c ^ 1];
            mirror_joint(&f, own[0], own[1], oth[0], oth[1], axis, across);
            mirror_joint(&f, own[1], own[2], oth[1], oth[2], axis, across);
        }
    }

    vec2 hc = {0.0f, 0.0f};
    bool head_rebuilt;
    if (head_centre(&f, &hc, &head_rebuilt)) {
        add_segment(&f, tb->mass_pct[GS_SEG_HEAD], hc, head_rebuilt);
    }
    bool trunk_rebuilt = !corners;
    add_segment(&f, tb->mass_pct[GS_SEG_TRUNK], v_lerp(s, p, tb->c_trunk), trunk_rebuilt);
    use(&f, K_LSHO);
    use(&f, K_RSHO);
    use(&f, K_LHIP);
    use(&f, K_RHIP);

    const float *m = tb->mass_pct;
    add_limb(&f, K_LSHO, K_LELB, K_LWRI, m[GS_SEG_UPPER_ARM], tb->c_upper_arm, m[GS_SEG_FOREARM], tb->c_forearm);
    add_limb(&f, K_RSHO, K_RELB, K_RWRI, m[GS_SEG_UPPER_ARM], tb->c_upper_arm, m[GS_SEG_FOREARM], tb->c_forearm);
    add_hand(&f, blaze, K_LELB, K_LWRI, K_LPINKY, K_LINDEX, m[GS_SEG_HAND], tb->e_hand);
    add_hand(&f, blaze, K_RELB, K_RWRI, K_RPINKY, K_RINDEX, m[GS_SEG_HAND], tb->e_hand);
    add_limb(&f, K_LHIP, K_LKNE, K_LANK, m[GS_SEG_THIGH], tb->c_thigh, m[GS_SEG_SHANK], tb->c_shank);
    add_limb(&f, K_RHIP, K_RKNE, K_RANK, m[GS_SEG_THIGH], tb->c_thigh, m[GS_SEG_SHANK], tb->c_shank);
    add_foot(&f, blaze, K_LKNE, K_LANK, K_LHEEL, K_LTOE, m[GS_SEG_FOOT], tb->c_foot);
    add_foot(&f, blaze, K_RKNE, K_RANK, K_RHEEL, K_RTOE, m[GS_SEG_FOOT], tb->c_foot);

    /* Renormalise over the segments present; w falls with the square of what is missing. */
    out->x_px = f.sx / f.m_sum;
    out->y_px = f.sy / f.m_sum;
    float csum = 0.0f;
    int n = 0;
    for (int k = 0; k < K_N; k++) {
        if (f.used & (1u << k)) {
            csum += f.c[k];
            n++;
        }
    }
    float frac = f.m_obs / total;
    float w = frac * frac * (n > 0 ? csum / (float)n : 0.0f);
    /* a segment missing outright (not even rebuilt from its mirror, e.g. the head
     * out of the frame at the apex) biases the renormalised COM by centimetres:
     * such frames count only when nothing better exists */
    if (f.m_sum < 0.999f * total) w *= DROPPED_SEGMENT_WEIGHT;
    out->w = w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
    if (!isfinite(out->x_px) || !isfinite(out->y_px)) {
        out->x_px = out->y_px = NAN;
        out->w = 0.0f;
    }
#endif
    return GS_OK;
}

/* ---- names ---------------------------------------------------------------------- */

/* s[0..len) equals the NUL-terminated name, ASCII case-insensitive. */
static bool name_eq(const char *s, size_t len, const char *name)
{
    size_t i = 0;
    for (; i < len; i++) {
        char a = s[i], b = name[i];
        if (b == '\0') {
            return false;
        }
        if (a >= 'A' && a <= 'Z') {
            a = (char)(a - 'A' + 'a');
        }
        if (a != b) {
            return false;
        }
    }
    return name[i] == '\0';
}

static const char *const k_table_names[] = { "deleva", "clauser", "dempster" };
static const char *const k_stature_names[] = { "anthro", "nose_ankle_1.17" };
static const char *const k_layout_names[] = { "point", "coco17", "blazepose33" };

const char *gs_mass_table_name(gs_mass_table t)
{
    return (unsigned)t < 3u ? k_table_names[t] : "unknown";
}

bool gs_mass_table_from_name(const char *s, size_t len, gs_mass_table *out)
{
    for (unsigned i = 0; s && out && i < 3u; i++) {
        if (name_eq(s, len, k_table_names[i])) {
            *out = (gs_mass_table)i;
            return true;
        }
    }
    return false;
}

const char *gs_stature_method_name(gs_stature_method m)
{
    return (unsigned)m < 2u ? k_stature_names[m] : "unknown";
}

bool gs_stature_method_from_name(const char *s, size_t len, gs_stature_method *out)
{
    for (unsigned i = 0; s && out && i < 2u; i++) {
        if (name_eq(s, len, k_stature_names[i])) {
            *out = (gs_stature_method)i;
            return true;
        }
    }
    return false;
}

const char *gs_layout_name(gs_layout l)
{
    return (unsigned)l < 3u ? k_layout_names[l] : "unknown";
}

bool gs_layout_from_name(const char *s, size_t len, gs_layout *out)
{
    for (unsigned i = 0; s && out && i < 3u; i++) {
        if (name_eq(s, len, k_layout_names[i])) {
            *out = (gs_layout)i;
            return true;
        }
    }
    return false;
}
