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

#ifdef GS_FUZZ_MAIN
#include <stdio.h>
int main(int argc, char **argv)
{
    static uint8_t buf[1 << 16];
    for (int i = 1; i < argc; i++) {
        FILE *f = fopen(argv[i], "rb");
        if (!f) continue;
        size_t n = fread(buf, 1, sizeof buf, f);
        fclose(f);
        LLVMFuzzerTestOneInput(buf, n);
    }
    if (argc > 1) return 0;
    static const char seed[] = "[core]\ng_m_s2 = 9.81\nlatitude_deg = 45 # c\r\nfit = ransac\n[other]\nx = 1\n"
                               "ring_capacity = 1024\n; end\n";
    static const char alpha[] = "[]=#;\n\r \t.-0123456789eaxcore_\0";
    uint64_t r = 88172645463325252ull;
    for (int it = 0; it < 100000; it++) {
        size_t n = sizeof seed - 1;
        memcpy(buf, seed, n);
        int muts = 1 + (int)(r % 6u);
        for (int m = 0; m < muts; m++) {
            r ^= r << 13; r ^= r >> 7; r ^= r << 17;
            size_t pos = (size_t)(r % n);
            r ^= r << 13; r ^= r >> 7; r ^= r << 17;
            buf[pos] = (uint8_t)alpha[r % (sizeof alpha - 1)];
        }
        r ^= r << 13; r ^= r >> 7; r ^= r << 17;
        LLVMFuzzerTestOneInput(buf, (size_t)(r % (n + 1)));
    }
    puts("fuzz_config: 100000 mutated inputs ok");
    return 0;
}
#endif
