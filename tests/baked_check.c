/* baked_check.c - a core that reads its profile as a compile-time constant
 * (GS_BAKED_PROFILE, src/core/gs_cfg_in.h) gives the same events as the core that
 * reads the configuration it was given. Built twice by CMake from the same baked
 * profile (tests/data/fw_baked_core.cfg through fw_bake): baked_core_on (the core
 * folds the profile) and baked_core_off (the plain core); each prints the firmware
 * workload's lines (tools/fw/fw_scenario.c), which CTest requires to be identical
 * and to hold jumps. The baked build must also refuse any other configuration. */
#include <stdio.h>
#include <string.h>

#include "fw_profile.h"
#include "fw_scenario.h"
#include "gravscale/gravscale.h"

static void on_line(const char *line, size_t len)
{
    fwrite(line, 1, len, stdout);
}

/* gs_pipeline_init with the baked profile, and with one field changed */
static int check_refusal(void)
{
    static uint64_t storage[(512u * sizeof(gs_sample) + 64u) / 8u + 1u];
    static gs_pipeline p;
    gs_core_config cfg = FW_PROFILE_CONFIG;
    gs_status same = gs_pipeline_init(&p, &cfg, GS_LAYOUT_COCO17, storage, sizeof storage, NULL, NULL);
    cfg.min_conf = 0.5f;
    gs_status other = gs_pipeline_init(&p, &cfg, GS_LAYOUT_COCO17, storage, sizeof storage, NULL, NULL);
#ifdef GS_BAKED_PROFILE
    const gs_status other_want = GS_EINVAL;  /* another profile than the baked one: refused */
#else
    const gs_status other_want = GS_OK;
#endif
    if (same != GS_OK || other != other_want) {
        fprintf(stderr, "baked_check: init with the baked profile %d (want %d), with another %d (want %d)\n",
                (int)same, (int)GS_OK, (int)other, (int)other_want);
        return 1;
    }
    return 0;
}

int main(void)
{
    int fail = check_refusal();
    unsigned st = fw_scenario_run_both(on_line);
    if (st != 0u) fprintf(stderr, "baked_check: the workload's status %u\n", st);
    return fail || st != 0u;
}
