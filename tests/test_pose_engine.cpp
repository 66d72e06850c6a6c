// test_pose_engine.cpp - the pose networks' engines (pose_engine.hpp): names,
// the choice in force, and, when this build has OpenVINO, that it gives the
// keypoints OpenCV's DNN gives on real frames: every frame of the gym jump
// (720 x 1280, tracked by the OpenCV tracker; heavy: the first 18), the landmarks of that frame's
// ROI from both engines, all 33 keypoints of each model, within 1e-3 of the
// ROI's side (normalised crop units, MediaPipe's) and within 1e-3 in c; the
// detector's persons on the first frame alike. Without OpenVINO: asking for
// it is refused with a message that names how to get it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

extern "C" {
#include "unity.h"
}

#include <opencv2/videoio.hpp>

#include "gs_test_util.hpp"
#include "pose_blazepose.hpp"
#include "pose_engine.hpp"

#ifndef GS_SHARED_DIR
#error "GS_SHARED_DIR must be defined"
#endif

void setUp(void) {}
void tearDown(void) {}

static void test_engine_names(void)
{
    gs::PoseEngine e = gs::PoseEngine::opencv;
    TEST_ASSERT_TRUE(gs::pose_engine_from_name("openvino", &e));
    TEST_ASSERT_TRUE(e == gs::PoseEngine::openvino);
    TEST_ASSERT_TRUE(gs::pose_engine_from_name("auto", &e));
    TEST_ASSERT_TRUE(e == gs::PoseEngine::automatic);
    TEST_ASSERT_FALSE(gs::pose_engine_from_name("onnx", &e));
    TEST_ASSERT_TRUE(e == gs::PoseEngine::automatic);  // untouched
    TEST_ASSERT_TRUE(gs::pose_engine_built(gs::PoseEngine::opencv));
    TEST_ASSERT_TRUE(gs::pose_engine_resolve(gs::PoseEngine::opencv) == gs::PoseEngine::opencv);
    TEST_ASSERT_TRUE(gs::pose_engine_resolve(gs::PoseEngine::automatic) ==
                     (GS_HAVE_OPENVINO ? gs::PoseEngine::openvino : gs::PoseEngine::opencv));

    gs::PoseConfig c;
    char msg[160] = "";
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs::pose_config_set(&c, "engine", 6, "tflite", 6, msg, sizeof msg));
    TEST_ASSERT_NOT_NULL(std::strstr(msg, "opencv"));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs::pose_config_set(&c, "engine", 6, "opencv", 6, msg, sizeof msg));
    TEST_ASSERT_TRUE(c.engine == gs::PoseEngine::opencv);
    TEST_ASSERT_TRUE(gs::pose_engine_in_force(c) == gs::PoseEngine::opencv);
    TEST_ASSERT_NOT_NULL(std::strstr(gs::pose_detector_path(c).c_str(), "/pose_detection.onnx"));
    gs_status st = gs::pose_config_set(&c, "engine", 6, "openvino", 8, msg, sizeof msg);
    if (GS_HAVE_OPENVINO) {
        TEST_ASSERT_EQUAL_INT(GS_OK, st);
        TEST_ASSERT_NOT_NULL(std::strstr(gs::pose_landmark_path(c).c_str(), "/pose_landmark_lite_noseg_strict.onnx"));
    } else {
        TEST_ASSERT_EQUAL_INT(GS_EINVAL, st);
        TEST_ASSERT_NOT_NULL(std::strstr(msg, "fetch_engine.sh"));
        std::string err;
        TEST_ASSERT_NULL(gs::pose_net_load(gs::PoseEngine::openvino, "x.onnx", 0, err).get());
        TEST_ASSERT_NOT_NULL(std::strstr(err.c_str(), "fetch_engine.sh"));
    }
}

#if GS_HAVE_OPENVINO
namespace {

const char kGym[] = "/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4";

std::vector<cv::Mat> gym_frames()
{
    std::vector<cv::Mat> v;
    cv::VideoCapture cap(std::string(GS_SHARED_DIR) + kGym);
    cv::Mat f;
    while (cap.read(f)) v.push_back(f.clone());
    return v;
}

}  // namespace

static void test_openvino_keypoints_equal_opencv_on_the_gym_jump(void)
{
    std::vector<cv::Mat> frames = gym_frames();
    TEST_ASSERT_TRUE_MESSAGE(frames.size() >= 50, (std::string(GS_SHARED_DIR) + kGym + ": fewer than 50 frames").c_str());
    for (gs::PoseModel m : {gs::PoseModel::lite, gs::PoseModel::full, gs::PoseModel::heavy}) {
        gs::PoseConfig ca, cb;
        ca.model = cb.model = m;
        // the networks' own outputs: MediaPipe's heatmap refinement switches on at a peak of
        // 0.5, and a peak at the threshold may fall either side on the two engines (one
        // knee of one frame here moves 2.6 px); compared with it on, below
        ca.heatmap_refine = cb.heatmap_refine = false;
        ca.engine = gs::PoseEngine::opencv;
        cb.engine = gs::PoseEngine::openvino;
        gs::PoseTracker a(ca), b(cb);
        TEST_ASSERT_TRUE_MESSAGE(a.ok(), a.error().c_str());
        TEST_ASSERT_TRUE_MESSAGE(b.ok(), b.error().c_str());
        TEST_ASSERT_TRUE(a.engine() == gs::PoseEngine::opencv && b.engine() == gs::PoseEngine::openvino);

        std::vector<gs::PoseDetection> da = a.detect(frames[0]), db = b.detect(frames[0]);
        TEST_ASSERT_EQUAL_INT(1, (int)da.size());
        TEST_ASSERT_EQUAL_INT((int)da.size(), (int)db.size());
        double det_px = 0.0;
        for (int k = 0; k < 4; k++)
            det_px = std::max({det_px, (double)std::fabs(da[0].kp_x[k] - db[0].kp_x[k]),
                               (double)std::fabs(da[0].kp_y[k] - db[0].kp_y[k])});
        TEST_ASSERT_FLOAT_WITHIN(1e-3f, da[0].score, db[0].score);

        double worst_n = 0.0, worst_px = 0.0, worst_c = 0.0;
        int n_frames = 0;
        const size_t n_run = m == gs::PoseModel::heavy ? 18 : frames.size();  // heavy costs ~0.4 s a frame here
        for (size_t i = 0; i < n_run; i++) {
            gs::PoseOutput t;
            if (!a.process(frames[i], i / 30.0, &t) || !(t.roi.size_px > 0.0)) continue;
            gs::PoseOutput oa, ob;
            a.landmarks(frames[i], t.roi, &oa, nullptr);
            b.landmarks(frames[i], t.roi, &ob, nullptr);
            TEST_ASSERT_TRUE(oa.present && ob.present);
            for (int k = 0; k < gs::kPoseKeypoints; k++) {
                double d = std::max(std::fabs(oa.kp[k].x_px - ob.kp[k].x_px), std::fabs(oa.kp[k].y_px - ob.kp[k].y_px));
                worst_px = std::max(worst_px, d);
                worst_n = std::max(worst_n, d / t.roi.size_px);
                worst_c = std::max(worst_c, (double)std::fabs(oa.kp[k].c - ob.kp[k].c));
            }
            n_frames++;
        }
        char buf[200];
        std::snprintf(buf, sizeof buf, "%s: %d frames, keypoints |OpenVINO - OpenCV| <= %.2e of the ROI (%.4f px), c %.2e; "
                      "detector keypoints %.4f px", gs::pose_model_name(m), n_frames, worst_n, worst_px, worst_c, det_px);
        std::printf("%s\n", buf);
        TEST_ASSERT_TRUE_MESSAGE(n_frames == (int)n_run, buf);
        TEST_ASSERT_TRUE_MESSAGE(worst_n <= 1e-3, buf);
        TEST_ASSERT_TRUE_MESSAGE(worst_c <= 1e-3, buf);
        TEST_ASSERT_TRUE_MESSAGE(det_px <= 0.05, buf);
    }
}

// as users run it (heatmap refinement on, lite): the same keypoints but where a heatmap
// peak sits at the refinement's threshold
static void test_openvino_with_heatmap_refinement(void)
{
    std::vector<cv::Mat> frames = gym_frames();
    TEST_ASSERT_TRUE(frames.size() >= 50);
    gs::PoseConfig ca, cb;
    ca.engine = gs::PoseEngine::opencv;
    cb.engine = gs::PoseEngine::openvino;
    gs::PoseTracker a(ca), b(cb);
    TEST_ASSERT_TRUE_MESSAGE(a.ok() && b.ok(), (a.error() + b.error()).c_str());
    int n = 0, off = 0;
    double worst_n = 0.0;
    for (size_t i = 0; i < frames.size(); i++) {
        gs::PoseOutput t, oa, ob;
        if (!a.process(frames[i], i / 30.0, &t) || !(t.roi.size_px > 0.0)) continue;
        a.landmarks(frames[i], t.roi, &oa, nullptr);
        b.landmarks(frames[i], t.roi, &ob, nullptr);
        for (int k = 0; k < gs::kPoseKeypoints; k++) {
            double d = std::max(std::fabs(oa.kp[k].x_px - ob.kp[k].x_px), std::fabs(oa.kp[k].y_px - ob.kp[k].y_px)) / t.roi.size_px;
            worst_n = std::max(worst_n, d);
            off += d > 1e-3;
            n++;
        }
    }
    std::printf("lite, heatmap refinement on: %d of %d keypoints beyond 1e-3 of the ROI, worst %.2e\n", off, n, worst_n);
    TEST_ASSERT_TRUE(n >= 50 * gs::kPoseKeypoints);
    TEST_ASSERT_TRUE(off * 500 <= n);      // at most 0.2 %
    TEST_ASSERT_TRUE(worst_n <= 0.01);     // a heatmap cell's shift, never a different point
}
#endif

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_engine_names);
#if GS_HAVE_OPENVINO
    RUN_TEST(test_openvino_keypoints_equal_opencv_on_the_gym_jump);
    RUN_TEST(test_openvino_with_heatmap_refinement);
#endif
    return UNITY_END();
}
