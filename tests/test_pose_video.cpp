// test_pose_video.cpp - `gravscale video --detector pose` end to end on real
// clips with stated truth, and the scene watch (flight warnings, feet timing)
// against synthetic truth.
//  - jumpvision gym clip: one countermovement jump, 789 ms flight by a jump-test
//    app, filmed handheld: the flight time within 2 frames, timed by the feet
//    with either inference engine (within 5 ms of each other), and a camera_moved
//    warning on the flight (the static-camera assumption is broken).
//  - opencv_vtest: people walking far away: no jump, no height.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <vector>

extern "C" {
#include "gravscale/gs_event.h"
#include "unity.h"
}

#include "scene_watch.hpp"
#include "gs_test_util.hpp"

#ifndef GS_SHARED_DIR
#error "GS_SHARED_DIR must be defined"
#endif

void setUp(void) {}
void tearDown(void) {}

namespace {

using gs_test::exists;
using gs_test::Run;
using gs_test::lines_of;
using gs_test::num;

Run run(const std::string &args)
{
    return gs_test::run_shell(std::string(GS_PROGRAM) + " video " + args, gs_test::tmp_path("gs_test_pose_video.err"));
}

}  // namespace

static void test_gym_handheld_flight_time_and_warning(void)
{
    // a plain buffer: TEST_IGNORE longjmps out of the test, past C++ destructors
    char clip_buf[512];
    std::snprintf(clip_buf, sizeof clip_buf, "%s/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4", GS_SHARED_DIR);
    if (!exists(clip_buf)) TEST_IGNORE_MESSAGE("jumpvision_jumps is absent");
    std::string clip = clip_buf;
    Run r = run("'" + clip + "' --detector pose");
    TEST_ASSERT_EQUAL_INT(0, r.code);
    auto jumps = lines_of(r.out, "jump");
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, (int)jumps.size(), r.out.c_str());
    const std::string &j = jumps[0];
    double ft = num(j, "flight_time_s");
    std::printf("gym clip: flight %.4f s (app 0.789 s), jump height %.3f m (app 0.763), %s\n", ft,
                num(j, "jump_height_m"), j.substr(j.find("\"warnings\"")).c_str());
    // the app's flight time to half a frame, and its jump height (g T^2 / 8) to 2 cm
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.017, 0.789, ft, "flight time within half a frame of the app's");
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.02, 0.7634, num(j, "jump_height_m"), "jump height within 2 cm of the app's");
    bool accepted = j.find("\"accepted\":true") != std::string::npos;
    bool warned = j.find("\"camera_moved\"") != std::string::npos;
    TEST_ASSERT_TRUE_MESSAGE(!accepted || warned, "a height from a moving camera carries camera_moved");
    TEST_ASSERT_TRUE_MESSAGE(warned, "the handheld camera is noticed");
    // guidance while it happens, and the visit with its result
    TEST_ASSERT_TRUE(lines_of(r.out, "warning").size() >= 1);
    auto ses = lines_of(r.out, "session");
    TEST_ASSERT_EQUAL_INT(2, (int)ses.size());
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, ft, num(ses[1], "best_flight_s"));
    TEST_ASSERT_TRUE_MESSAGE(j.find("\"com_timed\"") == std::string::npos, "the flight is timed by the feet");
    // the fallback engine's keypoints differ by a few pixels (10 px at the impact's blurred
    // frame): the feet time the same flight, to a third of a frame
    Run rc = run("'" + clip + "' --detector pose --engine opencv");
    TEST_ASSERT_EQUAL_INT(0, rc.code);
    auto jc = lines_of(rc.out, "jump");
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, (int)jc.size(), rc.out.c_str());
    std::printf("gym clip, OpenCV DNN: flight %.4f s, %s\n", num(jc[0], "flight_time_s"),
                jc[0].substr(jc[0].find("\"warnings\"")).c_str());
    TEST_ASSERT_TRUE_MESSAGE(jc[0].find("\"com_timed\"") == std::string::npos, "OpenCV DNN: timed by the feet");
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.011, ft, num(jc[0], "flight_time_s"), "both engines, one flight time");
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.017, 0.789, num(jc[0], "flight_time_s"), "OpenCV DNN: the app's flight time");
}

static void test_vtest_people_walking_report_nothing(void)
{
    // a plain buffer: TEST_IGNORE longjmps out of the test, past C++ destructors
    char clip_buf[512];
    std::snprintf(clip_buf, sizeof clip_buf, "%s/data/real/opencv_vtest/vtest_first15s_h264.mp4", GS_SHARED_DIR);
    if (!exists(clip_buf)) TEST_IGNORE_MESSAGE("opencv_vtest is absent");
    std::string clip = clip_buf;
    Run r = run("'" + clip + "' --detector pose");
    TEST_ASSERT_EQUAL_INT(0, r.code);
    TEST_ASSERT_EQUAL_INT(0, (int)lines_of(r.out, "jump").size());
    TEST_ASSERT_EQUAL_INT(0, (int)lines_of(r.out, "height").size());
    auto sum = lines_of(r.out, "summary");
    TEST_ASSERT_EQUAL_INT(1, (int)sum.size());
    TEST_ASSERT_TRUE(sum[0].find("\"height_m\":null") != std::string::npos);
}

static void test_missing_models_is_a_clear_error(void)
{
    std::string clip = std::string(GS_SHARED_DIR) + "/data/real/opencv_vtest/vtest_first15s_h264.mp4";
    Run r = run("'" + clip + "' --detector pose --models /nonexistent/models");
    TEST_ASSERT_EQUAL_INT(2, r.code);
    TEST_ASSERT_EQUAL_INT(0, (int)r.out.size());
    FILE *f = std::fopen(gs_test::tmp_path("gs_test_pose_video.err").c_str(), "r");
    TEST_ASSERT_NOT_NULL(f);
    char line[1024] = {0};
    TEST_ASSERT_NOT_NULL(std::fgets(line, sizeof line, f));
    std::fclose(f);
    TEST_ASSERT_NOT_NULL_MESSAGE(std::strstr(line, "fetch_models.sh"), line);
}

// ---- the scene watch against synthetic truth ---------------------------------------

// a jumper at 60 fps: feet on the ground row 900 px, off at t0, back at t1, flying
// under a = 2000 px/s^2; the camera still or drifting; the body 600 px tall
static void synth(gs::SceneWatch &w, double t0, double t1, double drift_px_s, double border_at,
                  double other_from = -1.0, double other_to = -1.0)
{
    const double a = 2000.0, g = 900.0, v0 = 0.5 * a * (t1 - t0);
    for (int i = 0; i <= 150; i++) {
        double t = i / 60.0;
        gs::SceneFrame f;
        f.t_s = t;
        f.present = true;
        f.size_px = 600.0;
        f.cam_dx_px = drift_px_s * t;
        f.cam_dy_px = 0.0;
        f.ground_y_px = (t > t0 && t < t1) ? g - v0 * (t - t0) + 0.5 * a * (t - t0) * (t - t0) : g;
        f.at_border = std::fabs(t - border_at) < 0.02;
        f.other = (t >= other_from && t <= other_to) ? 8 : 1;  // corners moving beside the body
        w.add(f);
    }
}

static void test_scene_watch_warnings(void)
{
    const double t0 = 0.7913, t1 = 1.2871;  // between frames
    gs::SceneWatch still;
    synth(still, t0, t1, 0.0, -1.0);
    TEST_ASSERT_EQUAL_UINT32(0, still.flight_warnings(t0, t1, 0.5 * (t0 + t1)));

    gs::SceneWatch drift;  // 20 px/s: 10 px over the flight, above 1 % of 600 px
    synth(drift, t0, t1, 20.0, 1.0);
    uint32_t w = drift.flight_warnings(t0, t1, 0.5 * (t0 + t1));
    TEST_ASSERT_TRUE(w & GS_WARN_CAMERA_MOVED);
    TEST_ASSERT_TRUE(w & GS_WARN_LEFT_FRAME);
    gs::SceneWatch slow;  // 5 px/s: 2.5 px over the flight, below 6 px
    synth(slow, t0, t1, 5.0, -1.0);
    TEST_ASSERT_EQUAL_UINT32(0, slow.flight_warnings(t0, t1, 0.5 * (t0 + t1)));
    // someone moving beside the body: 3 frames of the window (60 fps) warn, 2 do not
    gs::SceneWatch other, brief, outside;
    synth(other, t0, t1, 0.0, -1.0, 1.0, 1.0 + 2.5 / 60.0);
    TEST_ASSERT_EQUAL_UINT32(GS_WARN_OTHER_MOTION, other.flight_warnings(t0, t1, 0.5 * (t0 + t1)));
    synth(brief, t0, t1, 0.0, -1.0, 1.0, 1.0 + 1.5 / 60.0);
    TEST_ASSERT_EQUAL_UINT32(0, brief.flight_warnings(t0, t1, 0.5 * (t0 + t1)));
    synth(outside, t0, t1, 0.0, -1.0, 0.0, 0.6);  // before the take-off (window: from t0 - 0.1 s)
    TEST_ASSERT_EQUAL_UINT32(0, outside.flight_warnings(t0, t1, 0.5 * (t0 + t1)));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_scene_watch_warnings);
    RUN_TEST(test_gym_handheld_flight_time_and_warning);
    RUN_TEST(test_vtest_people_walking_report_nothing);
    RUN_TEST(test_missing_models_is_a_clear_error);
    return UNITY_END();
}
