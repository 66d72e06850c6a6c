/* gs_types.h - status codes, keypoints and the per-frame COM sample shared by every core module. */
#ifndef GS_TYPES_H
#define GS_TYPES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gs_features.h"
#include "gs_math.h"

#define GS_VERSION "0.1.0"

/* The arithmetic of the fits and every measured value: double on hosts, float on
 * single-precision FPUs (the cortex-m4 build sets -DGS_REAL=float; docs/firmware.md
 * has the numbers). Times are not gs_real: they are integer microseconds (gs_time.h). */
#ifndef GS_REAL
#define GS_REAL double
#endif
typedef GS_REAL gs_real;
#define GS_R(x) ((gs_real)(x))
/* sqrt and fabs of a gs_real without <tgmath.h> */
#define GS_SQRT(x) (sizeof(gs_real) < sizeof(double) ? (gs_real)sqrtf((float)(x)) : (gs_real)sqrt((double)(x)))
#define GS_FABS(x) ((x) < GS_R(0.0) ? -(x) : (x))
/* cos and sin of a double argument, in float where gs_real is float (gs_math.c: no libm trig linked) */
#define GS_COS(x) (sizeof(gs_real) < sizeof(double) ? (double)gs_cosf((float)(x)) : cos((double)(x)))
#define GS_SIN(x) (sizeof(gs_real) < sizeof(double) ? (double)gs_sinf((float)(x)) : sin((double)(x)))

typedef enum {
    GS_OK = 0,
    GS_EINVAL,   /* bad argument or value */
    GS_ERANGE,   /* value outside its allowed range */
    GS_ENOMEM,   /* caller storage or buffer too small */
    GS_ESYNTAX,  /* malformed text */
    GS_ENOKEY,   /* unknown key or section */
    GS_EORDER,   /* time went backwards */
    GS_ESTATE    /* call not allowed in the current state */
} gs_status;

const char *gs_status_str(gs_status s);

/* One detected keypoint in pixels (y down); c = confidence 0..1, c == 0 means missing. */
typedef struct {
    float x_px;
    float y_px;
    float c;
} gs_kp;

typedef enum {
    GS_LAYOUT_POINT = 0,  /* one tracked point (ball centre): 1 keypoint */
    GS_LAYOUT_COCO17,     /* COCO-17 order: nose, l/r eye, l/r ear, l/r shoulder, l/r elbow, l/r wrist, l/r hip, l/r knee, l/r ankle */
    GS_LAYOUT_BLAZEPOSE33 /* BlazePose-33 order (heels 29/30, foot index 31/32) */
} gs_layout;

/* A per-frame sample at full precision, as a source delivers it and as
 * gs_ring_get gives it back: the COM (or object centre) and the object's
 * pixel size this frame (stature in px when upright, ball diameter); NaN where
 * unknown. */
typedef struct {
    int64_t t_us;    /* source timestamp, microseconds (gs_time.h) */
    float x_px;      /* COM x */
    float y_px;      /* COM y (down) */
    float w;         /* weight 0..1 (0 = unusable frame) */
    float size_px;   /* object size in px this frame, NaN unknown */
    float up_x;      /* unit vector of the body axis feet->head in the image, NaN unknown */
    float up_y;
    float upright;   /* 0..1 how upright/straight the body stands (1 for rigid objects), NaN unknown */
} gs_sample_full;

/* The same sample as stored in the ring: 16 bytes (512 samples = 8 KB). Read it
 * through gs_ring_get / the gs_ring_sample_* accessors (gs_ring.h), which know
 * the ring's time base. The body axis (up_x, up_y) is consumed when the frame
 * is examined, so only the newest frame's is kept (in the ring, not here). */
typedef struct {
    uint32_t t_us;       /* microseconds since the ring's time base, modulo 2^32 */
    float x_px;          /* COM x, NaN unknown */
    float y_px;          /* COM y (down), NaN unknown */
    uint16_t size_q;     /* size: 1/16 px below 2048 px, then 1/4 px up to 10240 px; 0xFFFF unknown */
    uint8_t w_q;         /* w in 1/255 (a positive w never rounds to 0) */
    uint8_t upright_q;   /* upright in 1/250, floored (thresholds at tenths stay exact); 255 unknown */
} gs_sample;

#ifdef __cplusplus
static_assert(sizeof(gs_sample) == 16, "the ring sample must stay 16 bytes");
#else
_Static_assert(sizeof(gs_sample) == 16, "the ring sample must stay 16 bytes");
#endif

#endif
