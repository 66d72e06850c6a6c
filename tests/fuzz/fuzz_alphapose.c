/* fuzz_alphapose.c - libFuzzer harness for the AlphaPose reader
 * (src/io/gs_kp_alphapose.c and the person choice in gs_kpread.c) and the core
 * behind it: the first byte picks --fps, --track and the core's fit, the rest
 * is the result list. Properties: no crash or leak; errors name the file; frames
 * come in increasing frame order with t = frame / fps, confidences in 0..1,
 * coordinates NaN or finite; every core event formats (fuzz_pipe.h).
 * Built by tests/fuzz/run.sh (clang), not by CMake. */
#include "fuzz_kpread.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    uint8_t sel = data[0];
    static const double fps_tab[] = {30.0, 25.0, 1e-3, 1e6};
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    o.format = GS_KPF_ALPHAPOSE;
    o.fps = fps_tab[sel & 3u];
    o.track = (sel >> 2) & 1u ? (long)((sel >> 3) & 3u) : -1;
    const char *path = fz_write_temp(data + 1, size - 1, ".json");

    return fz_json_reader_run(path, &o, (uint8_t)(sel >> 5), false);
}
