/* gs_com.c - whole-body centre of mass, standing stature in pixels, body axis
 * and an uprightness score from one frame of 2D keypoints (COCO-17 or
 * BlazePose-33). Segment model and landmark ratios: docs/anthropometry.md.
 * Plain C11, no heap, no stdio; float arithmetic for a Cortex-M4 FPU. */
#include <float.h>
#include <math.h>

#include "gravscale/gs_com.h"

#include "gs_finite.h"
#include "gs_inline.h"

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

/* Limb joints run shoulder, elbow, wrist and hip, knee, ankle two apart; each
 * left keypoint (odd) is followed by its right one (even). */
#define NEXT_JOINT 2
_Static_assert(K_LELB == K_LSHO + NEXT_JOINT && K_LWRI == K_LELB + NEXT_JOINT && K_LKNE == K_LHIP + NEXT_JOINT &&
               K_LANK == K_LKNE + NEXT_JOINT && K_REYE == K_LEYE + 1 && K_REAR == K_LEAR + 1 &&
               K_RSHO == K_LSHO + 1 && K_RHIP == K_LHIP + 1 && K_RANK == K_LANK + 1 && (K_LSHO & 1) && (K_LHIP & 1),
               "canonical keypoint order");

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
    /* COM position per segment: trunk from the shoulder centre towards the hip
     * centre; upper arm from the shoulder; forearm from the elbow; hand beyond the
     * wrist in forearm lengths; thigh from the hip; shank from the knee; foot along
     * heel -> toe tip. The head's COM is its centre (no fraction). */
    float c[GS_SEG_COUNT];
} seg_table;

/* de Leva P. (1996) Adjustments to Zatsiorsky-Seluyanov's segment inertia
 * parameters. J Biomech 29:1223-30, Table 4, mean of male and female columns.
 * Trunk SUPR->MIDH (0.4486 M, 0.4151 F); hand 0.79/0.747 of WJC->MET3 turned
 * into forearm lengths; foot HEEL->TTIP. Female shank/hand values from memory. */
static const seg_table k_deleva = {
    { 6.81f, 43.015f, 2.63f, 1.50f, 0.585f, 14.47f, 4.57f, 1.33f },
    { 0.0f, 0.4319f, 0.5763f, 0.4567f, 0.24f, 0.3854f, 0.4438f, 0.4215f } };
/* Clauser C.E., McConville J.T., Young J.W. (1969) Weight, volume and centre
 * of mass of segments of the human body. AMRL-TR-69-70, mean of 13 cadavers.
 * Trunk COM 38.0 % of trunk length read from the hip end (see the doc: read
 * from the top it puts the standing COM at 0.60 of stature); hand 18 % of
 * hand length = 0.13 forearm lengths beyond the wrist. */
static const seg_table k_clauser = {
    { 7.3f, 50.7f, 2.6f, 1.6f, 0.7f, 10.3f, 4.3f, 1.5f },
    { 0.0f, 0.6197f, 0.513f, 0.390f, 0.13f, 0.372f, 0.371f, 0.449f } };
/* Dempster W.T. (1955) Space requirements of the seated operator, WADC-TR-55-159,
 * as tabulated by Winter D.A., Biomechanics and Motor Control of Human Movement,
 * Table 4.1. Head+neck COM at the ear canal; trunk glenohumeral -> trochanter 0.50;
 * hand 0.506 of wrist -> middle-finger knuckle = 0.27 forearm lengths;
 * foot 0.50 of malleolus -> metatarsal II, used as 0.50 heel -> toe. */
static const seg_table k_dempster = {
    { 8.1f, 49.7f, 2.8f, 1.6f, 0.6f, 10.0f, 4.65f, 1.45f },
    { 0.0f, 0.50f, 0.436f, 0.430f, 0.27f, 0.433f, 0.433f, 0.50f } };
/* by gs_mass_table; one object each, so a build whose table is a constant (a baked
 * profile) keeps only its own */
static const seg_table *const k_tables[3] = {&k_deleva, &k_clauser, &k_dempster};

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

/* A keypoint counts when its confidence is positive, finite and >= min_conf and its
 * position is finite (c == 0 is missing even with min_conf 0). */
static bool kp_usable(const gs_kp *q, float min_conf)
{
    /* (c >= a positive min_conf is c > 0: one test where min_conf is a constant) */
    return q->c >= min_conf && (min_conf > 0.0f || q->c > 0.0f) && q->c <= FLT_MAX &&
           gs_finite2_f(q->x_px, q->y_px);
}

static float conf01(float c)
{
    return c > 1.0f ? 1.0f : c;
}

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

/* acos in degrees of a cosine clamped to [-1, 1] (rounding may step outside). */
static NOINLINE float acos_deg(float cs)
{
    cs = cs > 1.0f ? 1.0f : (cs < -1.0f ? -1.0f : cs);
    return GS_ACOSF_CLAMPED(cs) * RAD_TO_DEG;
}

/* 0 at x0, 1 at x1 (either order), linear and clamped between. */
static NOINLINE float ramp(float x, float x0, float x1)
{
    float t = (x - x0) / (x1 - x0);
    return t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
}

/* Weighted sums: total weight, weighted x and y, and one more weighted quantity e. */
typedef struct {
    float w, x, y, e;
} wsum;

/* (x and y apart: a vec2 argument costs its callee a stack copy at -Os) */
static NOINLINE void wsum_add(wsum *s, float w, float x, float y, float e)
{
    s->w += w;
    s->x += w * x;
    s->y += w * y;
    s->e += w * e;
}

static vec2 wsum_mean(const wsum *s)
{
    return (vec2){ s->x / s->w, s->y / s->w };
}

/* ---- per-frame working state --------------------------------------------------- */

#define BIT(k) (1u << (k))
#define BIT2(a, b) (BIT(a) | BIT(b))

/* (the COM sums first and the positions before the confidences: shorter addressing on the M4) */
typedef struct {
    wsum com; /* segment masses and their COMs; e: share observed (rebuilt counts half) */
    uint32_t obs;  /* bit k: keypoint k detected with enough confidence */
    uint32_t have; /* bit k: observed or rebuilt */
    uint32_t used; /* bit k: observed keypoint k entered the COM */
    vec2 p[K_N];
    float c[K_N];
} frame;

/* Keypoint a minus keypoint b: the helpers below take keypoint indices (smaller calls). */
static vec2 kp_diff(const frame *f, int a, int b)
{
    return v_sub(f->p[a], f->p[b]);
}

/* Keypoint base + s x (keypoint a - keypoint b). */
static vec2 kp_extend(const frame *f, int base, int a, int b, float s)
{
    vec2 d = kp_diff(f, a, b);
    return (vec2){ f->p[base].x + d.x * s, f->p[base].y + d.y * s };
}

static float kp_dist(const frame *f, int a, int b)
{
    return v_len(kp_diff(f, a, b));
}

#ifdef __OPTIMIZE_SIZE__
/* Angle at keypoint b between b->a and b->c in degrees, NaN when a leg has no length. */
static float angle_deg(const frame *f, int a, int b, int c)
{
    vec2 u = kp_diff(f, a, b), v = kp_diff(f, c, b);
    float lu = v_len(u), lv = v_len(v);
    if (!(lu > 0.0f) || !(lv > 0.0f)) {
        return NAN;
    }
    return acos_deg(v_dot(u, v) / (lu * lv));
}
#else
/* The cosine of angle_deg's angle, NaN when a leg has no length. */
static float angle_cos(const frame *f, int a, int b, int c)
{
    vec2 u = kp_diff(f, a, b), v = kp_diff(f, c, b);
    float lu = v_len(u), lv = v_len(v);
    if (!(lu > 0.0f) || !(lv > 0.0f)) {
        return NAN;
    }
    return v_dot(u, v) / (lu * lv);
}

/* ramp(acos_deg(cs), x0, x1) with c0, c1 the cosines of x0, x1 degrees: where the cosine
 * lies clearly beyond either end the ramp is exactly 0 or 1 and no acos is needed (acos
 * falls as the cosine rises; 1e-4 in the cosine is at least 0.005 degree there, far beyond
 * the rounding of acosf and of the constants). */
static float ramp_acos(float cs, float x0, float x1, float c0, float c1)
{
    float s = x0 < x1 ? 1.0f : -1.0f;
    if (s * (cs - c0) > 1e-4f) {
        return 0.0f;
    }
    if (s * (c1 - cs) > 1e-4f) {
        return 1.0f;
    }
    return ramp(acos_deg(cs), x0, x1);
}
#define COS_KNEE_0 -0.8660254f /* cos 150 deg */
#define COS_KNEE_1 -0.9848078f /* cos 170 deg */
#define COS_HIP_0 -0.7660444f  /* cos 140 deg */
#define COS_HIP_1 -0.9659258f  /* cos 165 deg */
#define COS_TILT_0 0.8191520f  /* cos 35 deg */
#define COS_TILT_1 0.9848078f  /* cos 10 deg */
#endif

/* The same keypoint on the other side of the body (left odd, right even). */
static int other_side(int k)
{
    return ((k - 1) ^ 1) + 1;
}

static bool all_in(uint32_t set, uint32_t bits)
{
    return (set & bits) == bits;
}

/* One segment's COM enters with its full mass; w counts a rebuilt segment at half.
 * The observed ones of the keypoints in bits count for the confidence. */
static NOINLINE void add_segment(frame *f, float mass, float x, float y, bool rebuilt, uint32_t bits)
{
    f->used |= f->obs & bits;
    wsum_add(&f->com, mass, x, y, rebuilt ? 0.5f : 1.0f);
}

static bool is_rebuilt(const frame *f, int a, int b)
{
    return !all_in(f->obs, BIT2(a, b));
}

/* A keypoint not observed keeps c = 0 and position (0, 0): it adds nothing to a weighted sum. */
static void load(frame *f, bool blaze, float min_conf, const gs_kp *kp)
{
    *f = (frame){ 0 };
#ifndef __OPTIMIZE_SIZE__
    if (GS_WITH_COCO17 && !blaze) {
        /* the same as the loop below, without its per-keypoint layout choice */
        uint32_t obs = 0;
#pragma GCC unroll 17
        for (int k = 0; k < 17; k++) {
            const gs_kp *q = &kp[k];
            if (kp_usable(q, min_conf)) {
                obs |= BIT(k);
                f->c[k] = conf01(q->c);
                f->p[k] = (vec2){ q->x_px, q->y_px };
            }
        }
        f->obs = obs;
        f->have = obs;
        return;
    }
#endif
    bool coco = GS_WITH_COCO17 && !blaze;
    for (int k = 0; k < (coco ? 17 : K_N); k++) { /* COCO-17's are the first 17 canonical ones */
        const gs_kp *q = &kp[coco ? k : k_blaze_index[k]];
        if (kp_usable(q, min_conf)) {
            f->obs |= BIT(k);
            f->c[k] = conf01(q->c);
            f->p[k] = (vec2){ q->x_px, q->y_px };
        }
    }
    f->have = f->obs;
}

/* Rebuild one missing shoulder from the hip pair (or a hip from the shoulders):
 * the two pairs are roughly parallel, so this also holds in lateral views.
 * l and ol are the left keypoints of the pair and of the other pair (right = left + 1). */
static NOINLINE void rebuild_trunk_corner(frame *f, int l, int ol, float scale)
{
    uint32_t seen = f->obs & BIT2(l, l + 1);
    if (seen == 0 || seen == BIT2(l, l + 1) || !all_in(f->obs, BIT2(ol, ol + 1))) {
        return;
    }
    /* the other pair's left -> right vector, backwards from a right corner */
    int known = l + 1, lost = l;
    float s = -scale;
    if (seen == BIT(l)) {
        known = l;
        lost = l + 1;
        s = scale;
    }
    f->p[lost] = kp_extend(f, known, ol + 1, ol, s);
    f->have |= BIT(lost);
}

/* Centre of two keypoints among those in set: the mean, or the lone one. */
static bool centre_of(const frame *f, uint32_t set, int a, int b, vec2 *out)
{
    if (all_in(set, BIT2(a, b))) {
        *out = v_mid(f->p[a], f->p[b]);
        return true;
    }
    if (set & BIT2(a, b)) {
        *out = f->p[(set & BIT(a)) ? a : b];
        return true;
    }
    return false;
}

/* Centre of the left/right pair from l (the right one follows): a lone point
 * stands for the pair in a lateral view. */
static NOINLINE bool pair_centre(const frame *f, uint32_t set, int l, vec2 *out)
{
    return centre_of(f, set, l, l + 1, out);
}

/* Missing distal joint = own proximal joint + the other side's limb vector
 * mirrored across the body's mid-plane. Seen from the front that mirror is a
 * reflection about the trunk axis (across = -1); seen from the side both sides
 * project onto one plane and the vector is copied (across = +1); oblique views
 * blend the across-axis part linearly. */
static void mirror_joint(frame *f, int prox, vec2 axis, float across)
{
    int dist = prox + NEXT_JOINT, oprox = other_side(prox), odist = oprox + NEXT_JOINT;
    if ((f->have & BIT(dist)) || !(f->have & BIT(prox)) || !all_in(f->obs, BIT2(oprox, odist))) {
        return;
    }
    vec2 v = kp_diff(f, odist, oprox);
    vec2 along = v_scale(axis, v_dot(v, axis));
    v = v_add(along, v_scale(v_sub(v, along), across));
    f->p[dist] = v_add(f->p[prox], v);
    f->have |= BIT(dist);
}

#define EARS BIT2(K_LEAR, K_REAR)

/* Head centre from the ears, else a lone ear moved to the mid-line, else the
 * eyes, else the nose. Returns the keypoints used, 0 when there is no head; any
 * but the ears means a rebuilt centre (eyes and nose sit in front of it). */
static uint32_t head_centre(const frame *f, vec2 *out)
{
    const uint32_t eyes = BIT2(K_LEYE, K_REYE);
    uint32_t ears = f->obs & EARS;
    if (ears) {
        pair_centre(f, ears, K_LEAR, out);
        if (ears != EARS && all_in(f->obs, eyes)) {
            /* shift the lone ear towards the mid-line by the eyes' half spread, scaled to ear breadth */
            int eye = ears == BIT(K_LEAR) ? K_LEYE : K_REYE;
            vec2 half = v_sub(v_mid(f->p[K_LEYE], f->p[K_REYE]), f->p[eye]);
            *out = v_add(*out, v_scale(half, EARS_OVER_EYES_HALF));
            return ears | eyes;
        }
        return ears;
    }
    if (pair_centre(f, f->obs, K_LEYE, out)) {
        return eyes;
    }
    *out = f->p[K_NOSE];
    return f->obs & BIT(K_NOSE);
}

/* Limb segments in the order their COMs are summed, by proximal joint (the
 * distal one is the next joint); hand and foot lie beyond the distal joint. */
typedef struct {
    uint8_t prox, seg;
} seg_def;

static const seg_def k_limb_segs[] = {
    { K_LSHO, GS_SEG_UPPER_ARM }, { K_LELB, GS_SEG_FOREARM }, { K_RSHO, GS_SEG_UPPER_ARM },
    { K_RELB, GS_SEG_FOREARM },   { K_LELB, GS_SEG_HAND },    { K_RELB, GS_SEG_HAND },
    { K_LHIP, GS_SEG_THIGH },     { K_LKNE, GS_SEG_SHANK },   { K_RHIP, GS_SEG_THIGH },
    { K_RKNE, GS_SEG_SHANK },     { K_LKNE, GS_SEG_FOOT },    { K_RKNE, GS_SEG_FOOT },
};

/* BlazePose hand or foot from its own keypoints (added to bits); false when they are missing. */
static bool blaze_extremity(const frame *f, int dist, bool hand, float c, vec2 *com, uint32_t *bits)
{
    vec2 q = f->p[dist];
    if (hand) {
        /* BlazePose pinky and index knuckles lie 12 and 14 after the wrist */
        int pinky = dist + (K_LPINKY - K_LWRI), index = dist + (K_LINDEX - K_LWRI);
        vec2 mcp;
        if (!centre_of(f, f->obs, pinky, index, &mcp)) {
            return false;
        }
        *com = v_lerp(q, mcp, c / WRIST_MCP_OVER_FOREARM);
        *bits |= BIT2(pinky, index);
        return true;
    }
    /* heel and toe tip lie 2 and 4 after the ankle */
    int heel = dist + (K_LHEEL - K_LANK), toe = dist + (K_LTOE - K_LANK);
    if (!all_in(f->obs, BIT2(heel, toe))) {
        return false;
    }
    /* halfway between the ankle and the sole point at c: foot COM is ~3 cm above the floor */
    *com = v_mid(q, v_lerp(f->p[heel], f->p[toe], c));
    *bits |= BIT2(heel, toe);
    return true;
}

/* One limb segment: an arm or leg bone between its joints, or a hand or foot
 * beyond the distal joint (wrist/ankle), from the BlazePose extremity keypoints
 * (blaze: BlazePose-33 input), else along the forearm/shank, else at the joint itself. */
static void add_limb_segment(frame *f, bool blaze, const seg_def *d, float m, float c)
{
    int prox = d->prox, dist = prox + NEXT_JOINT;
    bool hand = d->seg == GS_SEG_HAND, extremity = hand || d->seg == GS_SEG_FOOT;
    bool has_prox = f->have & BIT(prox);
    if (!(f->have & BIT(dist)) || (!extremity && !has_prox)) {
        return;
    }
    vec2 q = f->p[dist], com = q;
    /* prox -> dist: the bone, or the forearm/shank behind a hand/foot (used only with prox) */
    vec2 bone = v_sub(q, f->p[prox]);
    uint32_t bits = BIT(dist);
    bool rebuilt = is_rebuilt(f, prox, dist); /* also when prox is missing */
    if (!extremity) {
        com = v_add(f->p[prox], v_scale(bone, c));
        bits |= BIT(prox);
    } else if (GS_WITH_BLAZEPOSE33 && blaze && blaze_extremity(f, dist, hand, c, &com, &bits)) {
        rebuilt = !(f->obs & BIT(dist));
    } else if (has_prox) {
        com = v_add(q, v_scale(bone, hand ? c : FOOT_BELOW_ANKLE));
    }
    add_segment(f, m, com.x, com.y, rebuilt, bits);
}

static void add_limbs(frame *f, bool blaze, const seg_table *tb)
{
#ifndef __OPTIMIZE_SIZE__
#pragma GCC unroll 12 /* hosts: each segment's kind and joints constant, its tests folded */
#endif
    for (size_t i = 0; i < sizeof k_limb_segs / sizeof k_limb_segs[0]; i++) {
        const seg_def *d = &k_limb_segs[i];
        add_limb_segment(f, blaze, d, tb->mass_pct[d->seg], tb->c[d->seg]);
    }
}

/* ---- stature and axis ---------------------------------------------------------- */

/* Stature landmarks in summation order, head group first; fraction and prior per kind. */
enum { M_EYE, M_EAR, M_NOSE, M_ANKLE, M_HEEL, M_TOE, M_KINDS };
typedef struct {
    float frac, prior;
} mark_kind;
static const mark_kind k_mark_kinds[M_KINDS] = {
    { F_EYE, P_EYE }, { F_EAR, P_EAR }, { F_NOSE, P_NOSE }, { F_ANKLE, P_ANKLE }, { F_HEEL, P_HEEL }, { F_TOE, P_TOE },
};
static const uint8_t k_marks[][2] = {
    { K_LEYE, M_EYE },     { K_REYE, M_EYE },     { K_LEAR, M_EAR },   { K_REAR, M_EAR },
    { K_NOSE, M_NOSE },    { K_LANK, M_ANKLE },   { K_RANK, M_ANKLE }, { K_LHEEL, M_HEEL },
    { K_RHEEL, M_HEEL },   { K_LTOE, M_TOE },     { K_RTOE, M_TOE },
};

/* Weighted head and foot landmark centroids with their mean height fractions;
 * stature = their distance along the body axis / the fraction difference.
 * Called before any keypoint is rebuilt (have == obs). */
static bool anthro_stature(const frame *f, float *stature_px, vec2 *up)
{
    wsum g[2] = { { 0.0f, 0.0f, 0.0f, 0.0f }, { 0.0f, 0.0f, 0.0f, 0.0f } }; /* head, feet; e: height fraction */
#ifndef __OPTIMIZE_SIZE__
#pragma GCC unroll 11 /* hosts: each landmark's kind constant */
#endif
    for (size_t i = 0; i < sizeof k_marks / sizeof k_marks[0]; i++) {
        int k = k_marks[i][0], kind = k_marks[i][1];
        const mark_kind *mk = &k_mark_kinds[kind];
        /* (a landmark not observed adds 0 to sums that start at +0, never -0: no change) */
        wsum_add(&g[kind >= M_ANKLE], f->c[k] * mk->prior, f->p[k].x, f->p[k].y, mk->frac);
    }
    const wsum *h = &g[0], *ft = &g[1];
    if (!(h->w > 0.0f) || !(ft->w > 0.0f)) {
        return false;
    }
    vec2 hc = wsum_mean(h), fc = wsum_mean(ft);
    /* Axis along the posture plumb line ear -> ankle when seen: eyes, nose and
     * toes sit in front of it and would tilt it forward in a lateral view. */
    vec2 ha = hc, fa = fc;
    if (!pair_centre(f, f->have, K_LEAR, &ha)) {
        pair_centre(f, f->have, K_LEYE, &ha);
    }
    pair_centre(f, f->have, K_LANK, &fa);
    vec2 d = v_sub(ha, fa);
    float len = v_len(d);
    if (!(len > 0.0f)) {
        return false;
    }
    vec2 u = v_scale(d, 1.0f / len);
    if (!gs_finite2_f(u.x, u.y)) {
        return false; /* absurd coordinates overflow float (the stature would not be finite either) */
    }
    *up = u;
    *stature_px = v_dot(v_sub(hc, fc), u) / (h->e / h->w - ft->e / ft->w);
    return true;
}

/* The paper's baseline: 1.17 x distance nose -> mean of the visible ankles. */
static float nose_ankle_stature(const frame *f)
{
    vec2 a;
    if (!(f->obs & BIT(K_NOSE)) || !pair_centre(f, f->obs, K_LANK, &a)) {
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


/* trunk = shoulder centre - hip centre, trunk_len its length (0 without a trunk). */
static float upright_score(const frame *f, vec2 trunk, float trunk_len, bool axis_from_body, vec2 up)
{
    float knee = NAN, other = NAN;
#ifndef __OPTIMIZE_SIZE__
#pragma GCC unroll 2 /* hosts: each side's bits constant */
#endif
    for (int i = 0; i < 2; i++) { /* the right keypoint follows the left one */
        int sh = K_LSHO + i, hp = K_LHIP + i, kn = K_LKNE + i, an = K_LANK + i;
        if (!all_in(f->obs >> i, BIT(K_LHIP) | BIT(K_LKNE) | BIT(K_LANK))) {
            continue;
        }
#ifndef __OPTIMIZE_SIZE__
        knee = min_nan(knee, ramp_acos(angle_cos(f, hp, kn, an), KNEE_DEG_0, KNEE_DEG_1, COS_KNEE_0, COS_KNEE_1));
        if ((f->obs >> i) & BIT(K_LSHO)) {
            other = min_nan(other, ramp_acos(angle_cos(f, sh, hp, kn), HIP_DEG_0, HIP_DEG_1, COS_HIP_0, COS_HIP_1));
        }
#else
        knee = min_nan(knee, ramp(angle_deg(f, hp, kn, an), KNEE_DEG_0, KNEE_DEG_1));
        if ((f->obs >> i) & BIT(K_LSHO)) {
            other = min_nan(other, ramp(angle_deg(f, sh, hp, kn), HIP_DEG_0, HIP_DEG_1));
        }
#endif
        if (trunk_len > 0.0f) {
            float leg = kp_dist(f, hp, kn) + kp_dist(f, kn, an);
            other = min_nan(other, ramp(leg / trunk_len, LEG_TRUNK_0, LEG_TRUNK_1));
        }
    }
    if (isnan(knee)) {
        return NAN; /* legs missing: cannot tell */
    }
    if (axis_from_body && trunk_len > 0.0f) {
#ifndef __OPTIMIZE_SIZE__
        other = min_nan(other, ramp_acos(v_dot(trunk, up) / trunk_len, TRUNK_TILT_DEG_0, TRUNK_TILT_DEG_1, COS_TILT_0,
                                         COS_TILT_1));
#else
        float tilt_deg = acos_deg(v_dot(trunk, up) / trunk_len);
        other = min_nan(other, ramp(tilt_deg, TRUNK_TILT_DEG_0, TRUNK_TILT_DEG_1));
#endif
    }
    return min_nan(knee, other);
}

/* Rebuild lost limb joints from the other side (mirror across the mid-plane). */
static void mirror_limbs(frame *f, vec2 axis, float trunk_len)
{
    /* shoulder width / trunk length: ~0.7 frontal, ~0 lateral; else from the hips */
    float width = NAN;
    if (all_in(f->obs, BIT2(K_LSHO, K_RSHO))) {
        width = kp_dist(f, K_LSHO, K_RSHO) / trunk_len;
    } else if (all_in(f->obs, BIT2(K_LHIP, K_RHIP))) {
        width = SHOULDER_OVER_HIP_WIDTH * kp_dist(f, K_LHIP, K_RHIP) / trunk_len;
    }
    /* no pair seen: one side hidden, i.e. a lateral view */
    float across = isnan(width) ? 1.0f : 1.0f - 2.0f * ramp(width, LATERAL_MAX_WIDTH, MIRROR_MIN_WIDTH);
    static const uint8_t prox[8] = { K_LSHO, K_LELB, K_RSHO, K_RELB, K_LHIP, K_LKNE, K_RHIP, K_RKNE };
#ifndef __OPTIMIZE_SIZE__
#pragma GCC unroll 8 /* hosts: each joint's bits constant */
#endif
    for (int i = 0; i < 8; i++) {
        mirror_joint(f, prox[i], axis, across);
    }
}

#endif /* GS_WITH_POSE */

/* ---- public ---------------------------------------------------------------------- */

size_t gs_layout_kp_count(gs_layout layout)
{
    switch (layout) {
    /* a layout left out of the build (gs_features.h) is unknown */
    case GS_LAYOUT_POINT: return GS_WITH_POINT ? 1u : 0u;
    case GS_LAYOUT_COCO17: return GS_WITH_COCO17 ? 17u : 0u;
    case GS_LAYOUT_BLAZEPOSE33: return GS_WITH_BLAZEPOSE33 ? 33u : 0u;
    default: return 0;
    }
}

static float table_total_pct(const seg_table *t)
{
    float s = t->mass_pct[GS_SEG_HEAD] + t->mass_pct[GS_SEG_TRUNK];
#pragma GCC unroll 6 /* a constant table's sum folds to a constant */
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
    const seg_table *tb = k_tables[t];
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

#if GS_WITH_POSE
/* Renormalise over the segments present; w falls with the square of what is missing.
 * A COM out of float range leaves out unknown (NaN, w = 0). */
static void com_result(const frame *f, float total, gs_com_out *out)
{
    vec2 com = wsum_mean(&f->com);
    float csum = 0.0f;
    int n = 0;
#ifndef __OPTIMIZE_SIZE__
    for (uint32_t u = f->used; u != 0u; u &= u - 1u) { /* the set bits in ascending order, as below */
        csum += f->c[__builtin_ctz(u)];
        n++;
    }
#else
    int k = 0;
    for (uint32_t u = f->used; u != 0u; u >>= 1, k++) { /* up to the last used keypoint */
        if (u & 1u) {
            csum += f->c[k];
            n++;
        }
    }
#endif
    float frac = f->com.e / total;
    float w = frac * frac * (csum / (float)n); /* n > 0: the trunk's corners include an observed one */
    /* a segment missing outright (not even rebuilt from its mirror, e.g. the head
     * out of the frame at the apex) biases the renormalised COM by centimetres:
     * such frames count only when nothing better exists */
    if (f->com.w < 0.999f * total) w *= DROPPED_SEGMENT_WEIGHT;
    if (gs_finite2_f(com.x, com.y)) {
        out->x_px = com.x;
        out->y_px = com.y;
        out->w = w > 1.0f ? 1.0f : w; /* never below 0: squares times confidences in (0, 1] */
    }
}

/* (the table by its enum: a build whose table is a constant folds its sums) */
static void skeleton_com(gs_layout layout, gs_mass_table table, gs_stature_method stature,
                         float min_conf, const gs_kp *kp, gs_com_out *out)
{
    const seg_table *tb = k_tables[table];
    frame f;
    bool blaze = GS_WITH_BLAZEPOSE33 && (!GS_WITH_COCO17 || layout == GS_LAYOUT_BLAZEPOSE33);
    load(&f, blaze, min_conf, kp);

    /* Stature and body axis do not need the trunk. */
    vec2 up = { NAN, NAN };
    float st = NAN;
    bool axis_from_body = anthro_stature(&f, &st, &up);
    if (stature == GS_STATURE_NOSE_ANKLE_117) {
        st = nose_ankle_stature(&f);
    }
    if (gs_finite_f(st)) { /* else NaN: absurd coordinates overflow float */
        out->stature_px = st;
    }

    /* Trunk: rebuild a lone missing shoulder/hip, then the two centres. */
    rebuild_trunk_corner(&f, K_LSHO, K_LHIP, SHOULDER_OVER_HIP_WIDTH);
    rebuild_trunk_corner(&f, K_LHIP, K_LSHO, 1.0f / SHOULDER_OVER_HIP_WIDTH);
    vec2 s, p, trunk = { 0.0f, 0.0f }; /* (s and p are read only when both were found) */
    bool have_trunk = pair_centre(&f, f.have, K_LSHO, &s) && pair_centre(&f, f.have, K_LHIP, &p);
    float trunk_len = 0.0f;
    if (have_trunk) {
        trunk = v_sub(s, p);
        trunk_len = v_len(trunk);
    }
    if (trunk_len > 0.0f) {
        vec2 axis = v_scale(trunk, 1.0f / trunk_len);
        if (!axis_from_body) {
            up = axis; /* fallback axis: hip centre -> shoulder centre */
        }
        /* lost limb joints from the other side (writes only keypoints not observed) */
        mirror_limbs(&f, axis, trunk_len);
    }
    if (!isnan(up.x)) {
        out->up_x = up.x;
        out->up_y = up.y;
    }
    out->upright = upright_score(&f, trunk, trunk_len, axis_from_body, up);

    if (!have_trunk) {
        return; /* w = 0: without the trunk (half the mass) the COM is a guess */
    }
    const uint32_t corners = BIT2(K_LSHO, K_RSHO) | BIT2(K_LHIP, K_RHIP);
    bool trunk_rebuilt = !all_in(f.obs, corners);

    vec2 hc; /* (head_centre always sets it) */
    uint32_t head_bits = head_centre(&f, &hc);
    if (head_bits) {
        add_segment(&f, tb->mass_pct[GS_SEG_HEAD], hc.x, hc.y, (head_bits & ~EARS) != 0u, head_bits);
    }
    vec2 tc = v_lerp(s, p, tb->c[GS_SEG_TRUNK]);
    add_segment(&f, tb->mass_pct[GS_SEG_TRUNK], tc.x, tc.y, trunk_rebuilt, corners);
    add_limbs(&f, blaze, tb);
    com_result(&f, table_total_pct(tb), out);
}
#endif

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

    if (GS_WITH_POINT && layout == GS_LAYOUT_POINT) {  /* (a layout not built in was refused above) */
        out->upright = 1.0f; /* a rigid object is always "upright" */
        if (kp_usable(kp, min_conf)) {
            out->x_px = kp->x_px;
            out->y_px = kp->y_px;
            out->w = conf01(kp->c);
        }
        return GS_OK;
    }
#if GS_WITH_POSE
    skeleton_com(layout, table, stature, min_conf, kp, out);
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
