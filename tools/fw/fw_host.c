/* fw_host.c - the firmware's workload (fw_scenario.c) on the host: the lines it
 * emits, the ball's then (after "--- pose") the skeleton's, on stdout, to
 * compare with the target's (tools/firmware_size.sh under QEMU). */
#include <stdio.h>

#include "fw_scenario.h"

static void on_line(const char *line, size_t len)
{
    fwrite(line, 1, len, stdout);
}

int main(void)
{
    return fw_scenario_run_both(on_line) == 0u ? 0 : 1;
}
