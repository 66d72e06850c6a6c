/* fw_scenario.h - the firmware link test's workload, portable so the same bytes
 * can be produced on the host (fw_host.c) and on the target (fw_main.c). */
#ifndef FW_SCENARIO_H
#define FW_SCENARIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Receives every emitted line (with its '\n'), as a serial sink would send it. */
typedef void (*fw_line_fn)(const char *line, size_t len);

/* Parse the profile, run the pipeline on static storage over 6 s of a synthetic
 * bouncing ball (pose = false) or hopping COCO-17 skeleton (pose = true) at
 * 60 fps, flush. Returns the OR of every status (0 = all GS_OK). */
uint32_t fw_scenario_run(bool pose, fw_line_fn line);

/* The ball, a line "--- pose", then the skeleton: what the host twin and QEMU print. */
uint32_t fw_scenario_run_both(fw_line_fn line);

#endif
