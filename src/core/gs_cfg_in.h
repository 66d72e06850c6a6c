/* gs_cfg_in.h - the configuration as the core's code reads it. A device whose profile is
 * fixed at build time (GS_BAKED_PROFILE: fw_profile.h, whose FW_PROFILE_CONFIG
 * tools/fw/fw_bake.c parsed and checked) reads that constant, so the compiler folds each
 * setting into the code (no branch for a fit, mass table or gravity formula the profile
 * does not use); elsewhere the configuration the pipeline was given. */
#ifndef GS_CFG_IN_H
#define GS_CFG_IN_H

#include <stddef.h>

#include "gravscale/gs_config.h"

#ifdef GS_BAKED_PROFILE
#include "fw_profile.h"
static const gs_core_config gs_baked_cfg = FW_PROFILE_CONFIG;
/* held: the configuration the caller passed (checked against the baked one at init) */
#define GS_CFG_IN(held) ((void)(held), &gs_baked_cfg)
/* a baked build runs its own profile only: any other is refused, never ignored */
static inline bool gs_cfg_is_baked(const gs_core_config *c)
{
    /* byte by byte, a dozen bytes of code (newlib's memcmp would add 96) */
    const unsigned char *a = (const unsigned char *)c, *b = (const unsigned char *)&gs_baked_cfg;
    size_t n = offsetof(gs_core_config, format) + sizeof c->format;  /* not the tail padding (double gs_real) */
    while (n > 0u && *a == *b) n--, a++, b++;
    return n == 0u;
}
#else
#define GS_CFG_IN(held) (held)
static inline bool gs_cfg_is_baked(const gs_core_config *c) { (void)c; return true; }
#endif

#endif
