/* fw_scenario.c - the firmware's workload: the core on static memory (a
 * 512-sample ring), its profile (fw_profile.h, baked from tools/fw/workload.cfg
 * by fw_bake.c: parsed from flash at boot, or with FW_PROFILE_BAKED the parsed
 * configuration itself), synthetic frames pushed one by one, every event
 * formatted into a line buffer. No heap, no stdio. */
#include "fw_scenario.h"
#include "fw_profile.h"

#include <math.h>
#include <string.h>

#include "gravscale/gravscale.h"

#define FW_RING_CAP 512u
#define FW_FPS 60u
#define FW_T0_US INT64_C(1000000000)  /* a boot clock far from zero, so times are not small numbers */

/* ring + inlier bits, as gs_pipeline_storage_bytes computes for FW_RING_CAP */
#define FW_STORAGE_BYTES (FW_RING_CAP * sizeof(gs_sample) + (FW_RING_CAP + 31u) / 32u * 4u)
static uint64_t g_storage[(FW_STORAGE_BYTES + 7u) / 8u];  /* 8-byte aligned */
static gs_pipeline g_pipe;
static char g_line[GS_EMIT_MAX];
static fw_line_fn g_sink;
static uint32_t g_status;

#ifndef FW_PROFILE_BAKED
static const char k_profile[] = FW_PROFILE_TEXT;
static gs_core_config g_cfg;  /* parsed at boot */
#define FW_FORMAT g_cfg.format
#else
/* checked at build time: no text parser linked, no copy in RAM */
static const gs_core_config k_baked = FW_PROFILE_CONFIG;
#define FW_FORMAT k_baked.format  /* a constant: the emitter keeps only its format */
#endif

static void on_event(void *ctx, const gs_event *ev)
{
    (void)ctx;
    size_t n = gs_emit(FW_FORMAT, ev, g_line, sizeof g_line);
    if (n > 0 && g_sink) g_sink(g_line, n);
}

/* height in metres of a ball bouncing with 0.45 s flights, at time t */
static float bounce_m(float t)
{
    const float g = 9.81f, flight = 0.45f, v0 = 0.5f * g * flight;
    float x = t - (flight + 0.15f) * (float)(int)(t / (flight + 0.15f));  /* t >= 0: fmodf without libm */
    if (x > flight) return 0.0f;  /* on the floor */
    return v0 * x - 0.5f * g * x * x;
}

#if GS_WITH_POSE
/* the skeleton's layout: COCO-17 when built in (gs_features.h), else BlazePose-33 */
#define FW_POSE_LAYOUT (GS_WITH_COCO17 ? GS_LAYOUT_COCO17 : GS_LAYOUT_BLAZEPOSE33)

#if GS_WITH_COCO17
#define FW_POSE_KP 17
static int pose_index(int coco) { return coco; }
#else
#define FW_POSE_KP 33
/* the same body in BlazePose-33: its index of each COCO keypoint; the inner and outer
 * eyes, mouth and hand points unseen; heels and toes by the ankles */
static int pose_index(int coco)
{
    static const uint8_t k_to_blaze[17] = {0, 2, 5, 7, 8, 11, 12, 13, 14, 15, 16, 23, 24, 25, 26, 27, 28};
    return k_to_blaze[coco];
}
#endif

static void push_pose(int64_t t_us, float y_off_px)
{
    /* a standing skeleton about 530 px tall, lifted by y_off_px (COCO-17 order) */
    static const float k_y[17] = {60, 52, 52, 56, 56, 110, 110, 190, 190, 260, 260, 290, 290, 400, 400, 530, 530};
    static const float k_x[17] = {0, -6, 6, -14, 14, -40, 40, -48, 48, -50, 50, -22, 22, -24, 24, -24, 24};
    gs_kp kp[FW_POSE_KP];
    if (FW_POSE_KP > 17) memset(kp, 0, sizeof kp);  /* the points COCO-17 lacks: unseen */
    for (int i = 0; i < 17; i++) {
        gs_kp *q = &kp[pose_index(i)];
        q->x_px = 640.0f + k_x[i];
        q->y_px = 100.0f + k_y[i] - y_off_px;
        q->c = 0.9f;
    }
#if !GS_WITH_COCO17
    for (int s = 0; s < 2; s++) {
        const gs_kp *ank = &kp[pose_index(15 + s)];
        kp[29 + s] = (gs_kp){ank->x_px - 4.0f, ank->y_px + 12.0f, 0.9f};  /* heel */
        kp[31 + s] = (gs_kp){ank->x_px + 30.0f, ank->y_px + 14.0f, 0.9f}; /* foot index */
    }
#endif
    g_status |= (uint32_t)gs_pipeline_push_keypoints_us(&g_pipe, t_us, kp);
}
#endif

uint32_t fw_scenario_run(bool pose, fw_line_fn line)
{
    g_sink = line;
#ifndef FW_PROFILE_BAKED
    gs_cfg_error err;
    const gs_cfg_section sec = {"core", gs_core_config_set, &g_cfg};
    gs_core_config_default(&g_cfg);
    g_status = (uint32_t)gs_cfg_parse(k_profile, sizeof k_profile - 1u, &sec, 1, &err);
    const gs_core_config *cfg = &g_cfg;
#else
    const gs_core_config *cfg = &k_baked;
    g_status = 0;
#endif
    if (!pose && !GS_WITH_POINT) return 0u; /* no point layout built in: no ball workload */
#if GS_WITH_POSE
    const gs_layout layout = pose ? FW_POSE_LAYOUT : GS_LAYOUT_POINT;
#else
    if (pose) return 0u; /* no skeleton layout built in: no skeleton workload */
    const gs_layout layout = GS_LAYOUT_POINT;
#endif
    g_status |= (uint32_t)gs_pipeline_init(&g_pipe, cfg, layout,
                                           g_storage, sizeof g_storage, on_event, NULL);
    const float q_m_per_px = 0.002f;
    for (uint32_t i = 0; i < 6u * FW_FPS; i++) {
        /* frame i at i / FW_FPS s, rounded to the microsecond (32-bit: no 64-bit division) */
        int64_t t_us = FW_T0_US + (int64_t)((i * 1000000u + FW_FPS / 2u) / FW_FPS);
        float h = bounce_m((float)i / (float)FW_FPS);
        if (pose) {
#if GS_WITH_POSE
            push_pose(t_us, h / q_m_per_px);
#endif
        } else {
            g_status |= (uint32_t)gs_pipeline_push_point_us(&g_pipe, t_us, 320.0f, 400.0f - h / q_m_per_px, 1.0f,
                                                            34.35f);
        }
    }
    g_status |= (uint32_t)gs_pipeline_flush(&g_pipe);
    return g_status;
}

uint32_t fw_scenario_run_both(fw_line_fn line)
{
    static const char k_sep[] = "--- pose\n";
    uint32_t st = fw_scenario_run(false, line);
    line(k_sep, sizeof k_sep - 1u);
    return st | fw_scenario_run(true, line);
}
