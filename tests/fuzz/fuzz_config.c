/* fuzz_config.c - libFuzzer harness for gs_cfg_parse with the [core] handler:
 * no crash, no read past len, the error record is always NUL-terminated, and a
 * successful parse leaves a config whose fields are within their ranges.
 * Built by tests/fuzz/run.sh (clang), not by CMake. -DGS_FUZZ_MAIN: a main()
 * for gcc that replays files or mutated config text. */
#include "gravscale/gs_config.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static gs_status other_set(void *ctx, const char *key, size_t key_len, const char *value, size_t value_len,
                           char *msg, size_t cap)
{
    (void)ctx;
    (void)value;
    (void)value_len;
    if (key_len == 1 && key[0] == 'x') return GS_OK;
    if (cap) msg[0] = '\0';
    return GS_ENOKEY;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *s = malloc(size ? size : 1);
    if (!s) return 0;
    if (size) memcpy(s, data, size);
    gs_core_config c;
    gs_core_config_default(&c);
    gs_cfg_section sec[2] = {{"core", gs_core_config_set, &c}, {"other", other_set, NULL}};
    gs_cfg_error err;
    gs_status st = gs_cfg_parse(s, size, sec, 2, &err);
    if (!memchr(err.section, 0, sizeof err.section) || !memchr(err.key, 0, sizeof err.key) ||
        !memchr(err.msg, 0, sizeof err.msg))
        abort();
    if (st == GS_OK) {
        if (err.line != 0) abort();
        /* ranges hold after any accepted text; only cross-field checks may fail */
        gs_status cs = gs_core_config_check(&c, &err);
        if (cs != GS_OK && strcmp(err.key, "max_flight_s") != 0 && strcmp(err.key, "size_max_m") != 0) abort();
        double g = gs_core_config_g(&c);
        if (!(g > 9.7 - 0.03 && g < 9.9)) abort();
    } else if (err.msg[0] == '\0') {
        abort();
    }
    free(s);
    return 0;
}
