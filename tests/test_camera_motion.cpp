// test_camera_motion.cpp - the camera-motion tracker against truth: a textured
// scene moved by known sub-pixel similarity transforms, a moving subject that
// must not count as camera motion, and two real clips (a static campus camera;
// a handheld phone in a gym whose view drifts ~45 px during the jump); and
// the parts that reproduce OpenCV's (area reduction, corners, Lucas-Kanade's
// derivatives where it reads them, its tracking loop) against OpenCV itself.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/video/tracking.hpp>

extern "C" {
#include "unity.h"
}

#include "camera_motion.hpp"
#include "lk_track.hpp"

#ifndef GS_SHARED_DIR
#error "GS_SHARED_DIR must be defined"
#endif

void setUp(void) {}
void tearDown(void) {}

namespace {

// a wall with structure: blobs, lines and noise on a gradient (fixed seed)
cv::Mat scene(int w, int h)
{
    cv::Mat img(h, w, CV_8UC3);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) img.at<cv::Vec3b>(y, x) = cv::Vec3b(90 + x * 60 / w, 100, 110 + y * 40 / h);
    cv::RNG rng(1234);
    for (int i = 0; i < 400; i++) {
        cv::Point c(rng.uniform(0, w), rng.uniform(0, h));
        cv::Scalar col(rng.uniform(0, 255), rng.uniform(0, 255), rng.uniform(0, 255));
        if (i % 3 == 0)
            cv::circle(img, c, rng.uniform(3, 20), col, -1, cv::LINE_AA);
        else if (i % 3 == 1)
            cv::rectangle(img, c, c + cv::Point(rng.uniform(4, 30), rng.uniform(4, 30)), col, -1);
        else
            cv::line(img, c, c + cv::Point(rng.uniform(-40, 40), rng.uniform(-40, 40)), col, 2, cv::LINE_AA);
    }
    cv::GaussianBlur(img, img, cv::Size(3, 3), 0.8);
    return img;
}

// the view of the camera after it moved: the reference centre goes to centre + (dx, dy)
cv::Mat view(const cv::Mat &big, double dx, double dy, double rot_deg, double s, cv::Size out)
{
    cv::Point2f c(0.5f * big.cols, 0.5f * big.rows);
    cv::Mat m = cv::getRotationMatrix2D(c, rot_deg, s);
    m.at<double>(0, 2) += dx - 0.5 * (big.cols - out.width);
    m.at<double>(1, 2) += dy - 0.5 * (big.rows - out.height);
    cv::Mat v;
    cv::warpAffine(big, v, m, out, cv::INTER_CUBIC, cv::BORDER_REFLECT);
    return v;
}

bool exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

}  // namespace

static void test_known_motion_is_recovered(void)
{
    cv::Mat big = scene(1500, 900);
    cv::Size out(1280, 720);
    gs::CameraMotion cm;
    double worst_d = 0.0, worst_rot = 0.0, worst_s = 0.0;
    for (int i = 0; i < 40; i++) {
        // a slow handheld-like wander: drift, sway, a little rotation and zoom
        double dx = 0.9 * i + 6.0 * std::sin(0.3 * i), dy = -0.5 * i + 4.0 * std::cos(0.23 * i) - 4.0;
        double rot = 0.02 * i, s = 1.0 + 0.0005 * i;
        cv::Mat f = view(big, dx, dy, rot, s, out);
        gs::CameraMotionFrame o;
        cm.process(f, {}, &o);
        TEST_ASSERT_TRUE(o.valid);
        // the first frame is the reference: compare displacements relative to it
        double dx0 = 0.0, dy0 = 4.0 * std::cos(0.0) - 4.0;
        worst_d = std::max(worst_d, std::hypot(o.dx_px - (dx - dx0), o.dy_px - (dy - dy0)));
        worst_rot = std::max(worst_rot, std::fabs(o.rot_deg + rot));  // OpenCV's angle is anticlockwise
        worst_s = std::max(worst_s, std::fabs(o.scale - s));
    }
    std::printf("known motion: worst centre error %.3f px, rotation %.4f deg, scale %.5f\n", worst_d, worst_rot,
                worst_s);
    TEST_ASSERT_TRUE_MESSAGE(worst_d < 0.5, "the camera's displacement within 0.5 px over 40 frames");
    TEST_ASSERT_TRUE(worst_rot < 0.03);
    TEST_ASSERT_TRUE(worst_s < 0.001);
}

static void test_moving_subject_is_not_camera_motion(void)
{
    cv::Mat big = scene(1500, 900);
    cv::Size out(1280, 720);
    cv::Mat still = view(big, 0, 0, 0, 1, out);
    gs::CameraMotion with_box, without_box;
    double worst_box = 0.0, worst_free = 0.0;
    for (int i = 0; i < 30; i++) {
        cv::Mat f = still.clone();
        // a textured subject a sixth of the frame wide, moving 12 px a frame
        cv::Rect subj(200 + 12 * i, 150 + 3 * i, 220, 420);
        cv::Mat patch = scene(subj.width, subj.height);
        cv::flip(patch, patch, 1);
        patch.copyTo(f(subj));
        gs::CameraMotionFrame a, b;
        with_box.process(f, {subj}, &a);
        without_box.process(f, {}, &b);
        worst_box = std::max(worst_box, std::hypot(a.dx_px, a.dy_px));
        worst_free = std::max(worst_free, std::hypot(b.dx_px, b.dy_px));
    }
    std::printf("moving subject: camera shift %.3f px with its box excluded, %.3f px without\n", worst_box,
                worst_free);
    TEST_ASSERT_TRUE_MESSAGE(worst_box < 0.2, "a subject kept out leaves the camera still");
    TEST_ASSERT_TRUE_MESSAGE(worst_free < 0.5, "RANSAC keeps a minority of moving corners out");
}

static void test_other_motion_beside_the_subject(void)
{
    // A subject standing (its box excluded) while the camera wanders; a textured
    // passer-by walks past right beside it at 15 px a frame. Corners in the ring
    // around the subject that move against the background count as other motion;
    // the wandering camera alone gives none.
    cv::Mat big = scene(1500, 900);
    cv::Size out(1280, 720);
    cv::Rect subj(560, 200, 160, 400);
    cv::Mat body = scene(subj.width, subj.height), walker = scene(120, 380);
    cv::flip(body, body, 0);
    cv::flip(walker, walker, -1);
    gs::CameraMotion alone, passed;
    int alone_max = 0, passed_frames = 0, n = 0;
    for (int i = 0; i < 30; i++) {
        double dx = 0.9 * i + 6.0 * std::sin(0.3 * i), dy = -0.5 * i + 4.0 * std::cos(0.23 * i);
        cv::Mat f = view(big, dx, dy, 0.02 * i, 1.0, out);
        body.copyTo(f(subj));
        gs::CameraMotionFrame a, b;
        alone.process(f, {subj}, &a);
        cv::Rect w(300 + 15 * i, 230, walker.cols, walker.rows);  // passes the subject's left side, then behind it
        cv::Mat g = f.clone();
        walker.copyTo(g(w));
        body.copyTo(g(subj));
        passed.process(g, {subj}, &b);
        if (i == 0) continue;
        alone_max = std::max(alone_max, a.other);
        // frames where the walker is in the ring but not hidden behind the subject
        if (w.x + w.width < subj.x + 20) {
            n++;
            passed_frames += b.other >= 6 ? 1 : 0;
        }
    }
    std::printf("other motion: camera alone at most %d corners; passer-by seen in %d of %d frames beside the subject\n",
                alone_max, passed_frames, n);
    TEST_ASSERT_TRUE(n >= 8);
    TEST_ASSERT_TRUE_MESSAGE(alone_max <= 2, "the camera's own motion is not other motion");
    TEST_ASSERT_TRUE_MESSAGE(passed_frames >= n - 1, "a passer-by beside the subject is seen");
}

static double max_shift(const std::string &path, int frames, double *dy_range)
{
    cv::VideoCapture cap(path);
    TEST_ASSERT_TRUE_MESSAGE(cap.isOpened(), path.c_str());
    gs::CameraMotion cm;
    cv::Mat f;
    double mx = 0.0, lo = 1e9, hi = -1e9;
    int valid = 0, n = 0;
    while (n < frames && cap.read(f)) {
        gs::CameraMotionFrame o;
        cm.process(f, {}, &o);
        n++;
        if (!o.valid) continue;
        valid++;
        mx = std::max(mx, std::hypot(o.dx_px, o.dy_px));
        lo = std::min(lo, o.dy_px);
        hi = std::max(hi, o.dy_px);
    }
    TEST_ASSERT_TRUE(n > 20);
    TEST_ASSERT_EQUAL_MESSAGE(n, valid, "every frame's motion is known");
    *dy_range = hi - lo;
    return mx;
}

static void test_real_static_camera(void)
{
    // a plain buffer: TEST_IGNORE longjmps out of the test, past C++ destructors
    char p_buf[512];
    std::snprintf(p_buf, sizeof p_buf, "%s/data/real/opencv_vtest/vtest_first15s_h264.mp4", GS_SHARED_DIR);
    if (!exists(p_buf)) TEST_IGNORE_MESSAGE("opencv_vtest is absent");
    std::string p = p_buf;
    double dyr = 0.0, mx = max_shift(p, 150, &dyr);
    std::printf("vtest (static camera, people walking): largest shift %.2f px\n", mx);
    TEST_ASSERT_TRUE_MESSAGE(mx < 1.0, "a static camera stays within 1 px");
}

static void test_real_handheld_camera(void)
{
    // a plain buffer: TEST_IGNORE longjmps out of the test, past C++ destructors
    char p_buf[512];
    std::snprintf(p_buf, sizeof p_buf, "%s/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4", GS_SHARED_DIR);
    if (!exists(p_buf)) TEST_IGNORE_MESSAGE("jumpvision_jumps is absent");
    std::string p = p_buf;
    double dyr = 0.0, mx = max_shift(p, 200, &dyr);
    std::printf("gym clip (handheld): largest shift %.1f px, vertical range %.1f px\n", mx, dyr);
    // SOURCE.txt: the background shifts ~20-50 px during the clip
    TEST_ASSERT_TRUE_MESSAGE(dyr > 20.0 && dyr < 80.0, "the handheld drift is seen at its size");
}

// the working image is OpenCV's INTER_AREA reduction pixel for pixel: real
// frames at the working scales of 720p and 1080p, and random images and scales
static void test_area_reduction_is_opencvs(void)
{
    std::vector<cv::Mat> greys;
    char p_buf[512];
    std::snprintf(p_buf, sizeof p_buf, "%s/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4", GS_SHARED_DIR);
    if (exists(p_buf)) {
        cv::VideoCapture cap(p_buf);
        cv::Mat f, g;
        for (int i = 0; i < 10 && cap.read(f); i++) {
            cv::cvtColor(f, g, cv::COLOR_BGR2GRAY);
            greys.push_back(g.clone());
            cv::resize(g, g, cv::Size(1080, 1920));
            greys.push_back(g.clone());
        }
    }
    int cases = 0, same = 0;
    for (const cv::Mat &g : greys) {
        cv::Mat a, b;
        double f = 640.0 / g.cols;
        cv::resize(g, a, cv::Size(), f, f, cv::INTER_AREA);
        gs::resize_area_grey(g, b, f);
        cases++;
        same += a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0.0;
    }
    cv::RNG rng(7);
    for (int i = 0; i < 200; i++) {
        cv::Mat g(rng.uniform(8, 700), rng.uniform(8, 700), CV_8UC1);
        rng.fill(g, cv::RNG::UNIFORM, 0, 256);
        double f = rng.uniform(0.05, 1.0);
        if (i % 10 == 0) f = 1.0 / (1 + i % 3);  // whole factors and none
        cv::Mat a, b;
        cv::resize(g, a, cv::Size(), f, f, cv::INTER_AREA);
        gs::resize_area_grey(g, b, f);
        cases++;
        same += a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0.0;
    }
    std::printf("area reduction: %d of %d images as cv::resize\n", same, cases);
    TEST_ASSERT_EQUAL_INT(cases, same);
}

// the same for colour images and a given output size (the pose detector's
// letterbox: 720 x 1280 -> 360 x 640 -> 126 x 224), the scales per axis
static void test_area_reduction_to_a_size_is_opencvs(void)
{
    std::vector<cv::Mat> imgs;
    char p_buf[512];
    std::snprintf(p_buf, sizeof p_buf, "%s/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4", GS_SHARED_DIR);
    if (exists(p_buf)) {
        cv::VideoCapture cap(p_buf);
        cv::Mat f;
        for (int i = 0; i < 5 && cap.read(f); i++) imgs.push_back(f.clone());
    }
    int cases = 0, same = 0;
    auto check = [&](const cv::Mat &src, cv::Size ds) {
        cv::Mat a, b;
        cv::resize(src, a, ds, 0, 0, cv::INTER_AREA);
        gs::resize_area(src, b, ds);
        cases++;
        same += a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
    };
    for (const cv::Mat &f : imgs) {
        cv::Mat half;
        cv::resize(f, half, cv::Size(f.cols / 2, f.rows / 2), 0, 0, cv::INTER_AREA);
        check(f, cv::Size(f.cols / 2, f.rows / 2));
        check(half, cv::Size(126, 224));
        check(f, cv::Size(126, 224));
        cv::Mat grey;
        cv::cvtColor(f, grey, cv::COLOR_BGR2GRAY);
        check(grey, cv::Size(640, 1138));
    }
    cv::RNG rng(9);
    for (int i = 0; i < 200; i++) {
        cv::Mat g(rng.uniform(8, 500), rng.uniform(8, 500), i % 2 ? CV_8UC3 : CV_8UC1);
        rng.fill(g, cv::RNG::UNIFORM, 0, 256);
        cv::Size ds(rng.uniform(1, g.cols + 1), rng.uniform(1, g.rows + 1));
        if (i % 10 == 0) ds = cv::Size(g.cols / 2, g.rows / (1 + i % 3));  // whole factors
        check(g, ds);
    }
    // the output written into part of a larger image, as the letterbox is
    cv::Mat canvas(224, 224, CV_8UC3, cv::Scalar::all(0)), ref = canvas.clone(), src(640, 360, CV_8UC3);
    rng.fill(src, cv::RNG::UNIFORM, 0, 256);
    cv::Mat part = canvas(cv::Rect(49, 0, 126, 224)), ref_part = ref(cv::Rect(49, 0, 126, 224));
    gs::resize_area(src, part, part.size());
    cv::resize(src, ref_part, ref_part.size(), 0, 0, cv::INTER_AREA);
    cases++;
    same += cv::norm(canvas, ref, cv::NORM_INF) == 0.0;
    std::printf("area reduction to a size: %d of %d images as cv::resize (%d frames of the gym clip)\n", same,
                cases, static_cast<int>(imgs.size()));
    TEST_ASSERT_EQUAL_INT(cases, same);
}

// the corner search gives OpenCV's corners in OpenCV's order: whole frames, cells
// of a frame (the gradient reads past a cell's edge), masks, both block sizes
static void test_corners_are_opencvs(void)
{
    std::vector<cv::Mat> greys;
    char p_buf[512];
    std::snprintf(p_buf, sizeof p_buf, "%s/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4", GS_SHARED_DIR);
    if (exists(p_buf)) {
        cv::VideoCapture cap(p_buf);
        cv::Mat f, g;
        for (int i = 0; cap.read(f); i++) {
            if (i % 6) continue;
            cv::cvtColor(f, g, cv::COLOR_BGR2GRAY);
            cv::resize(g, g, cv::Size(), 640.0 / g.cols, 640.0 / g.cols, cv::INTER_AREA);
            greys.push_back(g.clone());
        }
    }
    cv::RNG rng(11);
    for (int i = 0; i < 4; i++) {  // noise: many equal eigenvalues, ties broken by position
        cv::Mat g(rng.uniform(40, 300), rng.uniform(40, 300), CV_8UC1);
        rng.fill(g, cv::RNG::UNIFORM, 0, i % 2 ? 4 : 256);
        greys.push_back(g);
    }
    gs::CornerWork work;
    int cases = 0, same = 0, corners = 0;
    for (const cv::Mat &g : greys) {
        for (int trial = 0; trial < 4; trial++) {
            cv::Mat img = g, mask;
            if (trial >= 1) {  // a cell inside the frame
                int x = rng.uniform(0, g.cols / 2), y = rng.uniform(0, g.rows / 2);
                img = g(cv::Rect(x, y, rng.uniform(16, g.cols - x), rng.uniform(16, g.rows - y)));
            }
            if (trial >= 2) {
                mask.create(img.size(), CV_8U);
                mask.setTo(255);
                cv::circle(mask, cv::Point(img.cols / 2, img.rows / 2), img.cols / 4, cv::Scalar(0), -1);
            }
            if (trial == 3) {
                mask.setTo(0);
                cv::rectangle(mask, cv::Rect(2, 2, img.cols / 3, img.rows / 3), cv::Scalar(255), -1);
            }
            for (int block : {3, 5})
                for (double spacing : {12.0, 3.0, 0.0})
                    for (int most : {9, 60, 0}) {
                        std::vector<cv::Point2f> a, b;
                        cv::goodFeaturesToTrack(img, a, most, 0.01, spacing, mask, block);
                        gs::good_features(img, b, most, 0.01, spacing, mask, block, work);
                        cases++;
                        corners += (int)a.size();
                        same += a == b;
                    }
        }
    }
    std::printf("corners: %d of %d searches as cv::goodFeaturesToTrack (%d corners)\n", same, cases, corners);
    TEST_ASSERT_TRUE(cases >= 18 * 4 * 4);
    TEST_ASSERT_EQUAL_INT(cases, same);
}

// Lucas-Kanade on a pyramid whose derivatives are computed only where it reads
// them gives OpenCV's points and status bit for bit (the full pyramid built by
// cv::buildOpticalFlowPyramid): corners, random points, points at and beyond the
// edges, a second call with other points on the same pyramid, small frames whose
// coarse levels are a few pixels wide
static void test_lk_derivatives_are_opencvs(void)
{
    const cv::Size win(21, 21);
    const int levels = 3;
    cv::RNG rng(21);
    int calls = 0, same = 0, points = 0, tracked = 0;
    for (cv::Size sz : {cv::Size(640, 1138), cv::Size(320, 200), cv::Size(97, 61), cv::Size(40, 30)}) {
        cv::Mat big = scene(sz.width + 80, sz.height + 80), a, b;
        cv::cvtColor(view(big, 0, 0, 0, 1, sz), a, cv::COLOR_BGR2GRAY);
        cv::cvtColor(view(big, 2.3, -1.6, 0.4, 1.003, sz), b, cv::COLOR_BGR2GRAY);
        std::vector<cv::Mat> full_a, full_b, img_a, img_b;
        cv::buildOpticalFlowPyramid(a, full_a, win, levels, true);
        cv::buildOpticalFlowPyramid(b, full_b, win, levels, true);
        cv::buildOpticalFlowPyramid(a, img_a, win, levels, false);
        cv::buildOpticalFlowPyramid(b, img_b, win, levels, false);
        gs::LkDerivatives lazy;
        lazy.reset(img_a, win);
        for (int call = 0; call < 3; call++) {
            std::vector<cv::Point2f> pts;
            if (call == 0) cv::goodFeaturesToTrack(a, pts, 80, 0.01, 8);
            for (int i = 0; i < (call == 2 ? 3 : 60); i++)  // inside, at the edges and beyond them
                pts.push_back(cv::Point2f(rng.uniform(-30.f, sz.width + 30.f), rng.uniform(-30.f, sz.height + 30.f)));
            for (float e : {0.f, 0.5f, 1.f})
                pts.push_back(cv::Point2f(e * (sz.width - 1), (1 - e) * (sz.height - 1)));
            std::vector<cv::Point2f> want, got;
            std::vector<uchar> st_want, st_got;
            cv::calcOpticalFlowPyrLK(full_a, full_b, pts, want, st_want, cv::noArray(), win, levels);
            lazy.cover(pts);
            cv::calcOpticalFlowPyrLK(lazy.pyramid(), img_b, pts, got, st_got, cv::noArray(), win, levels);
            bool eq = st_want == st_got && want.size() == got.size();
            for (size_t i = 0; eq && i < want.size(); i++)
                eq = std::memcmp(&want[i], &got[i], sizeof(cv::Point2f)) == 0;
            calls++;
            same += eq;
            points += (int)pts.size();
            for (uchar v : st_want) tracked += v;
        }
    }
    std::printf("lucas-kanade: %d of %d calls as on OpenCV's full pyramid (%d points, %d tracked)\n", same, calls,
                points, tracked);
    TEST_ASSERT_TRUE(tracked > points / 2);
    TEST_ASSERT_EQUAL_INT(calls, same);
}

// gs::lk_track against cv::calcOpticalFlowPyrLK on the same pyramids, bit for bit:
// real frame pairs (one and three frames apart) and synthetic views of several
// sizes (the small ones with fewer levels), moved a little and too far to follow,
// with a flat patch whose windows fail the eigenvalue test, and points inside, on
// the edges and beyond them
static void check_lk_track(const cv::Mat &a, const cv::Mat &b, const std::vector<cv::Point2f> &extra, cv::RNG &rng,
                           int *calls, int *same, int *points, int *tracked)
{
    const cv::Size win(21, 21);
    const int levels = 3;
    std::vector<cv::Mat> img_a, img_b;
    cv::buildOpticalFlowPyramid(a, img_a, win, levels, false);
    cv::buildOpticalFlowPyramid(b, img_b, win, levels, false);
    std::vector<cv::Point2f> pts;
    if (a.cols >= 8 && a.rows >= 8) cv::goodFeaturesToTrack(a, pts, 150, 0.01, 8);
    pts.insert(pts.end(), extra.begin(), extra.end());
    for (int i = 0; i < 40; i++)
        pts.push_back(cv::Point2f(rng.uniform(-30.f, a.cols + 30.f), rng.uniform(-30.f, a.rows + 30.f)));
    for (float e : {0.f, 0.5f, 1.f}) {
        pts.push_back(cv::Point2f(e * (a.cols - 1), (1 - e) * (a.rows - 1)));
        pts.push_back(cv::Point2f(rng.uniform(-1.f, 1.f) + e * a.cols, rng.uniform(-1.f, 1.f)));
    }
    gs::LkDerivatives deriv;
    deriv.reset(img_a, win);
    deriv.cover(pts);
    std::vector<cv::Point2f> want, got;
    std::vector<uchar> st_want, st_got;
    cv::calcOpticalFlowPyrLK(deriv.pyramid(), img_b, pts, want, st_want, cv::noArray(), win, levels);
    gs::lk_track(deriv.pyramid(), img_b, pts, got, st_got, win, levels);
    bool eq = st_want == st_got && want.size() == got.size();
    for (size_t i = 0; eq && i < want.size(); i++) eq = std::memcmp(&want[i], &got[i], sizeof(cv::Point2f)) == 0;
    (*calls)++;
    *same += eq;
    *points += (int)pts.size();
    for (uchar v : st_want) *tracked += v;
}

static void test_lk_track_is_opencvs(void)
{
    cv::RNG rng(33);
    int calls = 0, same = 0, points = 0, tracked = 0;
    char p_buf[512];
    std::snprintf(p_buf, sizeof p_buf, "%s/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4", GS_SHARED_DIR);
    if (exists(p_buf)) {
        cv::VideoCapture cap(p_buf);
        std::vector<cv::Mat> greys;
        cv::Mat f, g, w;
        for (int i = 0; i < 12 && cap.read(f); i++) {
            cv::cvtColor(f, g, cv::COLOR_BGR2GRAY);
            gs::resize_area_grey(g, w, 640.0 / g.cols);
            greys.push_back(w.clone());
        }
        for (size_t i = 0; i + 3 < greys.size(); i += 2) {
            check_lk_track(greys[i], greys[i + 1], {}, rng, &calls, &same, &points, &tracked);
            check_lk_track(greys[i], greys[i + 3], {}, rng, &calls, &same, &points, &tracked);
        }
    }
    for (cv::Size sz : {cv::Size(640, 1138), cv::Size(640, 360), cv::Size(320, 200), cv::Size(97, 61), cv::Size(40, 30),
                        cv::Size(23, 17)}) {
        cv::Mat big = scene(sz.width + 200, sz.height + 200), a, b;
        // a flat patch in both views: windows inside it have no gradient
        const cv::Rect flat(sz.width / 4 + 100, sz.height / 4 + 100, sz.width / 4 + 30, sz.height / 4 + 30);
        big(flat).setTo(cv::Scalar(120, 120, 120));
        const std::vector<cv::Point2f> in_flat = {cv::Point2f(sz.width * 0.375f, sz.height * 0.375f)};
        cv::cvtColor(view(big, 0, 0, 0, 1, sz), a, cv::COLOR_BGR2GRAY);
        const double moves[][4] = {{2.3, -1.6, 0.4, 1.003}, {-0.4, 0.7, 0, 1}, {45, -38, 3, 1.05}, {90, 70, 0, 1}};
        for (const double *m : moves) {
            cv::cvtColor(view(big, m[0], m[1], m[2], m[3], sz), b, cv::COLOR_BGR2GRAY);
            check_lk_track(a, b, in_flat, rng, &calls, &same, &points, &tracked);
        }
    }
    std::printf("lucas-kanade loop: %d of %d calls as cv::calcOpticalFlowPyrLK (%d points, %d tracked)\n", same, calls,
                points, tracked);
    TEST_ASSERT_TRUE(tracked > points / 2 && tracked < points);
    TEST_ASSERT_EQUAL_INT(calls, same);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_known_motion_is_recovered);
    RUN_TEST(test_moving_subject_is_not_camera_motion);
    RUN_TEST(test_other_motion_beside_the_subject);
    RUN_TEST(test_real_static_camera);
    RUN_TEST(test_real_handheld_camera);
    RUN_TEST(test_area_reduction_is_opencvs);
    RUN_TEST(test_area_reduction_to_a_size_is_opencvs);
    RUN_TEST(test_corners_are_opencvs);
    RUN_TEST(test_lk_derivatives_are_opencvs);
    RUN_TEST(test_lk_track_is_opencvs);
    return UNITY_END();
}
