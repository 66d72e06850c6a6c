/* gs_com.h - centre of mass and body pixel size from one frame of keypoints.
 * COM = sum over segments of mass_fraction * segment_centre, where a segment's
 * centre lies at a published fraction along proximal->distal keypoints. */
#ifndef GS_COM_H
#define GS_COM_H

#include "gs_types.h"

typedef enum {
    GS_MASS_DELEVA = 0, /* de Leva 1996 (adjusted Zatsiorsky-Seluyanov), sex-averaged: default */
    GS_MASS_CLAUSER,    /* Clauser, McConville & Young 1969 (the paper's) */
    GS_MASS_DEMPSTER    /* Dempster 1955 via Winter */
} gs_mass_table;

typedef enum {
    GS_STATURE_ANTHRO = 0, /* ours: several head and foot landmarks with anthropometric ratios */
    GS_STATURE_NOSE_ANKLE_117 /* the paper's: 1.17 x nose-to-ankle (baseline) */
} gs_stature_method;

/* Number of keypoints of a layout (1, 17 or 33), 0 for an unknown layout. */
size_t gs_layout_kp_count(gs_layout layout);

typedef struct {
    float x_px, y_px;   /* COM, NaN when it cannot be computed */
    float w;            /* 0..1 reliability of this frame's COM (observed mass fraction, confidences) */
    float stature_px;   /* estimated floor-to-vertex length as if upright, NaN when head or feet missing */
    float up_x, up_y;   /* unit body axis feet->head, NaN unknown */
    float upright;      /* 0..1: 1 = legs straight and trunk aligned with the body axis, NaN unknown */
} gs_com_out;

/* kp holds gs_layout_kp_count(layout) keypoints. Keypoints with c < min_conf count
 * as missing. For GS_LAYOUT_POINT the COM is the point itself, stature_px NaN,
 * upright 1. Returns GS_EINVAL on a bad layout/table/NULL; a frame with too
 * little visible is not an error: out->w = 0 and NaN fields. */
gs_status gs_com_compute(gs_layout layout, gs_mass_table table, gs_stature_method stature,
                         float min_conf, const gs_kp *kp, gs_com_out *out);

/* Body segments of the mass model; limbs count one side. */
typedef enum {
    GS_SEG_HEAD = 0,  /* head and neck */
    GS_SEG_TRUNK,
    GS_SEG_UPPER_ARM,
    GS_SEG_FOREARM,
    GS_SEG_HAND,
    GS_SEG_THIGH,
    GS_SEG_SHANK,
    GS_SEG_FOOT,
    GS_SEG_COUNT
} gs_segment;

/* Mass fraction of one segment (one side for limbs) in a table, normalised so
 * head + trunk + 2 x (limb segments) = 1; NaN for a bad table or segment. */
float gs_mass_fraction(gs_mass_table t, gs_segment s);

/* Name <-> enum for config and logs ("deleva", "clauser", "dempster";
 * "anthro", "nose_ankle_1.17"; "point", "coco17", "blazepose33"). */
const char *gs_mass_table_name(gs_mass_table t);
bool gs_mass_table_from_name(const char *s, size_t len, gs_mass_table *out);
const char *gs_stature_method_name(gs_stature_method m);
bool gs_stature_method_from_name(const char *s, size_t len, gs_stature_method *out);
const char *gs_layout_name(gs_layout l);
bool gs_layout_from_name(const char *s, size_t len, gs_layout *out);

#endif
