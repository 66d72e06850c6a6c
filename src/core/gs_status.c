/* gs_status.c - names of status codes, reject reasons and output formats. */
#include "gravscale/gs_emit.h"
#include "gravscale/gs_event.h"
#include "gravscale/gs_types.h"

#include <string.h>

const char *gs_status_str(gs_status s)
{
    switch (s) {
    case GS_OK: return "ok";
    case GS_EINVAL: return "invalid argument or value";
    case GS_ERANGE: return "value out of range";
    case GS_ENOMEM: return "buffer too small";
    case GS_ESYNTAX: return "syntax error";
    case GS_ENOKEY: return "unknown key or section";
    case GS_EORDER: return "time went backwards";
    case GS_ESTATE: return "not allowed in this state";
    }
    return "unknown status";
}

/* the names are part of the output protocol (docs/protocol.md) */
const char *gs_reject_reason_name(gs_reject_reason r)
{
    switch (r) {
    case GS_REJ_NONE: return "none";
    case GS_REJ_FEW_SAMPLES: return "few_samples";
    case GS_REJ_LARGE_RESIDUAL: return "large_residual";
    case GS_REJ_IMPLAUSIBLE_A: return "implausible_acceleration";
    case GS_REJ_NO_SIZE: return "no_size";
    case GS_REJ_UNCERTAIN_A: return "uncertain_acceleration";
    case GS_REJ_GAP: return "gap";
    case GS_REJ_OTHER_MOTION: return "other_motion";
    case GS_REJ_NOT_PLANAR: return "not_planar";
    case GS_REJ_GRAVITY_DIR: return "gravity_direction";
    case GS_REJ_FALL: return "fall";
    case GS_REJ_NO_FEET_FLIGHT: return "no_feet_flight";
    }
    return "unknown";
}

const char *gs_format_name(gs_format f)
{
    switch (f) {
    case GS_FMT_JSON: return "json";
    case GS_FMT_NMEA: return "nmea";
    }
    return "unknown";
}

bool gs_format_from_name(const char *s, size_t len, gs_format *out)
{
    if (!s || !out || len != 4) return false;
    /* a format left out of the build (gs_features.h) is an unknown name */
    if (GS_WITH_JSON && memcmp(s, "json", 4) == 0) {
        *out = GS_FMT_JSON;
        return true;
    }
    if (GS_WITH_NMEA && memcmp(s, "nmea", 4) == 0) {
        *out = GS_FMT_NMEA;
        return true;
    }
    return false;
}
