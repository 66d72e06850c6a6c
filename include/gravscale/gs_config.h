/* gs_config.h - key = value configuration in [sections], parsed without heap.
 * The core tokenises and routes each key to the handler of its section; each
 * layer (core, ball, pose, sinks) validates its own keys. */
#ifndef GS_CONFIG_H
#define GS_CONFIG_H

#include "gs_types.h"
#include "gs_com.h"
#include "gs_fit.h"
#include "gs_emit.h"

typedef struct {
    uint32_t line;        /* 1-based line of the first error, 0 if not tied to a line */
    char section[24];
    char key[40];
    char msg[96];
} gs_cfg_error;

/* Handle one key of a section. value is not NUL-terminated; leading and
 * trailing blanks are stripped. Return GS_OK, GS_ENOKEY (unknown key),
 * GS_EINVAL (bad value) or GS_ERANGE (out of range), optionally writing a
 * short reason to msg (cap bytes). */
typedef gs_status (*gs_cfg_handler)(void *ctx, const char *key, size_t key_len,
                                    const char *value, size_t value_len,
                                    char *msg, size_t cap);

typedef struct {
    const char *name;     /* section name without brackets, e.g. "core" */
    gs_cfg_handler fn;
    void *ctx;
} gs_cfg_section;

/* Parse text[0..len). Syntax: blank lines; comments starting with '#' or ';'
 * (whole line, or after a value preceded by a blank); "[name]" section headers;
 * "key = value". A key before any section, an unknown section, a duplicate key
 * in a section, a line without '=', and every handler error stop the parse:
 * returns the error and fills err (line, section, key, msg). */
gs_status gs_cfg_parse(const char *text, size_t len, const gs_cfg_section *sections,
                       size_t n_sections, gs_cfg_error *err);

/* The [core] section. */
typedef struct {
    gs_real g_m_s2;            /* g; NaN = from latitude/altitude when set, else 9.81 */
    gs_real latitude_deg;      /* NaN unset */
    gs_real altitude_m;        /* 0 default */
    gs_mass_table mass_table;  /* mass_table = deleva|clauser|dempster */
    gs_stature_method stature; /* stature = anthro|nose_ankle_1.17 */
    float min_conf;            /* keypoints below count as missing (0..1) */
    gs_fit_method fit_method;  /* fit = irls|ransac|plain */
    uint32_t ring_capacity;    /* samples, power of two 64..65536 */
    float min_flight_s;        /* shortest flight accepted */
    float max_flight_s;        /* longest flight considered */
    uint32_t min_samples;      /* fewest in-flight samples accepted */
    float max_rms_rel;         /* reject when fit RMS > this x object size */
    float max_a_se_rel;        /* reject when SE(a)/a above this */
    float size_min_m, size_max_m;  /* plausible object size; a flight whose height falls outside is rejected */
    float max_gap_s;           /* a time gap longer than this ends any flight */
    float landing_latency_s;   /* decide a landing at most this long after it */
    float session_absence_s;   /* no body for this long ends a visit (session) */
    float session_new_body_rel;/* after a gap, a standing size this far off starts a new visit */
    gs_format format;          /* format = json|nmea (default output line format) */
} gs_core_config;

void gs_core_config_default(gs_core_config *c);
/* The [core] handler; ctx is a gs_core_config*. */
gs_status gs_core_config_set(void *ctx, const char *key, size_t key_len,
                             const char *value, size_t value_len, char *msg, size_t cap);
/* Cross-field checks after parsing (e.g. min_flight_s < max_flight_s). */
gs_status gs_core_config_check(const gs_core_config *c, gs_cfg_error *err);
/* The g in force: g_m_s2 if set, else from latitude/altitude, else 9.81. */
gs_real gs_core_config_g(const gs_core_config *c);

/* Normal gravity (WGS-84 Somigliana formula) with the free-air altitude correction. */
gs_real gs_gravity_m_s2(gs_real latitude_deg, gs_real altitude_m);

#endif
