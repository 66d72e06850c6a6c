// test_pose_crossing.cpp - one person kept while another walks through.
//  - PoseKeeper (pure logic): which of two bodies is the tracked one, a body
//    that jumps beyond what a body can do between frames, another size, a body
//    nearer to someone else, forgetting after an absence. PoseLook: colours.
//  - Real composites: the man on the left of opencv-doc's basketball1.png (a
//    rough hand-drawn polygon mask, scaled 1.55x to 617 px, the jumper stands
//    639 px) pasted walking at 17.5 px/frame (525 px/s = 1.4 m/s at the
//    jumper's 2.66 mm/px), feet at row 1100 (a little nearer the camera than
//    the jumper), in front of him, across the jumpvision gym clip; written
//    losslessly (FFV1 .avi at 30 fps, the mp4's own times i/30 s) into a temp dir.
//    A "apex": in front of the jumper's legs from frame ~14 to ~32 (the flight
//      is frames ~12-35; take-off and landing stay clear).
//    B "landing": in front from the descent (~27) to after the landing (~45).
//  Truth: the jump app's 789 ms flight; the clean FFV1 copy's own run (same
//  frames, same program) for q and the stature.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

extern "C" {
#include "unity.h"
}

#include "pose_blazepose.hpp"
#include "pose_look.hpp"
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

const char *const kWalkerPhoto = "/usr/share/doc/opencv-doc/examples/data/basketball1.png";
// the man on the left of basketball1.png, outlined by hand on a 10 px grid
// (head, shoulders, the arms and hands holding the ball, trousers, shoes)
const cv::Point kMan[] = {{72, 84},   {92, 82},   {103, 95},  {104, 125}, {98, 140},  {115, 148}, {130, 160},
                          {150, 150}, {162, 160}, {158, 185}, {140, 215}, {138, 260}, {134, 295}, {130, 360},
                          {132, 430}, {138, 455}, {155, 462}, {152, 475}, {120, 475}, {112, 440}, {98, 360},
                          {94, 320},  {86, 360},  {82, 430},  {82, 470},  {75, 480},  {45, 480},  {45, 440},
                          {42, 360},  {46, 300},  {38, 270},  {36, 220},  {38, 170},  {50, 150},  {65, 142},
                          {60, 125},  {58, 100}};

struct Walk {
    double scale = 1.55;      // 398 px of the photo -> 617 px, the jumper stands 639 px
    double feet_y_px = 1100;  // a little nearer the camera than the jumper (feet ~1000)
    double x0_px = 2.5;       // centre at the entry frame (A; B: -100)
    double v_px = 17.5;       // per frame: 525 px/s = 1.4 m/s at 2.66 mm/px
    int enter = 3;            // first frame with the walker
    bool behind = false;      // pasted only outside the jumper's mask (drawn from the clean run's keypoints)
};

// per frame, the jumper's body drawn from the clean run's keypoints (255 = the jumper)
std::vector<cv::Mat> g_masks;
std::vector<std::vector<gs_kp>> g_clean_kp;  // the clean run's keypoints per frame
int g_man_w = 0;                            // the walker's cut-out width in the photo
const char *const kOverlapWarning = "\"other_motion\"";

std::string g_dir, g_clean, g_cross;
char g_gym[512];

// The gym clip re-written as FFV1 at 30 fps (the mp4's times are i/30 s), with
// the walker pasted when w is given.
bool write_clip(const std::string &out, const Walk *w)
{
    if (w && w->behind && g_masks.empty()) return false;
    cv::VideoCapture cap(g_gym);
    if (!cap.isOpened()) return false;
    cv::Mat man, alpha;
    if (w) {
        cv::Mat photo = cv::imread(kWalkerPhoto, cv::IMREAD_COLOR);
        if (photo.empty()) return false;
        cv::Mat m(photo.size(), CV_8U, cv::Scalar(0));
        std::vector<cv::Point> poly(kMan, kMan + sizeof kMan / sizeof kMan[0]);
        cv::fillPoly(m, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(255));
        cv::Rect bb = cv::boundingRect(poly) & cv::Rect(0, 0, photo.cols, photo.rows);
        g_man_w = bb.width;
        cv::resize(photo(bb), man, cv::Size(), w->scale, w->scale, cv::INTER_AREA);
        cv::resize(m(bb), alpha, man.size(), 0, 0, cv::INTER_AREA);
        cv::GaussianBlur(alpha, alpha, cv::Size(5, 5), 0);  // a soft edge, as a real cut-out
    }
    cv::VideoWriter vw;
    cv::Mat f;
    for (int i = 0; cap.read(f); i++) {
        if (!vw.isOpened() &&
            !vw.open(out, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30.0, f.size()))
            return false;
        if (w && i >= w->enter) {
            int cx = static_cast<int>(std::lround(w->x0_px + w->v_px * (i - w->enter)));
            int ox = cx - man.cols / 2, oy = static_cast<int>(std::lround(w->feet_y_px)) - man.rows;
            for (int y = 0; y < man.rows; y++) {
                int Y = oy + y;
                if (Y < 0 || Y >= f.rows) continue;
                for (int x = 0; x < man.cols; x++) {
                    int X = ox + x;
                    if (X < 0 || X >= f.cols) continue;
                    if (w->behind && (i >= (int)g_masks.size() || g_masks[i].at<uchar>(Y, X))) continue;
                    float a = alpha.at<uchar>(y, x) / 255.0f;
                    if (a <= 0.0f) continue;
                    cv::Vec3b &d = f.at<cv::Vec3b>(Y, X);
                    const cv::Vec3b &p = man.at<cv::Vec3b>(y, x);
                    for (int k = 0; k < 3; k++) d[k] = cv::saturate_cast<uchar>(a * p[k] + (1.0f - a) * d[k]);
                }
            }
        }
        vw.write(f);
    }
    return vw.isOpened();
}

Run run(const std::string &args)
{
    return gs_test::run_shell(std::string(GS_PROGRAM) + " video " + args, "/dev/null");
}

// the tracked hip centre per frame (NaN when no pose)
std::vector<cv::Point2d> hips(const std::string &clip, bool keep)
{
    gs::PoseConfig cfg;
    cfg.keep_person = keep;
    cfg.threads = 1;
    gs::PoseTracker t(cfg);
    std::vector<cv::Point2d> v;
    if (!t.ok()) return v;
    cv::VideoCapture cap(clip);
    cv::Mat f;
    gs::PoseOutput o;
    for (int i = 0; cap.read(f); i++) {
        t.process(f, i / 30.0, &o);
        if (o.present)
            v.push_back(cv::Point2d(0.5 * (o.kp[23].x_px + o.kp[24].x_px), 0.5 * (o.kp[23].y_px + o.kp[24].y_px)));
        else
            v.push_back(cv::Point2d(NAN, NAN));
    }
    return v;
}

// every frame's 33 keypoints (c = 0 when no pose)
std::vector<std::vector<gs_kp>> keypoints(const std::string &clip)
{
    gs::PoseConfig cfg;
    cfg.threads = 1;
    gs::PoseTracker t(cfg);
    std::vector<std::vector<gs_kp>> v;
    if (!t.ok()) return v;
    cv::VideoCapture cap(clip);
    cv::Mat f;
    gs::PoseOutput o;
    for (int i = 0; cap.read(f); i++) {
        t.process(f, i / 30.0, &o);
        std::vector<gs_kp> k(o.kp, o.kp + gs::kPoseKeypoints);
        if (!o.present)
            for (gs_kp &p : k) p.c = 0.0f;
        v.push_back(k);
    }
    return v;
}

// The jumper's silhouette, drawn generously from keypoints: the trunk's polygon,
// thick limbs (0.4 of the trunk's length), the head (a disc of 0.5 trunk around
// the nose), hands and feet, dilated by 15 px. What lies outside is background.
cv::Mat body_mask(const std::vector<gs_kp> &k, cv::Size size)
{
    cv::Mat m(size, CV_8U, cv::Scalar(0));
    auto P = [&](int i) { return cv::Point((int)std::lround(k[i].x_px), (int)std::lround(k[i].y_px)); };
    cv::Point2d sh(0.5 * (k[11].x_px + k[12].x_px), 0.5 * (k[11].y_px + k[12].y_px));
    cv::Point2d hp(0.5 * (k[23].x_px + k[24].x_px), 0.5 * (k[23].y_px + k[24].y_px));
    double trunk = std::hypot(sh.x - hp.x, sh.y - hp.y);
    if (!(trunk > 10.0)) return m;
    std::vector<cv::Point> poly = {P(11), P(12), P(24), P(23)};
    cv::fillConvexPoly(m, poly, cv::Scalar(255));
    static const int bones[][2] = {{11, 12}, {11, 23}, {12, 24}, {23, 24}, {11, 13}, {13, 15}, {12, 14},
                                   {14, 16}, {15, 19}, {16, 20}, {15, 17}, {16, 18}, {23, 25}, {25, 27},
                                   {24, 26}, {26, 28}, {27, 29}, {29, 31}, {27, 31}, {28, 30}, {30, 32},
                                   {28, 32}, {0, 11}, {0, 12}};
    int th = std::max(4, (int)std::lround(0.4 * trunk));
    for (auto &b : bones) cv::line(m, P(b[0]), P(b[1]), cv::Scalar(255), th);
    cv::circle(m, P(0), (int)std::lround(0.5 * trunk), cv::Scalar(255), -1);
    cv::dilate(m, m, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(31, 31)));
    return m;
}

gs::PoseBody body(double t, double x, double y, double r)
{
    gs::PoseBody b;
    b.t_s = t;
    b.x_px = x;
    b.y_px = y;
    b.r_px = r;
    return b;
}

}  // namespace

// ---- the keeper's rules --------------------------------------------------------------

static void test_keeper_keeps_the_tracked_body(void)
{
    gs::PoseKeeper k;
    TEST_ASSERT_FALSE(k.has());
    // a jumper rising at 1200 px/s (r 400 px, 30 fps: 40 px a frame)
    for (int i = 0; i < 5; i++) k.accept(body(i / 30.0, 350.0, 700.0 - 40.0 * i, 400.0));
    gs::PoseBody p = k.predict(5 / 30.0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 500.0, p.y_px);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 350.0, p.x_px);
    // the jumper where predicted (a little off) and a passer-by 120 px to the side at the same size
    std::vector<gs::PoseBody> c = {body(5 / 30.0, 470.0, 520.0, 390.0), body(5 / 30.0, 360.0, 510.0, 410.0)};
    TEST_ASSERT_EQUAL_INT(1, k.match(c));
    // landmarks that are the jumper's, with the passer-by near: kept
    std::vector<gs::PoseBody> other = {c[0]};
    TEST_ASSERT_TRUE(k.keeps(body(5 / 30.0, 355.0, 505.0, 400.0), other));
    // landmarks nearer to the passer-by than to where the jumper is: not kept
    TEST_ASSERT_FALSE(k.keeps(body(5 / 30.0, 430.0, 515.0, 400.0), other));
    // a body 200 px (0.5 r) off in one frame: beyond a body's acceleration
    TEST_ASSERT_FALSE(k.plausible(body(5 / 30.0, 350.0, 300.0, 400.0)));
    // another size (1.6x)
    TEST_ASSERT_FALSE(k.plausible(body(5 / 30.0, 350.0, 500.0, 640.0)));
    TEST_ASSERT_TRUE(k.plausible(body(5 / 30.0, 350.0, 500.0, 440.0)));
    // nobody plausible: no match
    std::vector<gs::PoseBody> far = {body(5 / 30.0, 50.0, 500.0, 400.0)};
    TEST_ASSERT_EQUAL_INT(-1, k.match(far));
    TEST_ASSERT_TRUE(k.near(far[0], 5 / 30.0));  // 300 px away: its body reaches the ROI
    TEST_ASSERT_FALSE(k.near(body(5 / 30.0, 3000.0, 500.0, 400.0), 5 / 30.0));
    // after a long absence the gate has opened (any position), the size still counts
    TEST_ASSERT_TRUE(k.plausible(body(1.5, 50.0, 500.0, 400.0)));
    k.forget();
    TEST_ASSERT_FALSE(k.has());
}

static void test_keeper_config_keys(void)
{
    gs::PoseConfig c;
    char msg[96];
    TEST_ASSERT_TRUE(c.keep_person);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs::pose_config_set(&c, "keep_person", 11, "off", 3, msg, sizeof msg));
    TEST_ASSERT_FALSE(c.keep_person);
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs::pose_config_set(&c, "keep_person", 11, "1", 1, msg, sizeof msg));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs::pose_config_set(&c, "recheck_s", 9, "0.5", 3, msg, sizeof msg));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.5, c.recheck_s);
    TEST_ASSERT_EQUAL_INT(GS_ERANGE, gs::pose_config_set(&c, "recheck_s", 9, "-1", 2, msg, sizeof msg));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs::pose_config_set(&c, "forget_s", 8, "2", 1, msg, sizeof msg));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.0, c.forget_s);
}

static void test_keeper_look(void)
{
    // a navy shirt and grey trousers on a light wall; then the same body with a
    // grey passer-by over its shanks
    cv::Mat img(400, 300, CV_8UC3, cv::Scalar(200, 200, 200));
    gs_kp kp[33];
    for (gs_kp &k : kp) k = gs_kp{NAN, NAN, 0.0f};
    auto put = [&](int i, float x, float y) { kp[i] = gs_kp{x, y, 0.9f}; };
    put(11, 130, 100); put(12, 170, 100); put(23, 135, 200); put(24, 165, 200);
    put(25, 135, 280); put(26, 165, 280); put(27, 135, 360); put(28, 165, 360);
    cv::rectangle(img, cv::Rect(120, 90, 60, 115), cv::Scalar(90, 30, 20), -1);   // navy trunk
    cv::rectangle(img, cv::Rect(125, 200, 50, 170), cv::Scalar(60, 170, 230), -1); // skin-like legs
    gs::PoseLookHist a[gs::kLookParts], b[gs::kLookParts];
    gs::pose_look_sample(img, kp, 0.5, a);
    TEST_ASSERT_TRUE(a[gs::kLookTrunk].valid);
    TEST_ASSERT_TRUE(a[gs::kLookShankL].valid);
    TEST_ASSERT_FALSE(a[gs::kLookFootL].valid);  // no foot index given
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, gs::pose_look_distance(a[gs::kLookTrunk], a[gs::kLookTrunk]));
    gs::PoseLook look;
    double d[gs::kLookParts];
    for (int i = 0; i < look.config().learn_frames; i++) {
        look.compare(a, d);
        TEST_ASSERT_TRUE(d[gs::kLookTrunk] != d[gs::kLookTrunk]);  // NaN while learning
        look.learn(a, d);
    }
    TEST_ASSERT_TRUE(look.learnt());
    cv::rectangle(img, cv::Rect(110, 285, 80, 100), cv::Scalar(110, 110, 110), -1);  // grey passer-by
    gs::pose_look_sample(img, kp, 0.5, b);
    look.compare(b, d);
    std::printf("look: trunk %.2f, thigh %.2f, shank %.2f\n", d[gs::kLookTrunk], d[gs::kLookThighL], d[gs::kLookShankL]);
    TEST_ASSERT_TRUE(d[gs::kLookTrunk] < 0.1);
    TEST_ASSERT_TRUE(d[gs::kLookShankL] > 0.6);
    TEST_ASSERT_TRUE(d[gs::kLookShankR] > 0.6);
}

// ---- the composite -------------------------------------------------------------------

namespace {
struct Jump {
    int n = 0;
    double ft = NAN, q = NAN, h = NAN;
    bool accepted = false, camera_moved = false;
    int sessions = 0;
    std::string reason, warnings;
    std::string out;
};
Jump jump_of(const std::string &clip, const char *config)
{
    Jump j;
    // one OpenCV thread: the networks' sums then come out the same on any core count
    // (with 4 threads the apex crossing gave 0.806 s and q +1.3 % instead of 0.826 s, +0.4 %)
    std::string args = "'" + clip + "' --detector pose --threads 1";
    if (config) args += std::string(" --config '") + config + "'";
    Run r = run(args);
    TEST_ASSERT_EQUAL_INT(0, r.code);
    auto jumps = lines_of(r.out, "jump");
    j.n = static_cast<int>(jumps.size());
    j.sessions = static_cast<int>(lines_of(r.out, "session").size());
    j.out = r.out;
    if (j.n >= 1) {
        j.ft = num(jumps[0], "flight_time_s");
        j.q = num(jumps[0], "q_m_per_px");
        j.h = num(jumps[0], "height_m");
        j.accepted = jumps[0].find("\"accepted\":true") != std::string::npos;
        j.camera_moved = jumps[0].find("\"camera_moved\"") != std::string::npos;
        size_t rr = jumps[0].find("\"reason\":\"");
        if (rr != std::string::npos) j.reason = jumps[0].substr(rr + 10, jumps[0].find('"', rr + 10) - rr - 10);
        size_t w = jumps[0].find("\"warnings\":[");
        if (w != std::string::npos) j.warnings = jumps[0].substr(w + 12, jumps[0].find(']', w) - w - 12);
    }
    return j;
}
void print_jump(const char *tag, const Jump &j)
{
    std::printf("%s: %d flight(s), flight %.4f s, q %.6g m/px, height %.4f m, accepted %d%s%s, %d session events, "
                "warnings [%s]\n", tag, j.n, j.ft, j.q, j.h, j.accepted, j.reason.empty() ? "" : " ", j.reason.c_str(),
                j.sessions, j.warnings.c_str());
}
std::string g_off_cfg;  // [pose] keep_person = off: the ROI alone, as before the keeper
std::string g_cross_b;
Jump g_clean_jump;
}  // namespace

static void test_clean_copy_keeps_the_flight(void)
{
    if (g_clean.empty()) TEST_IGNORE_MESSAGE("jumpvision_jumps or opencv-doc is absent");
    g_clean_jump = jump_of(g_clean, nullptr);
    print_jump("clean FFV1 copy", g_clean_jump);
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, g_clean_jump.n, g_clean_jump.out.c_str());
    TEST_ASSERT_DOUBLE_WITHIN(2.0 / 30.0, 0.789, g_clean_jump.ft);
    TEST_ASSERT_TRUE(g_clean_jump.accepted);
    TEST_ASSERT_EQUAL_INT(2, g_clean_jump.sessions);
}

static void test_apex_crossing_keeps_the_jump(void)
{
    // The walker in front of the jumper's legs through most of the flight.
    // Measured before the keeper (keep_person = off, below): flight 0.646 s
    // (4.3 frames short of the app), q 0.002918 (+9.6 %), an accepted height of
    // 1.812 m (+6.5 %). With it: the covered shanks and feet give c = 0, the
    // flight is 0.826 s and q 0.002674 (+0.4 %); no stature can be seen while the
    // legs are covered at the apex (the only still upright frames of this clip),
    // so the flight is rejected no_size: no height rather than a wrong one.
    if (g_cross.empty() || !std::isfinite(g_clean_jump.q)) TEST_IGNORE_MESSAGE("no clean run");
    Jump j = jump_of(g_cross, nullptr);
    print_jump("apex crossing", j);
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, j.n, j.out.c_str());  // the same single flight, no extra one
    TEST_ASSERT_DOUBLE_WITHIN(2.0 / 30.0, 0.789, j.ft);
    // q within 2 %: the clean fit's own standard error is 0.65 % (a_se 23.9 of
    // 3683 px/s^2), and a third of the flight's frames lose their lower legs
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * g_clean_jump.q, g_clean_jump.q, j.q);
    // a height, if one is given, is the clean run's to 2 %
    if (j.accepted) TEST_ASSERT_DOUBLE_WITHIN(0.02 * g_clean_jump.h, g_clean_jump.h, j.h);
    TEST_ASSERT_TRUE_MESSAGE(j.camera_moved, "the handheld camera is still noticed");
    TEST_ASSERT_EQUAL_INT_MESSAGE(2, j.sessions, "one visit: start and end, no split");
}

static void test_apex_crossing_without_the_keeper_is_corrupted(void)
{
    // the clip is a real hard case: the ROI alone gets a wrong flight and q
    if (g_cross.empty() || g_off_cfg.empty() || !std::isfinite(g_clean_jump.q)) TEST_IGNORE_MESSAGE("no clean run");
    Jump j = jump_of(g_cross, g_off_cfg.c_str());
    print_jump("apex crossing, keep_person = off", j);
    bool good = j.n == 1 && std::fabs(j.ft - 0.789) <= 2.0 / 30.0 && std::fabs(j.q - g_clean_jump.q) <= 0.02 * g_clean_jump.q;
    TEST_ASSERT_FALSE(good);
}

static void test_landing_crossing_does_not_take_the_track(void)
{
    // The walker in front from the descent to after the landing. The ROI alone
    // slides onto him (frames 28-37) and follows him out of the frame: measured
    // at frame 45 the tracked hip at x 618, the walker's centre 635, the jumper's
    // hip 361. With the keeper the census finds the jumper again (frame 47) and
    // keeps him to the end. (The flight itself is lost either way: the landing is
    // hidden; no height may be accepted.)
    if (g_cross_b.empty()) TEST_IGNORE_MESSAGE("jumpvision_jumps or opencv-doc is absent");
    std::vector<cv::Point2d> clean = hips(g_clean, false), plain = hips(g_cross_b, false),
                             kept = hips(g_cross_b, true);
    TEST_ASSERT_EQUAL_INT(54, (int)clean.size());
    TEST_ASSERT_EQUAL_INT(54, (int)plain.size());
    TEST_ASSERT_EQUAL_INT(54, (int)kept.size());
    Walk w;
    w.x0_px = -100;
    double walker_x = w.x0_px + w.v_px * (45 - w.enter);
    std::printf("frame 45: ROI-only hip x %.0f, clean %.0f, walker %.0f\n", plain[45].x, clean[45].x, walker_x);
    TEST_ASSERT_TRUE(std::fabs(plain[45].x - walker_x) < std::fabs(plain[45].x - clean[45].x));
    double worst = 0.0;
    for (int i = 47; i < 54; i++) {
        TEST_ASSERT_TRUE(std::isfinite(kept[i].x));
        worst = std::max(worst, std::hypot(kept[i].x - clean[i].x, kept[i].y - clean[i].y));
    }
    std::printf("frames 47-53 with the keeper: hip within %.1f px of the clean run's\n", worst);
    TEST_ASSERT_TRUE(worst < 40.0);  // the jumper's torso is ~125 px here, the walker 250 px away
    Jump j = jump_of(g_cross_b, nullptr);
    print_jump("landing crossing", j);
    TEST_ASSERT_TRUE(j.n <= 1);
    if (j.accepted) TEST_ASSERT_DOUBLE_WITHIN(0.02 * g_clean_jump.h, g_clean_jump.h, j.h);
    TEST_ASSERT_EQUAL_INT(2, j.sessions);
}

// ---- the sweep: other crossings, each held to the product's promise -------------------

namespace {
struct Variant {
    const char *name;
    Walk w;
    std::string clip;
};
std::vector<Variant> g_sweep;

Walk walk(double scale, double feet_y, double x0, double v, bool behind)
{
    Walk w;
    w.scale = scale;
    w.feet_y_px = feet_y;
    w.x0_px = x0;
    w.v_px = v;
    w.behind = behind;
    return w;
}

// frames where the walker's box meets the jumper's (clean keypoints' box)
bool overlaps(const Walk &w, int i)
{
    if (i < w.enter || i >= (int)g_clean_kp.size()) return false;
    const std::vector<gs_kp> &k = g_clean_kp[i];
    float x0 = 1e9f, x1 = -1e9f;
    for (const gs_kp &p : k) {
        x0 = std::min(x0, p.x_px);
        x1 = std::max(x1, p.x_px);
    }
    double half = 0.5 * w.scale * g_man_w;
    double cx = w.x0_px + w.v_px * (i - w.enter);
    return cx + half > x0 && cx - half < x1;
}
}  // namespace

static void test_sweep_keeps_the_promise(void)
{
    // Every crossing: no accepted height off the clean run's by more than 2 %, no
    // extra flight, one visit (no session split); a flight the walker overlaps
    // carries other_motion, accepted or not. Before the other-motion cue this
    // failed on "behind" only: 1.650 m accepted without a warning (clean 1.702 m).
    if (g_sweep.empty() || !std::isfinite(g_clean_jump.h)) TEST_IGNORE_MESSAGE("no clean run");
    int bad = 0;
    std::string why;
    for (const Variant &v : g_sweep) {
        Jump j = jump_of(v.clip, nullptr);
        int ov = 0;
        double t0 = j.n ? num(lines_of(j.out, "jump")[0], "t_takeoff_s") : NAN;
        double t1 = j.n ? num(lines_of(j.out, "jump")[0], "t_land_s") : NAN;
        for (int i = 0; i < (int)g_clean_kp.size(); i++)
            if (i / 30.0 >= t0 - 0.05 && i / 30.0 <= t1 + 0.05 && overlaps(v.w, i)) ov++;
        bool warned = j.n && lines_of(j.out, "jump")[0].find(kOverlapWarning) != std::string::npos;
        char tag[160];
        std::snprintf(tag, sizeof tag, "sweep %-12s (scale %.2f, feet %.0f, x %.1f, %.1f px/f%s), overlap %2d frames, warned %d",
                      v.name, v.w.scale, v.w.feet_y_px, v.w.x0_px, v.w.v_px, v.w.behind ? ", behind" : "", ov, warned);
        print_jump(tag, j);
        std::string e;
        if (j.n > 1) e += " extra flight;";
        if (j.sessions != 2) e += " session split;";
        if (j.accepted && std::fabs(j.h - g_clean_jump.h) > 0.02 * g_clean_jump.h && !warned) e += " wrong height accepted without a warning;";
        if (j.accepted && std::fabs(j.h - g_clean_jump.h) > 0.02 * g_clean_jump.h && warned) e += " wrong height accepted (warned);";
        if (j.accepted && ov > 0 && !warned) e += " overlapped flight accepted without a warning;";
        if (!j.accepted && ov > 0 && !warned) e += " overlapped flight without other_motion;";
        if (!e.empty()) {
            bad++;
            why += std::string(v.name) + ":" + e + " ";
        }
    }
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, bad, why.c_str());
}

int main(void)
{
    std::snprintf(g_gym, sizeof g_gym, "%s/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4", GS_SHARED_DIR);
    char tmpl[] = "/tmp/gs_test_pose_crossing.XXXXXX";
    bool data = exists(g_gym) && exists(kWalkerPhoto);
    if (data && mkdtemp(tmpl)) {
        g_dir = tmpl;
        Walk w;
        Walk wb;
        wb.x0_px = -100;
        std::string clean = g_dir + "/clean.avi", cross = g_dir + "/crossing.avi", cross_b = g_dir + "/crossing_b.avi";
        std::string off = g_dir + "/off.cfg";
        FILE *f = std::fopen(off.c_str(), "w");
        if (f) {
            std::fputs("[pose]\nkeep_person = off\n", f);
            std::fclose(f);
            g_off_cfg = off;
        }
        bool ok = write_clip(clean, nullptr) && write_clip(cross, &w) && write_clip(cross_b, &wb);
        if (ok) {
            g_clean = clean;
            g_cross = cross;
            g_cross_b = cross_b;
            g_clean_kp = keypoints(clean);
            cv::Size fs(720, 1280);
            {
                cv::VideoCapture cap(clean);
                cv::Mat fr;
                if (cap.read(fr)) fs = fr.size();
            }
            for (const std::vector<gs_kp> &k : g_clean_kp) g_masks.push_back(body_mask(k, fs));
            g_sweep = {{"speed 15", walk(1.55, 1100, 2.5, 15.0, false), ""},
                       {"speed 20", walk(1.55, 1100, 2.5, 20.0, false), ""},
                       {"scale 1.45", walk(1.45, 1100, 2.5, 17.5, false), ""},
                       {"scale 1.65", walk(1.65, 1100, 2.5, 17.5, false), ""},
                       {"start x 30", walk(1.55, 1100, 30.0, 17.5, false), ""},
                       {"behind", walk(1.45, 1000, 2.5, 17.5, true), ""}};
            for (size_t i = 0; ok && i < g_sweep.size(); i++) {
                g_sweep[i].clip = g_dir + "/sweep" + std::to_string(i) + ".avi";
                ok = write_clip(g_sweep[i].clip, &g_sweep[i].w);
            }
        }
        if (!ok) {
            std::fprintf(stderr, "cannot write the FFV1 clips in %s\n", g_dir.c_str());
            return 1;
        }
    }
    UNITY_BEGIN();
    RUN_TEST(test_keeper_keeps_the_tracked_body);
    RUN_TEST(test_keeper_config_keys);
    RUN_TEST(test_keeper_look);
    RUN_TEST(test_clean_copy_keeps_the_flight);
    RUN_TEST(test_apex_crossing_keeps_the_jump);
    RUN_TEST(test_apex_crossing_without_the_keeper_is_corrupted);
    RUN_TEST(test_landing_crossing_does_not_take_the_track);
    RUN_TEST(test_sweep_keeps_the_promise);
    int rc = UNITY_END();
    if (!g_dir.empty() && std::getenv("GS_KEEP_CLIPS")) {
        std::printf("clips kept in %s\n", g_dir.c_str());
    } else if (!g_dir.empty()) {
        for (size_t i = 0; i < g_sweep.size(); i++) std::remove(g_sweep[i].clip.c_str());
        std::remove((g_dir + "/clean.avi").c_str());
        std::remove((g_dir + "/crossing.avi").c_str());
        std::remove((g_dir + "/crossing_b.avi").c_str());
        std::remove((g_dir + "/off.cfg").c_str());
        rmdir(g_dir.c_str());
    }
    return rc;
}
