// pose_blazepose.cpp - see pose_blazepose.hpp and docs/pose.md.
#include "pose_blazepose.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <thread>
#include <sys/stat.h>

#include "camera_motion.hpp"
#include "pose_look.hpp"
#include "side_thread.hpp"
#include "warp_crop.hpp"

#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#ifndef GS_MODELS_DEFAULT_DIR
#define GS_MODELS_DEFAULT_DIR "models"
#endif

namespace gs {

namespace {

const float kNaNf = std::numeric_limits<float>::quiet_NaN();
const double kPi = 3.14159265358979323846;

constexpr int kDetSide = 224;
constexpr int kDetCoords = 12;       // box (4) + 4 keypoints x (x, y)
constexpr int kLmSide = 256;
constexpr int kLmPoints = 39;        // 33 keypoints, 2 alignment points, 4 unused
constexpr int kLmValues = 5;         // x, y, z, visibility logit, presence logit
constexpr int kHeatmapKernel = 7;    // MediaPipe's refinement window (heatmap cells)
constexpr float kHeatmapMinConf = 0.5f;
constexpr double kRoiScale = 1.25;   // margin the landmark network was trained with
constexpr double kMinRoiPx = 16.0;   // a tracked ROI smaller than this is no person
// Look distance (Bhattacharyya, pose_look.hpp) above which a part is not the
// kept person's, per part: trunk, upper arms, forearms, thighs, shanks, feet.
// Measured on the gym jump alone (the reference following the body), the most
// any part of the one person reached: trunk 0.63 (the take-off blur, the shirt
// riding up), upper arms 0.71, forearms 0.72, thighs 0.72, shanks 0.38, feet
// 0.56; a grey passer-by over the shanks 0.52-0.91. Arms and thighs change too
// much with the pose to judge them by colour here.
const double kLookMax[kLookParts] = {0.75, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 0.48, 0.48, 0.65, 0.65};

double now_ms()
{
    return std::chrono::duration<double, std::milli>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

float sigmoid(float v)
{
    v = std::max(-100.0f, std::min(100.0f, v));  // score clipping as MediaPipe's decoder
    return 1.0f / (1.0f + std::exp(-v));
}

bool file_exists(const std::string &path)
{
    struct stat st;
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// One-euro filter (Casiez et al. 2012) of one value in ROI sizes: a still value
// is smoothed hard (min_cutoff), a moving one follows quickly (beta).
struct OneEuro {
    double min_cutoff_hz = 0.01, beta = 10.0, d_cutoff_hz = 1.0;  // MediaPipe's for the pose ROI
    bool init = false;
    double x = 0.0, dx = 0.0;

    static double alpha(double cutoff_hz, double dt_s)
    {
        double tau = 1.0 / (2.0 * kPi * cutoff_hz);
        return 1.0 / (1.0 + tau / dt_s);
    }
    double step(double v, double dt_s)
    {
        if (!init || !(dt_s > 0.0)) {
            init = true;
            x = v;
            dx = 0.0;
            return x;
        }
        double d = (v - x) / dt_s;
        dx += alpha(d_cutoff_hz, dt_s) * (d - dx);
        double cutoff = min_cutoff_hz + beta * std::fabs(dx);
        x += alpha(cutoff, dt_s) * (v - x);
        return x;
    }
};

// ---------------------------------------------------------------- config ---

bool key_is(const char *key, size_t len, const char *name)
{
    return std::strlen(name) == len && std::memcmp(key, name, len) == 0;
}

void put_msg(char *msg, size_t cap, const char *text)
{
    if (msg && cap > 0) std::snprintf(msg, cap, "%s", text);
}

gs_status num_in(const char *v, size_t len, double lo, double hi, double *out, char *msg,
                 size_t cap)
{
    if (len == 0 || len > 63) {
        put_msg(msg, cap, "expected a number");
        return GS_EINVAL;
    }
    char buf[64];
    std::memcpy(buf, v, len);
    buf[len] = '\0';
    char *end = nullptr;
    double d = std::strtod(buf, &end);
    if (end != buf + len || !std::isfinite(d)) {
        put_msg(msg, cap, "expected a number");
        return GS_EINVAL;
    }
    if (d < lo || d > hi) {
        char b[96];
        std::snprintf(b, sizeof b, "must be within %g..%g", lo, hi);
        put_msg(msg, cap, b);
        return GS_ERANGE;
    }
    *out = d;
    return GS_OK;
}

// ------------------------------------------------------------- detections ---

float iou(const PoseDetection &a, const PoseDetection &b)
{
    float ix = std::min(a.xmax, b.xmax) - std::max(a.xmin, b.xmin);
    float iy = std::min(a.ymax, b.ymax) - std::max(a.ymin, b.ymin);
    if (ix <= 0.0f || iy <= 0.0f) return 0.0f;
    float inter = ix * iy;
    float uni = (a.xmax - a.xmin) * (a.ymax - a.ymin) + (b.xmax - b.xmin) * (b.ymax - b.ymin) - inter;
    return uni > 0.0f ? inter / uni : 0.0f;
}

}  // namespace

const char *pose_model_name(PoseModel m)
{
    switch (m) {
    case PoseModel::lite: return "lite";
    case PoseModel::full: return "full";
    case PoseModel::heavy: return "heavy";
    }
    return "?";
}

gs_status pose_config_set(void *ctx, const char *key, size_t key_len, const char *value,
                          size_t value_len, char *msg, size_t cap)
{
    PoseConfig *c = static_cast<PoseConfig *>(ctx);
    std::string v(value, value_len);
    double d = 0.0;
    gs_status st;
    if (key_is(key, key_len, "models")) {
        if (v.empty()) {
            put_msg(msg, cap, "expected a folder");
            return GS_EINVAL;
        }
        c->models_dir = v;
        return GS_OK;
    }
    if (key_is(key, key_len, "model")) {
        if (v == "lite") c->model = PoseModel::lite;
        else if (v == "full") c->model = PoseModel::full;
        else if (v == "heavy") c->model = PoseModel::heavy;
        else {
            put_msg(msg, cap, "expected lite, full or heavy");
            return GS_EINVAL;
        }
        return GS_OK;
    }
    if (key_is(key, key_len, "engine")) {
        if (!pose_engine_from_name(v, &c->engine)) {
            put_msg(msg, cap, "expected auto, opencv or openvino");
            return GS_EINVAL;
        }
        if (!pose_engine_built(c->engine)) {
            put_msg(msg, cap, "this build has no OpenVINO (tools/fetch_engine.sh installs it; configure again)");
            return GS_EINVAL;
        }
        return GS_OK;
    }
    if (key_is(key, key_len, "threads")) {
        if ((st = num_in(value, value_len, 0.0, 64.0, &d, msg, cap)) != GS_OK) return st;
        if (d != std::floor(d)) {
            put_msg(msg, cap, "expected a whole number");
            return GS_EINVAL;
        }
        c->threads = static_cast<int>(d);
        return GS_OK;
    }
    if (key_is(key, key_len, "min_detection"))
        return num_in(value, value_len, 0.01, 0.99, &c->min_detection, msg, cap);
    if (key_is(key, key_len, "min_tracking"))
        return num_in(value, value_len, 0.01, 0.99, &c->min_tracking, msg, cap);
    if (key_is(key, key_len, "roi_smoothing")) {
        if (v == "on") c->roi_smoothing = true;
        else if (v == "off") c->roi_smoothing = false;
        else {
            put_msg(msg, cap, "expected on or off");
            return GS_EINVAL;
        }
        return GS_OK;
    }
    if (key_is(key, key_len, "keep_person")) {
        if (v == "on") c->keep_person = true;
        else if (v == "off") c->keep_person = false;
        else {
            put_msg(msg, cap, "expected on or off");
            return GS_EINVAL;
        }
        return GS_OK;
    }
    if (key_is(key, key_len, "recheck_s")) return num_in(value, value_len, 0.0, 60.0, &c->recheck_s, msg, cap);
    if (key_is(key, key_len, "forget_s")) return num_in(value, value_len, 0.05, 600.0, &c->forget_s, msg, cap);
    if (key_is(key, key_len, "heatmap_refine")) {
        if (v == "on") c->heatmap_refine = true;
        else if (v == "off") c->heatmap_refine = false;
        else {
            put_msg(msg, cap, "expected on or off");
            return GS_EINVAL;
        }
        return GS_OK;
    }
    return GS_ENOKEY;
}

std::string pose_models_dir(const PoseConfig &cfg)
{
    if (!cfg.models_dir.empty()) return cfg.models_dir;
    const char *env = std::getenv("GS_MODELS_DIR");
    if (env && *env) return env;
    return GS_MODELS_DEFAULT_DIR;
}

namespace {

std::string detector_path(const PoseConfig &cfg, PoseEngine e)
{
    return pose_models_dir(cfg) + (e == PoseEngine::openvino ? "/pose_detection_strict.onnx" : "/pose_detection.onnx");
}

std::string landmark_path(const PoseConfig &cfg, PoseEngine e)
{
    std::string base = pose_models_dir(cfg) + "/pose_landmark_" + pose_model_name(cfg.model);
    if (e == PoseEngine::openvino) return base + "_noseg_strict.onnx";
    // the variant without the segmentation output when setup made it: the mask
    // is not used, and OpenCV would compute it (lite: ~21 instead of ~30 ms)
    if (file_exists(base + "_noseg.onnx")) return base + "_noseg.onnx";
    return base + ".onnx";
}

}  // namespace

PoseEngine pose_engine_in_force(const PoseConfig &cfg)
{
    if (cfg.engine != PoseEngine::automatic) return cfg.engine;
    if (pose_engine_built(PoseEngine::openvino) && file_exists(detector_path(cfg, PoseEngine::openvino)) &&
        file_exists(landmark_path(cfg, PoseEngine::openvino)))
        return PoseEngine::openvino;
    return PoseEngine::opencv;
}

std::string pose_detector_path(const PoseConfig &cfg)
{
    return detector_path(cfg, pose_engine_in_force(cfg));
}

std::string pose_landmark_path(const PoseConfig &cfg)
{
    return landmark_path(cfg, pose_engine_in_force(cfg));
}

bool pose_models_present(const PoseConfig &cfg, std::string &err)
{
    for (const std::string &path : {pose_detector_path(cfg), pose_landmark_path(cfg)}) {
        if (!file_exists(path)) {
            err = "pose model not found: " + path +
                  " (tools/fetch_models.sh fetches and converts the models, tools/bootstrap.sh "
                  "runs it; or point --models DIR, [pose] models or GS_MODELS_DIR at them)";
            return false;
        }
    }
    return true;
}

// ---------------------------------------------------------------- geometry ---

PoseRoi pose_roi_from_alignment(double x0_px, double y0_px, double x1_px, double y1_px,
                                double scale)
{
    PoseRoi r;
    double dx = x1_px - x0_px, dy = y1_px - y0_px;
    r.cx_px = x0_px;
    r.cy_px = y0_px;
    r.size_px = 2.0 * std::sqrt(dx * dx + dy * dy) * scale;
    // y flipped (image y is down): the vector's angle against the target of 90 degrees
    double rot = kPi / 2.0 - std::atan2(-dy, dx);
    rot -= 2.0 * kPi * std::floor((rot + kPi) / (2.0 * kPi));  // to [-pi, pi)
    r.rotation_rad = rot;
    return r;
}

cv::Mat pose_roi_crop_to_image(const PoseRoi &roi, int side)
{
    // crop pixel centre u lies at the normalised (u + 0.5) / side of the ROI
    double s = roi.size_px / side;
    double c = std::cos(roi.rotation_rad), sn = std::sin(roi.rotation_rad);
    double o = 0.5 * s - 0.5 * roi.size_px;  // crop pixel 0's offset from the centre, both axes
    cv::Mat m(2, 3, CV_64F);
    m.at<double>(0, 0) = c * s;
    m.at<double>(0, 1) = -sn * s;
    m.at<double>(0, 2) = roi.cx_px + c * o - sn * o;
    m.at<double>(1, 0) = sn * s;
    m.at<double>(1, 1) = c * s;
    m.at<double>(1, 2) = roi.cy_px + sn * o + c * o;
    return m;
}

cv::Point2d pose_roi_to_image(const PoseRoi &roi, double xn, double yn)
{
    double dx = (xn - 0.5) * roi.size_px, dy = (yn - 0.5) * roi.size_px;
    double c = std::cos(roi.rotation_rad), s = std::sin(roi.rotation_rad);
    return cv::Point2d(roi.cx_px + c * dx - s * dy, roi.cy_px + s * dx + c * dy);
}

std::vector<PoseAnchor> pose_detector_anchors()
{
    // MediaPipe's SSD anchors for pose_detection: 5 layers with strides
    // 8, 16, 32, 32, 32; two anchors per layer and location (aspect 1 and the
    // interpolated scale), fixed size, offset 0.5. Layers of equal stride share
    // one grid, so the 32-stride grid carries 6 anchors per cell.
    static const int strides[] = {8, 16, 32, 32, 32};
    const int n_layers = 5;
    std::vector<PoseAnchor> out;
    out.reserve(2254);
    int layer = 0;
    while (layer < n_layers) {
        int last = layer;
        while (last < n_layers && strides[last] == strides[layer]) last++;
        int per_cell = 2 * (last - layer);
        int fm = (kDetSide + strides[layer] - 1) / strides[layer];
        for (int y = 0; y < fm; y++)
            for (int x = 0; x < fm; x++)
                for (int a = 0; a < per_cell; a++)
                    out.push_back({(x + 0.5f) / fm, (y + 0.5f) / fm});
        layer = last;
    }
    return out;
}

PoseLetterbox pose_letterbox(int width, int height, int side)
{
    PoseLetterbox lb;
    lb.side = side;
    double f = static_cast<double>(side) / std::max(width, height);
    int w = std::max(1, static_cast<int>(std::lround(width * f)));
    int h = std::max(1, static_cast<int>(std::lround(height * f)));
    lb.scale_x = static_cast<double>(w) / width;
    lb.scale_y = static_cast<double>(h) / height;
    lb.pad_x = (side - w) / 2;
    lb.pad_y = (side - h) / 2;
    return lb;
}

std::vector<PoseDetection> pose_decode_detections(const float *regressors, const float *logits,
                                                  const std::vector<PoseAnchor> &anchors,
                                                  const PoseLetterbox &lb, double min_score,
                                                  double nms_iou)
{
    // decode in the detector's continuous input coordinates (0..side)
    const double S = lb.side;
    std::vector<PoseDetection> cand;
    for (size_t i = 0; i < anchors.size(); i++) {
        float score = sigmoid(logits[i]);
        if (score < min_score) continue;
        const float *r = regressors + i * kDetCoords;
        const double ax = anchors[i].x * S, ay = anchors[i].y * S;
        PoseDetection d;
        d.score = score;
        double cx = ax + r[0], cy = ay + r[1], w = r[2], h = r[3];
        d.xmin = static_cast<float>(cx - 0.5 * w);
        d.xmax = static_cast<float>(cx + 0.5 * w);
        d.ymin = static_cast<float>(cy - 0.5 * h);
        d.ymax = static_cast<float>(cy + 0.5 * h);
        for (int k = 0; k < 4; k++) {
            d.kp_x[k] = static_cast<float>(ax + r[4 + 2 * k]);
            d.kp_y[k] = static_cast<float>(ay + r[5 + 2 * k]);
        }
        cand.push_back(d);
    }
    std::stable_sort(cand.begin(), cand.end(),
                     [](const PoseDetection &a, const PoseDetection &b) { return a.score > b.score; });

    // weighted NMS: each kept detection is the score-weighted mean of its cluster
    std::vector<PoseDetection> out;
    std::vector<bool> used(cand.size(), false);
    for (size_t i = 0; i < cand.size(); i++) {
        if (used[i]) continue;
        const PoseDetection &top = cand[i];
        PoseDetection m;
        double wsum = 0.0, acc[4 + 8] = {0};
        for (size_t j = i; j < cand.size(); j++) {
            if (used[j]) continue;
            if (j != i && iou(top, cand[j]) <= nms_iou) continue;
            used[j] = true;
            const PoseDetection &c = cand[j];
            double w = c.score;
            wsum += w;
            acc[0] += w * c.xmin; acc[1] += w * c.ymin; acc[2] += w * c.xmax; acc[3] += w * c.ymax;
            for (int k = 0; k < 4; k++) {
                acc[4 + 2 * k] += w * c.kp_x[k];
                acc[5 + 2 * k] += w * c.kp_y[k];
            }
        }
        m.score = top.score;
        // back to image pixels (pixel centres at integers)
        auto ix = [&](double u) { return static_cast<float>((u / wsum - lb.pad_x) / lb.scale_x - 0.5); };
        auto iy = [&](double v) { return static_cast<float>((v / wsum - lb.pad_y) / lb.scale_y - 0.5); };
        m.xmin = ix(acc[0]); m.ymin = iy(acc[1]); m.xmax = ix(acc[2]); m.ymax = iy(acc[3]);
        for (int k = 0; k < 4; k++) {
            m.kp_x[k] = ix(acc[4 + 2 * k]);
            m.kp_y[k] = iy(acc[5 + 2 * k]);
        }
        out.push_back(m);
    }
    return out;
}

// ------------------------------------------------------------------ keeper ---

PoseBody PoseKeeper::predict(double t_s) const
{
    PoseBody p = hist_.back();
    if (hist_.size() >= 2) {
        const PoseBody &a = hist_[hist_.size() - 2], &b = hist_.back();
        double dt = b.t_s - a.t_s;
        if (dt > 0.0) {
            double vx = (b.x_px - a.x_px) / dt, vy = (b.y_px - a.y_px) / dt;
            double v = std::hypot(vx, vy), vmax = cfg_.max_speed_r_s * b.r_px;
            if (v > vmax) {
                vx *= vmax / v;
                vy *= vmax / v;
            }
            double h = std::max(0.0, t_s - b.t_s);
            p.x_px += vx * h;
            p.y_px += vy * h;
        }
    }
    p.t_s = t_s;
    return p;
}

double PoseKeeper::cost(const PoseBody &b) const
{
    PoseBody p = predict(b.t_s);
    return std::hypot(b.x_px - p.x_px, b.y_px - p.y_px) / p.r_px + std::fabs(std::log(b.r_px / p.r_px));
}

bool PoseKeeper::plausible(const PoseBody &b) const
{
    if (hist_.empty()) return true;
    if (!(b.r_px > 0.0) || !std::isfinite(b.x_px) || !std::isfinite(b.y_px)) return false;
    PoseBody p = predict(b.t_s);
    double h = std::max(0.0, b.t_s - hist_.back().t_s);
    double gate = (cfg_.gate_r + 0.5 * cfg_.max_accel_r_s2 * h * h) * p.r_px;
    if (std::hypot(b.x_px - p.x_px, b.y_px - p.y_px) > gate) return false;
    double k = b.r_px / p.r_px;
    return k <= cfg_.size_ratio && k >= 1.0 / cfg_.size_ratio;
}

int PoseKeeper::match(const std::vector<PoseBody> &cands) const
{
    int best = -1;
    double bc = 0.0;
    for (size_t i = 0; i < cands.size(); i++) {
        if (!plausible(cands[i])) continue;
        double c = cost(cands[i]);
        if (best < 0 || c < bc) {
            best = static_cast<int>(i);
            bc = c;
        }
    }
    return best;
}

bool PoseKeeper::near(const PoseBody &o, double t_s) const
{
    if (hist_.empty()) return false;
    PoseBody p = predict(t_s);
    return std::hypot(o.x_px - p.x_px, o.y_px - p.y_px) < cfg_.near_r * (p.r_px + o.r_px);
}

bool PoseKeeper::keeps(const PoseBody &b, const std::vector<PoseBody> &others) const
{
    if (!plausible(b)) return false;
    if (hist_.empty()) return true;
    PoseBody p = predict(b.t_s);
    double d = std::hypot(b.x_px - p.x_px, b.y_px - p.y_px);
    for (const PoseBody &o : others)
        if (std::hypot(b.x_px - o.x_px, b.y_px - o.y_px) <= d) return false;
    return true;
}

void PoseKeeper::accept(const PoseBody &b)
{
    if (!hist_.empty() && b.t_s <= hist_.back().t_s) hist_.clear();  // time went back: a new stream
    hist_.push_back(b);
    size_t drop = 0;
    while (drop + 2 < hist_.size() && b.t_s - hist_[drop].t_s > cfg_.history_s) drop++;
    if (drop) hist_.erase(hist_.begin(), hist_.begin() + static_cast<std::ptrdiff_t>(drop));
}

// ----------------------------------------------------------------- tracker ---

struct PoseTracker::Impl {
    PoseConfig cfg;
    std::string error;
    bool ok = false;
    PoseEngine engine = PoseEngine::opencv;  // the one in force
    std::unique_ptr<PoseNet> det, lm;
    std::vector<std::string> det_out;  // regressors, logits
    std::vector<std::string> lm_out;   // landmarks, pose flag[, heatmap]
    bool heatmap_nchw = true;         // heatmap layout of the converted model
    int heatmap_side = 0;             // 0 = no heatmap output
    std::vector<PoseAnchor> anchors = pose_detector_anchors();
    bool tracking = false;
    PoseRoi roi;
    OneEuro roi_filter[4];  // alignment points x0, y0, x1, y1 in ROI sizes
    double last_t_s = 0.0;
    double roi_unit_px = 1.0;
    cv::Mat rgb_det, det_half, crop, blob, blob_det;  // kept: each frame writes into the same memory
    double align[4] = {0, 0, 0, 0};  // the last landmarks' alignment points, image px
    cv::Mat converted;                // a grey or BGRA frame as BGR

    // keeping one person
    PoseKeeper keeper;
    bool crowded = false;              // the last census saw another person near the tracked one
    double last_census_t = -1e300;     // time of the detector's last run
    PoseLook look;                     // the kept person's colours per body part
    double drift_r = 0.1;              // tracked vs fresh landmarks further apart than this x r: the ROI slid
    SideThread census_side;            // the census's detector beside the tracked ROI's landmarks

    bool process(const cv::Mat &bgr, double t_s, PoseOutput *out);
    bool process_plain(const cv::Mat &bgr, double t_s, PoseOutput *out);
    bool process_keep(const cv::Mat &bgr, double t_s, PoseOutput *out);

    // 8-bit BGR as is; 8-bit grey or BGRA converted; anything else: nullptr
    const cv::Mat *as_bgr(const cv::Mat &img)
    {
        if (img.empty() || img.depth() != CV_8U) return nullptr;
        if (img.channels() == 3) return &img;
        if (img.channels() == 1) cv::cvtColor(img, converted, cv::COLOR_GRAY2BGR);
        else if (img.channels() == 4) cv::cvtColor(img, converted, cv::COLOR_BGRA2BGR);
        else return nullptr;
        return &converted;
    }
    // an OpenCV error while running: kept (the first one), the frame gives no pose
    void fail(const cv::Exception &e)
    {
        if (error.empty()) error = std::string("pose network failed: ") + e.what();
    }

    // The next ROI from the filtered alignment points (values in units of the
    // ROI size when the track started, so the filter's speeds are scale-free).
    PoseRoi smooth_roi(const PoseRoi &raw, double t_s, bool restart)
    {
        if (restart) roi_unit_px = std::max(raw.size_px, 1.0);
        double dt = t_s - last_t_s;
        last_t_s = t_s;
        double f[4];
        for (int i = 0; i < 4; i++) {
            if (restart) roi_filter[i].init = false;
            f[i] = roi_filter[i].step(align[i] / roi_unit_px, dt) * roi_unit_px;
        }
        return pose_roi_from_alignment(f[0], f[1], f[2], f[3], kRoiScale);
    }

    // both networks, the detector's in a thread of its own: compiling them side by
    // side halves the start-up on two CPUs
    bool load(const std::string &det_path, const std::string &lm_path)
    {
        std::string det_error;
        std::thread t([&] { det = pose_net_load(engine, det_path, cfg.threads, det_error); });
        lm = pose_net_load(engine, lm_path, cfg.threads, error);
        t.join();
        if (!det) error = det_error;
        return det && lm;
    }

    // Run a zero input once and name the outputs by their shapes.
    bool find_outputs(const std::string &det_path, const std::string &lm_path)
    {
        try {
            std::vector<std::string> names = det->output_names();
            std::vector<cv::Mat> outs;
            det->run(cv::Mat(std::vector<int>{1, 3, kDetSide, kDetSide}, CV_32F, cv::Scalar(0)), names, outs);
            std::string reg, logit;
            for (size_t i = 0; i < outs.size(); i++) {
                if (outs[i].total() == anchors.size() * kDetCoords) reg = names[i];
                else if (outs[i].total() == anchors.size()) logit = names[i];
            }
            if (reg.empty() || logit.empty()) {
                error = det_path + ": expected outputs of 2254 x 12 regressors and 2254 scores";
                return false;
            }
            det_out = {reg, logit};

            names = lm->output_names();
            lm->run(cv::Mat(std::vector<int>{1, 3, kLmSide, kLmSide}, CV_32F, cv::Scalar(0)), names, outs);
            std::string pts, flag, hm;
            for (size_t i = 0; i < outs.size(); i++) {
                const cv::Mat &o = outs[i];
                if (o.total() == static_cast<size_t>(kLmPoints * kLmValues)) pts = names[i];
                else if (o.total() == 1) flag = names[i];
                else if (o.dims == 4 && (o.size[1] == kLmPoints || o.size[3] == kLmPoints) &&
                         o.total() % kLmPoints == 0) {
                    hm = names[i];
                    heatmap_nchw = o.size[1] == kLmPoints;
                    heatmap_side = heatmap_nchw ? o.size[2] : o.size[1];
                }
            }
            if (pts.empty() || flag.empty()) {
                error = lm_path + ": expected outputs of 195 landmark values and a pose flag";
                return false;
            }
            lm_out = {pts, flag};
            if (!hm.empty()) lm_out.push_back(hm);
        } catch (const cv::Exception &e) {
            error = "cannot run pose models: " + std::string(e.what());
            return false;
        }
        return true;
    }

    std::vector<PoseDetection> detect(const cv::Mat &bgr)
    {
        PoseLetterbox lb = pose_letterbox(bgr.cols, bgr.rows, kDetSide);
        int w = static_cast<int>(std::lround(lb.scale_x * bgr.cols));
        int h = static_cast<int>(std::lround(lb.scale_y * bgr.rows));
        // black border (-1 after scaling), as MediaPipe's zero border
        rgb_det.create(kDetSide, kDetSide, CV_8UC3);
        rgb_det.setTo(cv::Scalar::all(0));
        cv::Mat dst = rgb_det(cv::Rect(static_cast<int>(lb.pad_x), static_cast<int>(lb.pad_y), w, h));
        // area averaging against aliasing; a whole-factor step first keeps it
        // cheap (1080p: 3 ms instead of 14); both steps map extents to extents
        int k = static_cast<int>(std::floor(0.5 / std::max(lb.scale_x, lb.scale_y)));
        // (resize_area: cv::resize's pixels, its non-whole factor several times faster)
        if (k >= 2) {
            resize_area(bgr, det_half, cv::Size(bgr.cols / k, bgr.rows / k));
            resize_area(det_half, dst, dst.size());
        } else {
            resize_area(bgr, dst, dst.size());
        }
        cv::dnn::blobFromImage(rgb_det, blob_det, 1.0 / 127.5, cv::Size(), cv::Scalar::all(127.5), true, false, CV_32F);
        std::vector<cv::Mat> outs;
        det->run(blob_det, det_out, outs);
        cv::Mat reg = outs[0].isContinuous() ? outs[0] : outs[0].clone();
        cv::Mat lg = outs[1].isContinuous() ? outs[1] : outs[1].clone();
        return pose_decode_detections(reg.ptr<float>(), lg.ptr<float>(), anchors, lb,
                                      cfg.min_detection, cfg.nms_iou);
    }

    // Crop the rotated ROI to kLmSide x kLmSide, bilinear with replicated
    // borders as MediaPipe's CPU path. (Area-averaging large ROIs first, against
    // aliasing, did not help: on the gym jump the COM's rms about a quadratic
    // over frames 12-33 went lite 3.97 -> 4.91 px, full 1.93 -> 1.85, heavy
    // 2.70 -> 2.61.)
    void crop_roi(const cv::Mat &bgr, const PoseRoi &r)
    {
        warp_crop_bgr(bgr, pose_roi_crop_to_image(r, kLmSide), kLmSide, crop);
    }

    // Landmarks of one ROI into out; the next frame's ROI into *next.
    void landmarks(const cv::Mat &bgr, const PoseRoi &r, PoseOutput *out, PoseRoi *next)
    {
        crop_roi(bgr, r);
        bgr_to_rgb_blob(crop, 1.0 / 255.0, blob);
        std::vector<cv::Mat> outs;
        lm->run(blob, lm_out, outs);
        const float *raw = outs[0].ptr<float>();
        float presence = outs[1].ptr<float>()[0];
        out->presence = presence;
        out->present = presence >= cfg.min_tracking;
        out->roi = r;

        float xn[kLmPoints], yn[kLmPoints];
        for (int i = 0; i < kLmPoints; i++) {
            xn[i] = raw[i * kLmValues + 0] / kLmSide;
            yn[i] = raw[i * kLmValues + 1] / kLmSide;
        }
        if (cfg.heatmap_refine && outs.size() > 2 && heatmap_side > 0) {
            cv::Mat hmm = outs[2].isContinuous() ? outs[2] : outs[2].clone();
            refine(hmm.ptr<float>(), xn, yn);
        }
        for (int i = 0; i < kPoseKeypoints; i++) {
            cv::Point2d p = pose_roi_to_image(r, xn[i], yn[i]);
            float vis = sigmoid(raw[i * kLmValues + 3]);
            float inf = sigmoid(raw[i * kLmValues + 4]);
            out->kp[i].x_px = static_cast<float>(p.x);
            out->kp[i].y_px = static_cast<float>(p.y);
            out->kp[i].c = out->present ? vis * inf : 0.0f;
            out->z_px[i] = static_cast<float>(raw[i * kLmValues + 2] / kLmSide * r.size_px);
            out->visibility[i] = vis;
            out->in_frame[i] = inf;
        }
        if (next) {
            cv::Point2d a = pose_roi_to_image(r, xn[33], yn[33]);
            cv::Point2d b = pose_roi_to_image(r, xn[34], yn[34]);
            align[0] = a.x; align[1] = a.y; align[2] = b.x; align[3] = b.y;
            *next = pose_roi_from_alignment(a.x, a.y, b.x, b.y, kRoiScale);
        }
    }

    // MediaPipe's refinement: the sigmoid-weighted mean position of a 7x7
    // heatmap window around each landmark, when the window's peak is >= 0.5.
    // Cell col sits at col / side, as MediaPipe decodes it: the heatmap was
    // trained that way (with (col + 0.5) the refined points land 0.45 cells
    // right of the regressed ones on average; with col / side 0.07 across).
    void refine(const float *hm, float *xn, float *yn) const
    {
        const int n = heatmap_side, half = (kHeatmapKernel - 1) / 2;
        for (int k = 0; k < kLmPoints; k++) {
            int cc = static_cast<int>(std::floor(xn[k] * n)), cr = static_cast<int>(std::floor(yn[k] * n));
            if (cc < 0 || cc >= n || cr < 0 || cr >= n) continue;
            double sum = 0.0, sx = 0.0, sy = 0.0;
            float peak = 0.0f;
            for (int row = std::max(0, cr - half); row < std::min(n, cr + half + 1); row++)
                for (int col = std::max(0, cc - half); col < std::min(n, cc + half + 1); col++) {
                    float v = heatmap_nchw ? hm[(static_cast<size_t>(k) * n + row) * n + col]
                                           : hm[(static_cast<size_t>(row) * n + col) * kLmPoints + k];
                    float c = 1.0f / (1.0f + std::exp(-v));
                    sum += c;
                    sx += col * c;
                    sy += row * c;
                    peak = std::max(peak, c);
                }
            if (peak >= kHeatmapMinConf && sum > 0.0) {
                xn[k] = static_cast<float>(sx / sum / n);
                yn[k] = static_cast<float>(sy / sum / n);
            }
        }
    }
};

namespace {

void clear_output(PoseOutput *out, double t_s)
{
    out->t_s = t_s;
    out->present = false;
    out->detector_ran = false;
    out->presence = kNaNf;
    out->det_score = kNaNf;
    for (int i = 0; i < kPoseKeypoints; i++) {
        out->kp[i] = gs_kp{kNaNf, kNaNf, 0.0f};
        out->z_px[i] = kNaNf;
        out->visibility[i] = kNaNf;
        out->in_frame[i] = kNaNf;
    }
    out->roi = PoseRoi();
    out->persons = -1;
    out->rejected = false;
    out->covered = 0;
    out->det_ms = 0.0;
    out->lm_ms = 0.0;
}

}  // namespace

PoseTracker::PoseTracker(const PoseConfig &cfg) : p_(new Impl)
{
    p_->cfg = cfg;
    if (!pose_models_present(cfg, p_->error)) return;
    p_->engine = pose_engine_in_force(cfg);
    // OpenCV's pool serves its DNN and the frame's image work (process-wide)
    if (cfg.threads > 0) cv::setNumThreads(cfg.threads);
    const std::string dp = pose_detector_path(cfg), lp = pose_landmark_path(cfg);
    if (!p_->load(dp, lp)) return;
    if (!p_->find_outputs(dp, lp)) return;
    p_->ok = true;
}

PoseTracker::~PoseTracker() = default;

bool PoseTracker::ok() const { return p_->ok; }
const std::string &PoseTracker::error() const { return p_->error; }
PoseEngine PoseTracker::engine() const { return p_->engine; }

void PoseTracker::reset()
{
    p_->tracking = false;
    p_->keeper.forget();
    p_->look.forget();
    p_->crowded = false;
    p_->last_census_t = -1e300;
}

std::vector<PoseDetection> PoseTracker::detect(const cv::Mat &bgr)
{
    const cv::Mat *img = p_->as_bgr(bgr);
    if (!p_->ok || !img) return {};
    try {
        return p_->detect(*img);
    } catch (const cv::Exception &e) {
        p_->fail(e);
        return {};
    }
}

void PoseTracker::landmarks(const cv::Mat &bgr, const PoseRoi &roi, PoseOutput *out, PoseRoi *next_roi)
{
    clear_output(out, 0.0);
    const cv::Mat *img = p_->as_bgr(bgr);
    if (!p_->ok || !img || !(roi.size_px > 0.0) || !std::isfinite(roi.cx_px) || !std::isfinite(roi.cy_px)) return;
    try {
        p_->landmarks(*img, roi, out, next_roi);
    } catch (const cv::Exception &e) {
        p_->fail(e);
        clear_output(out, 0.0);
    }
}

bool PoseTracker::process(const cv::Mat &bgr, double t_s, PoseOutput *out)
{
    clear_output(out, t_s);
    const cv::Mat *img = p_->as_bgr(bgr);
    if (!p_->ok || !img) return false;
    try {
        return p_->process(*img, t_s, out);
    } catch (const cv::Exception &e) {
        p_->fail(e);
        p_->tracking = false;
        clear_output(out, t_s);
        return false;
    }
}

bool PoseTracker::Impl::process(const cv::Mat &bgr, double t_s, PoseOutput *out)
{
    return cfg.keep_person ? process_keep(bgr, t_s, out) : process_plain(bgr, t_s, out);
}

namespace {
PoseBody body_of(const PoseDetection &d, double t_s)
{
    PoseBody b;
    b.t_s = t_s;
    b.x_px = d.kp_x[0];
    b.y_px = d.kp_y[0];
    b.r_px = std::hypot(d.kp_x[1] - d.kp_x[0], d.kp_y[1] - d.kp_y[0]);
    return b;
}
}  // namespace

// One person kept (docs/pose.md, "One person"): the landmarks of the tracked ROI
// are taken when no census is due and they lie where the tracked body can be;
// otherwise the detector runs and says who is where: the tracked person is the
// plausible detection nearest to the prediction, the others are someone else;
// the ROI's landmarks are kept when they are nearer to the tracked person than
// to anyone else, else the tracked person's own detection is tried, else the
// frame gives no pose and the next frame asks the detector again.
bool PoseTracker::Impl::process_keep(const cv::Mat &bgr, double t_s, PoseOutput *out)
{
    if (keeper.has() && (t_s - keeper.last_t() > cfg.forget_s || t_s < keeper.last_t())) {
        keeper.forget();  // unseen too long (or a new stream): whoever comes next is a new person
        look.forget();
        crowded = false;
    }
    PoseRoi next;
    PoseBody body;
    auto run_lm = [&](const PoseRoi &r) {
        double t0 = now_ms();
        landmarks(bgr, r, out, &next);
        out->lm_ms += now_ms() - t0;
        body.t_s = t_s;
        body.x_px = align[0];
        body.y_px = align[1];
        body.r_px = std::hypot(align[2] - align[0], align[3] - align[1]);
        return out->present && next.size_px >= kMinRoiPx && std::isfinite(next.cx_px);
    };
    auto accept = [&](bool restart) {
        // the look: parts whose colours are not the person's are covered (or someone else's)
        PoseLookHist h[kLookParts];
        double d[kLookParts];
        pose_look_sample(bgr, out->kp, look.config().min_c, h);
        look.compare(h, d);
        int covered = 0;
        for (int p = 0; p < kLookParts; p++) {
            if (!(d[p] > kLookMax[p])) continue;
            covered |= 1 << p;
            for (const int *k = pose_look_part_keypoints(p); *k >= 0; k++) out->kp[*k].c = 0.0f;
        }
        out->covered = covered;
        if (covered & (1 << kLookTrunk)) {  // the trunk is not the person's: nobody to follow here
            out->rejected = true;
            out->present = false;
            for (int k = 0; k < kPoseKeypoints; k++) out->kp[k].c = 0.0f;
            tracking = false;
            return false;
        }
        look.learn(h, d);
        keeper.accept(body);
        roi = cfg.roi_smoothing ? smooth_roi(next, t_s, restart) : next;
        tracking = true;
        return true;
    };
    bool lm_ok = false;
    std::vector<PoseDetection> dets;
    bool detected = false;
    double det_ms = 0.0;
    if (tracking) {
        const bool census_due = crowded || t_s - last_census_t >= cfg.recheck_s || t_s < last_census_t;
        if (census_due) {  // the census's detector (the same frame either way) beside the landmarks
            census_side.start([&] {
                const double t0 = now_ms();
                dets = detect(bgr);
                det_ms = now_ms() - t0;
            });
            SideJob job(census_side);
            lm_ok = run_lm(roi);
            job.rethrow();
            detected = true;
        } else {
            lm_ok = run_lm(roi);
            if (lm_ok && (!keeper.has() || keeper.plausible(body))) return accept(false);
        }
    }
    // the census: who is where
    if (!detected) {
        const double t0 = now_ms();
        dets = detect(bgr);
        det_ms = now_ms() - t0;
    }
    out->det_ms += det_ms;
    out->detector_ran = true;
    out->persons = static_cast<int>(dets.size());
    last_census_t = t_s;
    std::vector<PoseBody> bodies;
    for (const PoseDetection &d : dets) bodies.push_back(body_of(d, t_s));

    if (!keeper.has()) {
        // nobody kept: the most confident person is the one to follow
        crowded = false;
        if (tracking && lm_ok) {
            // the ROI's person stays the one (no identity yet to compare with)
            bool kept = accept(false);
            int me = keeper.match(bodies);
            for (size_t i = 0; i < bodies.size(); i++)
                if (static_cast<int>(i) != me) crowded = crowded || keeper.near(bodies[i], t_s);
            return kept;
        }
        if (dets.empty()) {
            tracking = false;
            if (!out->present) return false;
            out->present = false;  // landmarks without a usable next ROI and nobody found
            for (int k = 0; k < kPoseKeypoints; k++) out->kp[k].c = 0.0f;
            return false;
        }
        out->det_score = dets.front().score;
        PoseRoi r = pose_roi_from_alignment(dets.front().kp_x[0], dets.front().kp_y[0], dets.front().kp_x[1],
                                            dets.front().kp_y[1], kRoiScale);
        if (run_lm(r)) {
            bool kept = accept(true);
            int me = keeper.match(bodies);
            for (size_t i = 0; i < bodies.size(); i++)
                if (static_cast<int>(i) != me) crowded = crowded || keeper.near(bodies[i], t_s);
            return kept;
        }
        tracking = false;
        return out->present;
    }

    int m = keeper.match(bodies);
    std::vector<PoseBody> others;
    crowded = false;
    for (size_t i = 0; i < bodies.size(); i++) {
        if (static_cast<int>(i) == m) continue;
        others.push_back(bodies[i]);
        crowded = crowded || keeper.near(bodies[i], t_s);
    }
    if (tracking && lm_ok && keeper.keeps(body, others)) {
        if (m < 0) return accept(false);
        // a second opinion: the landmarks of the tracked person's own detection. A
        // tracked ROI that slid (onto someone the detector does not report) disagrees
        PoseOutput mine = *out;
        PoseRoi mine_next = next;
        PoseBody mine_body = body;
        const PoseDetection &d = dets[static_cast<size_t>(m)];
        PoseRoi r = pose_roi_from_alignment(d.kp_x[0], d.kp_y[0], d.kp_x[1], d.kp_y[1], kRoiScale);
        if (run_lm(r) && std::hypot(body.x_px - mine_body.x_px, body.y_px - mine_body.y_px) >
                             drift_r * mine_body.r_px) {
            out->det_score = d.score;
            if (keeper.plausible(body)) return accept(true);  // the fresh crop is the person
            out->rejected = true;
            out->present = false;
            for (int k = 0; k < kPoseKeypoints; k++) out->kp[k].c = 0.0f;
            tracking = false;
            return false;
        }
        double lm_ms = out->lm_ms;
        *out = mine;
        out->lm_ms = lm_ms;
        next = mine_next;
        body = mine_body;
        return accept(false);
    }
    if (m >= 0) {
        const PoseDetection &d = dets[static_cast<size_t>(m)];
        out->det_score = d.score;
        PoseRoi r = pose_roi_from_alignment(d.kp_x[0], d.kp_y[0], d.kp_x[1], d.kp_y[1], kRoiScale);
        if (run_lm(r) && keeper.keeps(body, others)) return accept(true);
    }
    // not the tracked person, or not found: no pose this frame; the detector looks again next frame
    out->rejected = out->present;
    out->present = false;
    for (int k = 0; k < kPoseKeypoints; k++) out->kp[k].c = 0.0f;
    tracking = false;
    return false;
}

bool PoseTracker::Impl::process_plain(const cv::Mat &bgr, double t_s, PoseOutput *out)
{
    // landmarks of the current ROI; true when the pose is there and the next ROI usable
    auto track = [&]() {
        PoseRoi next;
        double t0 = now_ms();
        landmarks(bgr, roi, out, &next);
        out->lm_ms += now_ms() - t0;
        if (out->present && next.size_px >= kMinRoiPx && std::isfinite(next.cx_px)) {
            roi = cfg.roi_smoothing ? smooth_roi(next, t_s, out->detector_ran) : next;
            return true;
        }
        tracking = false;
        return false;
    };
    if (tracking && track()) return true;
    if (tracking || out->present) return out->present;  // present, but no usable next ROI: detect next frame
    // no track (or lost on this frame): the detector, then the landmarks of its ROI
    double t0 = now_ms();
    std::vector<PoseDetection> dets = detect(bgr);
    out->det_ms += now_ms() - t0;
    out->detector_ran = true;
    if (dets.empty()) return false;
    const PoseDetection &d = dets.front();  // the most confident person
    out->det_score = d.score;
    roi = pose_roi_from_alignment(d.kp_x[0], d.kp_y[0], d.kp_x[1], d.kp_y[1], kRoiScale);
    tracking = true;
    track();
    return out->present;
}

}  // namespace gs
