/* fuzz_core.c - libFuzzer harness for the core alone (gs_pipeline: COM, ring,
 * flight detection, robust fits, aggregate, sessions) fed the way a live
 * detector might feed it: the input sets up synthetic jumps (a person template
 * from tests/data/sample_jumps.csv moved along parabolas, or a ball) at some
 * frame rate and noise, then damages frames: NaN, inf or huge coordinates,
 * zero or out-of-range confidences, repeated, reversed, NaN or far-jumping
 * times, outliers. Properties: no crash or sanitizer report; pushes answer
 * GS_OK, GS_EINVAL or GS_EORDER; every event formats (fuzz_pipe.h); one summary.
 * Built by tests/fuzz/run.sh (clang), not by CMake. */
#include "fuzz_pipe.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* a standing person, COCO-17, 1080p at 4 m (first frame of tests/data/sample_jumps.csv) */
static const float k_pose[17][2] = {
    {959.04f, 323.89f}, {971.34f, 307.50f}, {949.14f, 306.04f}, {983.91f, 315.01f}, {942.35f, 320.29f},
    {1023.12f, 384.94f}, {902.81f, 389.03f}, {1039.31f, 480.72f}, {891.25f, 482.00f}, {1055.44f, 560.54f},
    {878.89f, 560.77f}, {995.82f, 542.98f}, {938.59f, 539.33f}, {997.95f, 667.66f}, {926.03f, 664.73f},
    {1008.28f, 804.26f}, {919.11f, 799.90f}};

#define MAX_FRAMES 1500
#define MAX_DAMAGE 64

static double rnd(uint64_t *s) /* xorshift in [-1, 1) */
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) * 0x1p-52 - 1.0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in in = {data, size};
    uint8_t sel = fz_u8(&in);
    gs_layout lay = sel % 3u == 0 ? GS_LAYOUT_POINT : sel % 3u == 1 ? GS_LAYOUT_COCO17 : GS_LAYOUT_BLAZEPOSE33;
    size_t nkp = gs_layout_kp_count(lay);
    static const double fps_tab[] = {30.0, 60.0, 120.0, 25.0, 240.0, 29.97, 10.0, 1000.0};
    double fps = fps_tab[fz_u8(&in) & 7u];
    double a_px = 300.0 + 40.0 * fz_u8(&in);              /* 300..10500 px/s^2 */
    double t_fl = 0.1 + 0.005 * fz_u8(&in);               /* flight 0.1..1.4 s */
    int jumps = 1 + fz_u8(&in) % 3u;
    double noise = 0.05 * (fz_u8(&in) % 64u);             /* px */
    double roll = (fz_u8(&in) % 91u - 45.0) * 0.017453292519943295;
    double t0 = fz_u8(&in) & 1u ? 1.7e9 : 0.0;            /* a wall-clock time base too */
    uint64_t seed = 0x9e3779b97f4a7c15ull ^ fz_u32(&in);
    struct { uint16_t frame; uint8_t kind, kp; double v; } dmg[MAX_DAMAGE];
    size_t nd = 0;
    while (in.n >= 4 && nd < MAX_DAMAGE) {
        dmg[nd].frame = (uint16_t)(fz_u8(&in) << 8 | fz_u8(&in));
        dmg[nd].kind = fz_u8(&in) % 10u;
        dmg[nd].kp = (uint8_t)(fz_u8(&in) % nkp);
        dmg[nd].v = fz_double(&in);
        nd++;
    }

    fz_pipe fp;
    fz_pipe_begin(&fp, lay, sel >> 2);
    fp.frames = 0;
    double stand = 1.5, period = stand + t_fl + 0.5;
    int n = (int)((period * jumps + stand) * fps);
    if (n > MAX_FRAMES) n = MAX_FRAMES;
    double body = 480.0, ball = 100.0; /* ball: 0.34 m at a = 2860 px/s^2, inside the default size range */
    double ca = cos(roll), sa = sin(roll);
    for (int i = 0; i < n; i++) {
        double t = i / fps;
        double tj = fmod(t, period) - stand; /* time into this period's flight */
        double up = 0.0;                     /* px above the floor */
        if (t < period * jumps && tj > 0.0 && tj < t_fl) up = 0.5 * a_px * tj * (t_fl - tj);
        gs_kp kp[33];
        for (size_t k = 0; k < nkp; k++) {
            double x, y;
            if (lay == GS_LAYOUT_POINT) {
                x = 0.0;
                y = -ball / 2;
            } else {
                const float *q = k_pose[k % 17];
                x = (q[0] - 960.0) * body / 480.0;
                y = (q[1] - 804.0) * body / 480.0;
            }
            y -= up;
            kp[k].x_px = (float)(960.0 + ca * x - sa * y + noise * rnd(&seed));
            kp[k].y_px = (float)(900.0 + sa * x + ca * y + noise * rnd(&seed));
            kp[k].c = 0.9f;
        }
        double ts = t0 + t;
        float size = (float)ball;
        for (size_t d = 0; d < nd; d++) {
            if (dmg[d].frame % (unsigned)(n ? n : 1) != (unsigned)i) continue;
            gs_kp *k = &kp[dmg[d].kp];
            double v = dmg[d].v;
            switch (dmg[d].kind) {
            case 0: k->x_px = (float)v; break;
            case 1: k->y_px = (float)v; break;
            case 2: k->c = (float)v; break;
            case 3: k->x_px += (float)(fmod(v, 1000.0)); break; /* an outlier */
            case 4: k->x_px = k->y_px = NAN; k->c = 0.0f; break;
            case 5: ts = v; break;                               /* any time at all */
            case 6: ts = t0 + t - fabs(fmod(v, 1.0)); break;      /* back in time */
            case 7: ts = t0 + t + fabs(fmod(v, 100.0)); t0 += fabs(fmod(v, 100.0)); break; /* a gap */
            case 8: size = (float)v; break;
            default: for (size_t j = 0; j < nkp; j++) kp[j].c = 0.0f; break; /* nobody */
            }
        }
        gs_status st = lay == GS_LAYOUT_POINT
                           ? gs_pipeline_push_point(&fp.p, ts, kp[0].x_px, kp[0].y_px, kp[0].c, size)
                           : gs_pipeline_push_keypoints(&fp.p, ts, kp);
        FZ_CHECK(st == GS_OK || st == GS_EINVAL || st == GS_EORDER);
    }
    fz_pipe_end(&fp);
    return 0;
}
