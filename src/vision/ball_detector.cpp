// ball_detector.cpp - see ball_detector.hpp and docs/ball.md.
#include "ball_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "ball_outline.hpp"
#include "ballistic.hpp"

namespace gs {

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kAlphaFloor = 0.12;  // alpha below this is background noise, shadow or halo
const double kRoundMax = 1.06;     // an outline longer than this over its width is stretched by the smear
const double kMatteMassTol = 0.1;  // a matte whose total is off its outline's area by more is biased by shading

// ---------------------------------------------------------------- config ---

bool key_is(const char *key, size_t len, const char *name)
{
    return std::strlen(name) == len && std::memcmp(key, name, len) == 0;
}

void put_msg(char *msg, size_t cap, const char *text)
{
    if (msg && cap > 0) std::snprintf(msg, cap, "%s", text);
}

// strict number: the whole value, finite
bool parse_num(const char *v, size_t len, double *out)
{
    if (len == 0 || len > 63) return false;
    char buf[64];
    std::memcpy(buf, v, len);
    buf[len] = '\0';
    char *end = nullptr;
    double d = std::strtod(buf, &end);
    if (end != buf + len || !std::isfinite(d)) return false;
    *out = d;
    return true;
}

gs_status num_in(const char *v, size_t len, double lo, double hi, double *out, char *msg,
                 size_t cap)
{
    double d;
    if (!parse_num(v, len, &d)) {
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

}  // namespace

gs_status ball_config_set(void *ctx, const char *key, size_t key_len, const char *value,
                          size_t value_len, char *msg, size_t cap)
{
    BallConfig *c = static_cast<BallConfig *>(ctx);
    double d = 0.0;
    gs_status st;
    if (key_is(key, key_len, "color")) {
        std::string v(value, value_len);
        if (v == "auto") { c->color_auto = true; return GS_OK; }
        if (v == "fixed") { c->color_auto = false; return GS_OK; }
        put_msg(msg, cap, "expected auto or fixed");
        return GS_EINVAL;
    }
    if (key_is(key, key_len, "hue_deg")) {
        if ((st = num_in(value, value_len, 0.0, 360.0, &d, msg, cap)) != GS_OK) return st;
        c->hue_deg = std::fmod(d, 360.0);
        c->color_auto = false;
        return GS_OK;
    }
    if (key_is(key, key_len, "hue_tol_deg"))
        return num_in(value, value_len, 1.0, 90.0, &c->hue_tol_deg, msg, cap);
    if (key_is(key, key_len, "sat_min"))
        return num_in(value, value_len, 0.0, 1.0, &c->sat_min, msg, cap);
    if (key_is(key, key_len, "val_min"))
        return num_in(value, value_len, 0.0, 1.0, &c->val_min, msg, cap);
    if (key_is(key, key_len, "min_diameter_px"))
        return num_in(value, value_len, 2.0, 2000.0, &c->min_diameter_px, msg, cap);
    if (key_is(key, key_len, "max_diameter_px")) {
        if (value_len == 4 && std::memcmp(value, "auto", 4) == 0) { c->max_diameter_px = 0.0; return GS_OK; }
        return num_in(value, value_len, 2.0, 2000.0, &c->max_diameter_px, msg, cap);
    }
    if (key_is(key, key_len, "motion_min"))
        return num_in(value, value_len, 1.0, 255.0, &c->motion_min, msg, cap);
    if (key_is(key, key_len, "max_blur_ratio"))
        return num_in(value, value_len, 1.0, 5.0, &c->max_blur_ratio, msg, cap);
    if (key_is(key, key_len, "psf_sigma_px"))
        return num_in(value, value_len, 0.0, 3.0, &c->psf_sigma_px, msg, cap);
    if (key_is(key, key_len, "max_balls")) {
        if ((st = num_in(value, value_len, 1.0, 16.0, &d, msg, cap)) != GS_OK) return st;
        if (d != std::floor(d)) {
            put_msg(msg, cap, "expected a whole number");
            return GS_EINVAL;
        }
        c->max_balls = static_cast<int>(d);
        return GS_OK;
    }
    if (key_is(key, key_len, "roi")) {
        std::string v(value, value_len);
        if (v == "full") { c->roi_set = false; return GS_OK; }
        double f[4];
        size_t pos = 0;
        for (int i = 0; i < 4; i++) {
            size_t comma = v.find(',', pos);
            if ((i < 3) != (comma != std::string::npos)) {
                put_msg(msg, cap, "expected full or x,y,w,h");
                return GS_EINVAL;
            }
            std::string part = v.substr(pos, i < 3 ? comma - pos : std::string::npos);
            size_t a = part.find_first_not_of(" \t"), b = part.find_last_not_of(" \t");
            part = a == std::string::npos ? std::string() : part.substr(a, b - a + 1);
            if (!parse_num(part.data(), part.size(), &f[i]) || f[i] != std::floor(f[i])) {
                put_msg(msg, cap, "expected full or x,y,w,h in whole pixels");
                return GS_EINVAL;
            }
            pos = comma + 1;
        }
        if (f[0] < 0 || f[1] < 0 || f[2] < 8 || f[3] < 8 || f[0] + f[2] > 16384 || f[1] + f[3] > 16384) {
            put_msg(msg, cap, "x,y >= 0 and w,h >= 8 (at most 16384 wide)");
            return GS_ERANGE;
        }
        c->roi_set = true;
        c->roi_x = (int)f[0]; c->roi_y = (int)f[1]; c->roi_w = (int)f[2]; c->roi_h = (int)f[3];
        return GS_OK;
    }
    put_msg(msg, cap, "unknown key in [ball]");
    return GS_ENOKEY;
}

gs_status ball_config_check(const BallConfig &c, char *msg, size_t cap)
{
    if (!c.color_auto && !(c.hue_deg >= 0.0)) {
        put_msg(msg, cap, "color = fixed needs hue_deg");
        return GS_EINVAL;
    }
    if (c.max_diameter_px > 0.0 && !(c.min_diameter_px < c.max_diameter_px)) {
        put_msg(msg, cap, "min_diameter_px must be below max_diameter_px");
        return GS_ERANGE;
    }
    return GS_OK;
}

// ------------------------------------------------------------- detector ---

namespace {

struct Blob {
    cv::Rect box_s;                 // in the small image
    std::vector<cv::Point> hull_s;  // convex hull, small image
    double cx_s, cy_s;              // centroid, small image
    double d_eq_s;                  // equivalent diameter from the area, small image
    double d_minor_s;               // 4 sqrt(smallest eigenvalue) of the mask, small image
    double elong;                   // sqrt(l1/l2) of the blob's mask
    bool at_edge;                   // touches the frame's border
};

struct Meas {
    bool ok = false;
    double x = kNaN, y = kNaN;      // alpha centroid, full resolution
    double d_perp = kNaN;           // 4 sqrt(lambda_min - psf^2)
    double d_area = kNaN;           // 2 sqrt(sum alpha / pi)
    double ratio = kNaN;            // sqrt(lambda_max / lambda_min)
    double sxx = kNaN, syy = kNaN, sxy = kNaN;  // alpha covariance (px^2)
    double d_kurt = kNaN;           // across the motion from the 2nd and 4th moments (any Gaussian blur)
    double psf_var = kNaN;          // the blur's variance that implies (px^2)
    bool at_edge = false;
    bool shadow = false;            // a darkening of the background that keeps its texture
    bool shadow_color = false;      // darker than the background in its own colour (a shadow, or a grey ball)
    cv::Vec3f color;                // mean colour of the ball's core pixels
    double contrast = 0.0;          // |C - B|
    bool size_ok = true;            // false: a ball of the background's chromaticity whose outline could not be read
    bool outline = false;           // the moments are the outline's sharp disc (no blur, no smear)
};

// one detection of a track
struct Pt {
    double t = 0;
    int64_t frame = 0;
    double x = 0, y = 0;            // full resolution (alpha centroid, or the blob's centroid)
    double d = 0;                   // diameter across the motion (or the blob's), px
    Meas m;
};

struct Track {
    int id = -1;                   // output number (confirmed tracks only)
    bool confirmed = false;
    std::vector<Pt> arc;           // detections since the last break of the parabola
    Pt last;                       // the newest detection (also when it started a new arc)
    std::vector<Pt> recent;        // the newest detections across arcs (the clock's check)
    bool has_last = false;
    double d = 0;                  // running diameter (full res)
    double d_prev = kNaN;          // running diameter before the newest detection
    int hits = 0, misses = 0;
    bool matched = false;
    bool have_color = false;
    cv::Vec3f color;               // ball colour from sharp frames
    Parabola fit;                  // of the arc's newest points (prediction)
    double t_confirmed = kNaN;
};

constexpr size_t kArcKeep = 400;   // detections of an arc kept (1000 fps: 0.4 s)
constexpr size_t kFitLast = 24;    // newest arc points in the prediction fit
constexpr size_t kMaxTracks = 48;  // tentative and confirmed
constexpr size_t kMaxBlobs = 64;
constexpr size_t kRecentKeep = 6;  // detections in the clock's check (one may be contact)

// Rolling shutter: a row y is exposed k (y - H/2) later than the middle row, so a
// ball moving at v appears displaced by v k (y - H/2). k is unknown (readout time,
// either direction); it is chosen per clip as the value that makes the flights
// between bounces most parabolic (grid over k in frame-times per frame height).
constexpr int kRsSteps = 41;         // k_rel = -1 .. +1 in steps of 0.05
constexpr double kRsMax = 1.0;

double rs_k_rel(int i) { return -kRsMax + 2.0 * kRsMax * i / (kRsSteps - 1); }

double median(std::vector<double> v)
{
    if (v.empty()) return kNaN;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Parabola fit_points(const std::vector<Pt> &pts, size_t last_n)
{
    size_t n = std::min(last_n, pts.size());
    std::vector<TrackPoint> tp;
    tp.reserve(n);
    for (size_t i = pts.size() - n; i < pts.size(); i++) tp.push_back({pts[i].t, pts[i].x, pts[i].y, 1.0});
    return fit_parabola(tp);
}

}  // namespace

// cv::dilate by MORPH_ELLIPSE of radius r, the same pixels: the disc's rows are
// runs, so each distinct run is one fast rectangular dilation along x, and the rows
// are their maxima shifted along y (OpenCV's general kernel visits every one of the
// disc's points per pixel). Outside src counts as empty, as cv::dilate's border.
void dilate_ellipse(const cv::Mat &src_in, cv::Mat &dst, int r)
{
    CV_Assert(src_in.type() == CV_8UC1 && r >= 0);
    const cv::Mat src = src_in.isSubmatrix() ? src_in.clone() : src_in;
    const cv::Mat k = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
    cv::Mat out = cv::Mat::zeros(src.size(), CV_8U);
    std::vector<std::pair<std::pair<int, int>, cv::Mat>> runs;  // (first, last column) -> src dilated by it
    for (int i = 0; i < k.rows; i++) {
        const uchar *kr = k.ptr<uchar>(i);
        int a = -1, b = -1;
        for (int j = 0; j < k.cols; j++)
            if (kr[j]) {
                if (a < 0) a = j;
                b = j;
            }
        if (a < 0) continue;
        for (int j = a; j <= b; j++) CV_Assert(kr[j]);  // an ellipse's row is one run
        const cv::Mat *h = nullptr;
        for (const auto &run : runs)
            if (run.first == std::make_pair(a, b)) h = &run.second;
        if (!h) {
            cv::Mat d;
            cv::dilate(src, d, cv::Mat::ones(1, b - a + 1, CV_8U), cv::Point(r - a, 0));
            runs.emplace_back(std::make_pair(a, b), d);
            h = &runs.back().second;
        }
        // out(y) = max(out(y), h(y + i - r))
        const int dy = i - r;
        const int y0 = std::max(0, -dy), y1 = std::min(src.rows, src.rows - dy);
        if (y1 <= y0) continue;
        cv::Mat o = out.rowRange(y0, y1);
        cv::max(o, h->rowRange(y0 + dy, y1 + dy), o);
    }
    dst = out;
}

// max over the channels of |image - round(background)|: the background rounded
// to whole grey levels as convertTo would (the threshold is in whole levels), in
// one pass instead of convert, difference, split and two maxima
void max_channel_diff(const cv::Mat &img, const cv::Mat &bg, cv::Mat &out)
{
    CV_Assert(img.type() == CV_8UC3 && bg.type() == CV_32FC3 && img.size() == bg.size());
    out.create(img.size(), CV_8U);
    for (int y = 0; y < img.rows; y++) {
        const uchar *s = img.ptr<uchar>(y);
        const float *b = bg.ptr<float>(y);
        uchar *o = out.ptr<uchar>(y);
        int x = 0;
#if CV_SIMD128
        // 16 pixels at a time: the 48 values rounded and differenced as they lie,
        // then deinterleaved once as bytes for the maximum
        alignas(16) uchar d48[48];
        for (; x + 16 <= img.cols; x += 16) {
            const float *bp = b + 3 * x;
            for (int k = 0; k < 3; k++) {
                cv::v_int32x4 q0 = cv::v_round(cv::v_load(bp + 16 * k)), q1 = cv::v_round(cv::v_load(bp + 16 * k + 4));
                cv::v_int32x4 q2 = cv::v_round(cv::v_load(bp + 16 * k + 8)), q3 = cv::v_round(cv::v_load(bp + 16 * k + 12));
                cv::v_uint8x16 b8 = cv::v_pack_u(cv::v_pack(q0, q1), cv::v_pack(q2, q3));
                cv::v_store_aligned(d48 + 16 * k, cv::v_absdiff(cv::v_load(s + 3 * x + 16 * k), b8));
            }
            cv::v_uint8x16 d0, d1, d2;
            cv::v_load_deinterleave(d48, d0, d1, d2);
            cv::v_store(o + x, cv::v_max(cv::v_max(d0, d1), d2));
        }
#endif
        for (; x < img.cols; x++) {
            int m = 0;
            for (int c = 0; c < 3; c++)
                m = std::max(m, std::abs((int)s[3 * x + c] - (int)cv::saturate_cast<uchar>(b[3 * x + c])));
            o[x] = (uchar)m;
        }
    }
}

struct BallDetector::Impl {
    BallConfig cfg;
    bool hue_set = false;
    double hue = 0, hue_tol = 16, sat_min = 0.25, val_min = 0.15;
    double scale = 1.0;            // small = full * scale
    double max_d_px = 400.0;       // the diameter range in use (full res)
    cv::Mat bg_small, bg_full;     // CV_32FC3 running backgrounds
    cv::Mat small, hsv, motion, cand;
    std::vector<cv::Rect> keep_s;  // regions (working resolution) the background must not learn this frame
    std::vector<Track> tracks;
    long frame = 0;
    double dt = 1.0 / 30.0;        // typical frame interval
    double last_t = kNaN;
    double prev_t = kNaN;          // the previous frame's time on the repaired clock
    double clock_shift_s = 0.0;    // frames the encoder dropped, as time (added to the stream's)
    bool backlog = false;
    // gravity in the image, learnt from confirmed flights (unit vector, image down at first)
    double gx = 0.0, gy = 1.0;
    int g_n = 0;
    double rs_sse[kRsSteps] = {};  // accumulated quadratic-fit SSE per k over finished flights
    int rs_segments = 0;
    double rs_k = 0.0;             // seconds per row in use (0 = no correction)

    explicit Impl(const BallConfig &c) : cfg(c)
    {
        hue_tol = c.hue_tol_deg;
        if (!c.color_auto && c.hue_deg >= 0.0) {
            hue_set = true;
            hue = c.hue_deg;
            sat_min = c.sat_min;
            val_min = c.val_min;
        }
    }

    void find_blobs(const cv::Mat &mask, std::vector<Blob> &blobs);
    Meas measure(const cv::Mat &bgr, const Blob &b, const Track *tr);
    bool is_ball(const Track &tr) const;
    bool shadow_of_another(const Track &tr) const;
    void rs_segment(const std::vector<Pt> &arc, int rows);
    void rs_correct(double vx, double vy, double rows, double *x, double *y) const;
    bool make_obs(const Track &tr, const Pt &p, double vx, double vy, int rows, BallObs &o) const;
    int dropped_frames(const std::vector<Blob> &blobs, double t_s) const;
    void process(const cv::Mat &bgr, double t_s, std::vector<BallObs> &out);
};

void BallDetector::Impl::find_blobs(const cv::Mat &mask, std::vector<Blob> &blobs)
{
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    double dmin = cfg.min_diameter_px * scale, dmax = max_d_px * scale;
    for (const auto &c : contours) {
        cv::Rect box = cv::boundingRect(c);
        if (box.width < 0.5 * dmin && box.height < 0.5 * dmin) continue;
        if (box.width > 4.5 * dmax || box.height > 4.5 * dmax) continue;
        cv::Moments mo = cv::moments(c, false);
        double area = mo.m00;
        if (c.size() < 5 || area < 1.0) {
            // a speck of a few pixels: moments of its filled box
            if (!(dmin <= 3.0)) continue;
            area = std::max(1.0, (double)box.area());
            Blob b;
            b.box_s = box;
            cv::convexHull(c, b.hull_s);
            b.cx_s = box.x + 0.5 * (box.width - 1);
            b.cy_s = box.y + 0.5 * (box.height - 1);
            b.d_eq_s = 2.0 * std::sqrt(area / CV_PI);
            b.d_minor_s = std::min(box.width, box.height);
            b.elong = (double)std::max(box.width, box.height) / std::max(1, std::min(box.width, box.height));
            b.at_edge = box.x <= 0 || box.y <= 0 || box.br().x >= mask.cols || box.br().y >= mask.rows;
            if (b.elong <= 4.0) blobs.push_back(std::move(b));
            continue;
        }
        double deq = 2.0 * std::sqrt(area / CV_PI);
        double mu20 = mo.mu20 / area, mu02 = mo.mu02 / area, mu11 = mo.mu11 / area;
        double tr = mu20 + mu02, det = mu20 * mu02 - mu11 * mu11;
        double disc = std::sqrt(std::max(0.0, tr * tr / 4.0 - det));
        double l1 = tr / 2.0 + disc, l2 = std::max(1e-6, tr / 2.0 - disc);
        double elong = std::sqrt(l1 / l2);
        double dminor = 4.0 * std::sqrt(l2);
        if (dminor < 0.6 * dmin - 1.0 || dminor > 1.3 * dmax) continue;
        if (elong > 4.0) continue;
        // solidity: a ball (blurred or not) is convex
        std::vector<cv::Point> hull;
        cv::convexHull(c, hull);
        double harea = cv::contourArea(hull);
        if (harea > 0 && area / (harea + 0.5 * cv::arcLength(hull, true)) < 0.6) continue;
        Blob b;
        b.box_s = box;
        b.hull_s = hull;
        b.cx_s = mo.m10 / mo.m00;
        b.cy_s = mo.m01 / mo.m00;
        b.d_eq_s = deq;
        b.d_minor_s = dminor;
        b.elong = elong;
        b.at_edge = box.x <= 0 || box.y <= 0 || box.br().x >= mask.cols || box.br().y >= mask.rows;
        blobs.push_back(std::move(b));
    }
    // many blobs: a scene change or a crowd; the roundest, ball-sized ones first
    if (blobs.size() > kMaxBlobs) {
        std::sort(blobs.begin(), blobs.end(), [](const Blob &a, const Blob &b) { return a.elong < b.elong; });
        blobs.resize(kMaxBlobs);
    }
}

// Soft matte at full resolution around the blob: alpha = (I-B).(C-B)/|C-B|^2.
Meas BallDetector::Impl::measure(const cv::Mat &bgr, const Blob &b, const Track *tr)
{
    Meas r;
    double inv = 1.0 / scale;
    double dfull = b.d_eq_s * inv;
    int margin = (int)std::ceil(0.35 * dfull + 3.0 + 2.0 * inv);
    cv::Rect box((int)std::floor(b.box_s.x * inv) - margin, (int)std::floor(b.box_s.y * inv) - margin,
                 (int)std::ceil(b.box_s.width * inv) + 2 * margin,
                 (int)std::ceil(b.box_s.height * inv) + 2 * margin);
    cv::Rect frame_r(0, 0, bgr.cols, bgr.rows);
    cv::Rect roi = box & frame_r;
    if (roi.area() <= 0) return r;
    // support: the blob's hull scaled to full resolution, dilated
    cv::Mat sup = cv::Mat::zeros(roi.size(), CV_8U);
    std::vector<cv::Point> hull;
    for (const auto &p : b.hull_s)
        hull.emplace_back((int)std::lround((p.x + 0.5) * inv - 0.5) - roi.x,
                          (int)std::lround((p.y + 0.5) * inv - 0.5) - roi.y);
    if (hull.size() >= 3)
        cv::fillConvexPoly(sup, hull, cv::Scalar(255));
    else
        cv::rectangle(sup, cv::Rect(cv::Point((int)(b.box_s.x * inv) - roi.x, (int)(b.box_s.y * inv) - roi.y),
                                    cv::Size((int)std::ceil(b.box_s.width * inv), (int)std::ceil(b.box_s.height * inv))),
                      cv::Scalar(255), cv::FILLED);
    int k = (int)std::ceil(0.12 * dfull + 1.5 + inv);
    dilate_ellipse(sup, sup, k);
    cv::Mat I = bgr(roi), B = bg_full(roi);
    // colour of the ball: pass 1 from the most different pixels, pass 2 from
    // the pixels that pass 1 calls ball
    std::vector<std::pair<float, cv::Vec3f>> px;
    for (int y = 0; y < roi.height; y++) {
        const uchar *s = sup.ptr<uchar>(y);
        const cv::Vec3b *ir = I.ptr<cv::Vec3b>(y);
        const cv::Vec3f *br = B.ptr<cv::Vec3f>(y);
        for (int x = 0; x < roi.width; x++) {
            if (!s[x]) continue;
            cv::Vec3f d = cv::Vec3f(ir[x][0], ir[x][1], ir[x][2]) - br[x];
            px.emplace_back((float)d.dot(d), cv::Vec3f(ir[x][0], ir[x][1], ir[x][2]));
        }
    }
    if (px.size() < 4) return r;
    size_t top = std::max<size_t>(2, px.size() / 4);
    std::nth_element(px.begin(), px.begin() + (long)top, px.end(),
                     [](const auto &a, const auto &c) { return a.first > c.first; });
    cv::Vec3f C(0, 0, 0);
    for (size_t i = 0; i < top; i++) C += px[i].second;
    C *= 1.0f / (float)top;
    cv::Mat alpha(roi.size(), CV_32F, cv::Scalar(0));
    // A shaded ball is its colour times a shading factor s (the side away from the
    // light is darker): I = u C + (1 - alpha) B with u = alpha s unknown too, so
    // alpha comes from a 2x2 least-squares unmixing against C and B. Where C and B
    // are nearly parallel (the same chromaticity: a grey ball, a white ball on a
    // grey wall) that is ill-posed and the plain projection alpha = (I-B).(C-B)/|C-B|^2
    // (s = 1) is used.
    // A shadow on the background is the background darkened (u = 0, beta < 1): in
    // the unmixing it would pass for coverage 1 - beta, so coverage also needs the
    // ball's own colour: alpha <= u / (0.35 u_ref), u_ref the ball's typical u
    // (its shading may darken it to 35 % of that before it counts as less ball).
    cv::Mat uw(roi.size(), CV_32F, cv::Scalar(-1)), bw(roi.size(), CV_32F, cv::Scalar(1));
    // The ball's shadow on the wall darkens the background beside it by a factor
    // sigma: an edge pixel covered c by the ball then has beta = (1 - c) sigma, and
    // 1 - beta overstates c there. sigma is read per direction from the pixels
    // just outside the ball that carry none of its colour, and c = 1 - beta / sigma.
    auto background_gain = [&](float u_ref) {
        constexpr int kSect = 16;
        cv::Mat core = alpha > 0.5f, dist;
        cv::Moments mo = cv::moments(core, true);
        if (mo.m00 < 4.0) return;
        const double cx = mo.m10 / mo.m00, cy = mo.m01 / mo.m00;
        const double d_core = 2.0 * std::sqrt(mo.m00 / CV_PI);
        cv::distanceTransform(~core, dist, cv::DIST_L2, 3);
        // beyond the blur of the edge, and near enough that the shadow is the same
        const float lo = 3.0f, hi = 3.0f + (float)std::max(3.0, 0.1 * d_core);
        std::vector<float> sect[kSect];
        auto sector_of = [&](int x, int y) { return std::atan2(y - cy, x - cx) / (2.0 * CV_PI) * kSect + kSect; };
        for (int y = 0; y < roi.height; y++) {
            const float *ur = uw.ptr<float>(y), *br = bw.ptr<float>(y), *dr = dist.ptr<float>(y);
            for (int x = 0; x < roi.width; x++) {
                if (!(ur[x] > -0.99f || ur[x] < -1.01f) || dr[x] < lo || dr[x] > hi) continue;
                if (std::fabs(ur[x]) > 0.1f * u_ref) continue;  // some ball (blur, smear): not the bare background
                sect[(int)sector_of(x, y) % kSect].push_back(br[x]);
            }
        }
        float sigma[kSect];
        bool any = false;
        for (int i = 0; i < kSect; i++) {
            sigma[i] = 1.0f;
            if (sect[i].size() < 5) continue;
            std::vector<float> &v = sect[i];
            const size_t n = v.size();
            std::nth_element(v.begin(), v.begin() + (long)(n / 2), v.end());
            const float med = v[n / 2];
            for (float &dv : v) dv = std::fabs(dv - med);
            std::nth_element(v.begin(), v.begin() + (long)(n / 2), v.end());
            // the median's standard error from the MAD: the wall's texture and the
            // sensor's noise alone must not pass for a shadow
            const float se = 1.2533f * 1.4826f * v[n / 2] / std::sqrt((float)n);
            if (1.0f - med > 3.0f * se) sigma[i] = std::max(0.5f, med);
            any = any || sigma[i] < 1.0f;
        }
        if (!any) return;
        for (int y = 0; y < roi.height; y++) {
            const float *ur = uw.ptr<float>(y), *br = bw.ptr<float>(y);
            float *ar = alpha.ptr<float>(y);
            for (int x = 0; x < roi.width; x++) {
                if (!(ur[x] > -0.99f || ur[x] < -1.01f)) continue;
                double t = sector_of(x, y) - 0.5;  // between the two nearest sectors' centres
                int i0 = (int)std::floor(t);
                float f = (float)(t - i0), s = (1.0f - f) * sigma[i0 % kSect] + f * sigma[(i0 + 1) % kSect];
                ar[x] = std::min(1.5f, std::max(-0.5f, 1.0f - br[x] / s));
            }
        }
    };
    int n_plain = 0, n_unmixed = 0;
    auto compute_alpha = [&](const cv::Vec3f &col) {
        const double cc = col.dot(col);
        std::vector<float> core_u;
        n_plain = n_unmixed = 0;
        for (int y = 0; y < roi.height; y++) {
            const uchar *s = sup.ptr<uchar>(y);
            const cv::Vec3b *ir = I.ptr<cv::Vec3b>(y);
            const cv::Vec3f *br = B.ptr<cv::Vec3f>(y);
            float *ar = alpha.ptr<float>(y);
            float *ur = uw.ptr<float>(y);
            for (int x = 0; x < roi.width; x++) {
                ur[x] = -1.f;
                if (!s[x]) { ar[x] = 0.f; continue; }
                cv::Vec3f v = col - br[x];
                float vv = v.dot(v);
                if (vv < 1.0f) { ar[x] = 0.f; continue; }
                cv::Vec3f iv(ir[x][0], ir[x][1], ir[x][2]);
                double bb = br[x].dot(br[x]), cb = col.dot(br[x]);
                double det = cc * bb - cb * cb;
                float a;
                if (det > 0.03 * cc * bb) {  // C and B at least ~10 deg apart (noise grows as 1 / sin)
                    double ci = col.dot(iv), bi = br[x].dot(iv);
                    double beta = (cc * bi - cb * ci) / det;    // weight of the background
                    double u = (bb * ci - cb * bi) / det;       // weight of the ball's colour
                    a = (float)(1.0 - beta);
                    ur[x] = (float)u;
                    bw.at<float>(y, x) = (float)beta;
                    if (a > 0.8f) core_u.push_back((float)u);
                    n_unmixed++;
                } else {
                    a = (iv - br[x]).dot(v) / vv;
                    n_plain++;
                }
                ar[x] = std::min(1.5f, std::max(-0.5f, a));
            }
        }
        if (core_u.size() < 4) return;
        std::nth_element(core_u.begin(), core_u.begin() + (long)(core_u.size() / 2), core_u.end());
        const float u_ref = core_u[core_u.size() / 2];
        if (!(u_ref > 0.2f)) return;
        background_gain(u_ref);
        const float inv_u = 1.0f / (0.35f * u_ref);
        for (int y = 0; y < roi.height; y++) {
            float *ar = alpha.ptr<float>(y);
            const float *ur = uw.ptr<float>(y);
            for (int x = 0; x < roi.width; x++)
                if (ur[x] > -0.99f || ur[x] < -1.01f) ar[x] = std::min(ar[x], std::max(-0.5f, ur[x] * inv_u));
        }
    };
    compute_alpha(C);
    // pass 2: mean colour of the confident core
    cv::Vec3f C2(0, 0, 0);
    double n2 = 0;
    for (int y = 0; y < roi.height; y++) {
        const float *ar = alpha.ptr<float>(y);
        const cv::Vec3b *ir = I.ptr<cv::Vec3b>(y);
        for (int x = 0; x < roi.width; x++)
            if (ar[x] > 0.6f) {
                C2 += cv::Vec3f(ir[x][0], ir[x][1], ir[x][2]);
                n2 += 1;
            }
    }
    if (n2 >= 4) C = C2 * (float)(1.0 / n2);
    r.color = C;
    if (tr && tr->have_color) C = tr->color;
    compute_alpha(C);
    // the ball is one compact region: its confident core (the largest component of
    // alpha > 0.5) widened by the edge's blur; what lies beyond (a shadow beside
    // it, a hand, the ghost of where it lay) is no part of it
    {
        cv::Mat core = alpha > 0.5f, lab, stats, cents;
        int nl = cv::connectedComponentsWithStats(core, lab, stats, cents, 8, CV_32S);
        int best = 0, best_area = 0;
        for (int l = 1; l < nl; l++)
            if (stats.at<int>(l, cv::CC_STAT_AREA) > best_area) { best_area = stats.at<int>(l, cv::CC_STAT_AREA); best = l; }
        if (best > 0) {
            cv::Mat keep = lab == best;
            int e = (int)std::ceil(0.06 * std::sqrt(best_area * 4.0 / CV_PI) + 2.0 * cfg.psf_sigma_px + 2.0);
            dilate_ellipse(keep, keep, e);
            alpha.setTo(0.0f, ~keep);
        }
    }
    // moments; and whether the core is a shadow: the background darkened by one
    // factor in every channel, its texture still there
    double m0 = 0, mx = 0, my = 0, mxx = 0, myy = 0, mxy = 0;
    double sh_n = 0, sh_r = 0, sh_rr = 0, sh_chroma = 0, si = 0, sb = 0, sii = 0, sbb = 0, sib = 0;
    for (int y = 0; y < roi.height; y++) {
        const float *ar = alpha.ptr<float>(y);
        const cv::Vec3b *ir = I.ptr<cv::Vec3b>(y);
        const cv::Vec3f *br = B.ptr<cv::Vec3f>(y);
        for (int x = 0; x < roi.width; x++) {
            /* the ball covers a pixel between none and all of it: shading above 1 and
             * shadows or noise below a small floor would widen the measured disc */
            double a = std::min(1.0, (double)ar[x]);
            if (!(a >= kAlphaFloor)) continue;
            m0 += a;
            mx += a * x;
            my += a * y;
            mxx += a * x * x;
            myy += a * y * y;
            mxy += a * x * y;
            if (a > 0.6) {
                double rb = (ir[x][0] + 1.0) / (br[x][0] + 1.0), rg = (ir[x][1] + 1.0) / (br[x][1] + 1.0),
                       rr = (ir[x][2] + 1.0) / (br[x][2] + 1.0);
                double rm = (rb + rg + rr) / 3.0;
                sh_r += rm;
                sh_rr += rm * rm;
                sh_chroma += (std::fabs(rb - rm) + std::fabs(rg - rm) + std::fabs(rr - rm)) / (3.0 * rm);
                double iv = ir[x][0] + ir[x][1] + ir[x][2], bv = br[x][0] + br[x][1] + br[x][2];
                si += iv; sb += bv; sii += iv * iv; sbb += bv * bv; sib += iv * bv;
                sh_n += 1;
            }
        }
    }
    if (!(m0 > 1.5)) return r;
    if (const char *dd = std::getenv("GS_BALL_DEBUG_DIR")) {
        char path[512];
        std::snprintf(path, sizeof path, "%s/a%04ld_%d_%d.png", dd, frame, roi.x, roi.y);
        cv::Mat a8;
        alpha.convertTo(a8, CV_8U, 200.0);
        cv::imwrite(path, a8);
    }
    double cx = mx / m0, cy = my / m0;
    double sxx = mxx / m0 - cx * cx, syy = myy / m0 - cy * cy, sxy = mxy / m0 - cx * cy;
    double trc = sxx + syy, det = sxx * syy - sxy * sxy;
    double disc = std::sqrt(std::max(0.0, trc * trc / 4.0 - det));
    double l1 = trc / 2.0 + disc, l2 = trc / 2.0 - disc;
    if (!(l2 > 0.0)) return r;
    // the fourth moment across the motion (the minor axis): a disc of radius R blurred
    // by a Gaussian of any width has m2 = R^2/4 + s^2 and m4 = 3 m2^2 - R^4/16 there
    {
        double nx = -sxy, ny = sxx - l2;  // eigenvector of l2
        if (std::hypot(nx, ny) < 1e-9) { nx = syy - l2; ny = -sxy; }
        if (std::hypot(nx, ny) < 1e-9) { nx = 1.0; ny = 0.0; }
        double nn = std::hypot(nx, ny);
        nx /= nn;
        ny /= nn;
        double m4 = 0.0;
        for (int y = 0; y < roi.height; y++) {
            const float *ar = alpha.ptr<float>(y);
            for (int x = 0; x < roi.width; x++) {
                double a = std::min(1.0, (double)ar[x]);
                if (!(a >= kAlphaFloor)) continue;
                double d = (x - cx) * nx + (y - cy) * ny;
                m4 += a * d * d * d * d;
            }
        }
        m4 /= m0;
        double A2 = 3.0 * l2 * l2 - m4;
        r.d_kurt = A2 > 0.0 ? 4.0 * std::pow(A2, 0.25) : kNaN;
        r.psf_var = A2 > 0.0 ? l2 - std::sqrt(A2) : kNaN;
    }
    r.ok = true;
    r.x = roi.x + cx;
    r.y = roi.y + cy;
    r.sxx = sxx;
    r.syy = syy;
    r.sxy = sxy;
    r.d_area = 2.0 * std::sqrt(m0 / CV_PI);
    // a disc's variance D^2/16 plus the camera's blur variance: take the blur off
    // (it widens small balls by several per cent; floor: never below half the width)
    double psf2 = cfg.psf_sigma_px * cfg.psf_sigma_px;
    r.d_perp = 4.0 * std::sqrt(std::max(0.25 * l2, l2 - psf2));
    r.ratio = std::sqrt(l1 / l2);
    r.at_edge = (box & frame_r) != box;
    // A ball of the background's chromaticity was read by the plain projection,
    // which follows its shading (the lit side near the background's level reads
    // as partial coverage): where the matte does not add up to the area inside the
    // ball's outline, the outline gives the moments, or none where it cannot be read.
    if (n_plain > n_unmixed) {
        const double r_guess = 0.5 * std::max(4.0 * std::sqrt(l2), b.d_minor_s * inv);
        const double ramp0_px = 2.0 + 2.5 * cfg.psf_sigma_px;
        BallOutline ol = ball_outline(I, B, cx, cy, r_guess, ramp0_px, cfg.psf_sigma_px);
        // A smear longer than the edge's ramp window reads the step's level part way
        // up its ramp and stretches the outline along the motion by about the smear:
        // read it again with the window reaching over the smear.
        double smear_px = ol.ok ? 4.0 * (std::sqrt(ellipse_major(ol)) - std::sqrt(ellipse_minor(ol)))
                                : std::sqrt(12.0 * std::max(0.0, l1 - l2));
        if (smear_px > 1.0 + 0.05 * 2.0 * r_guess) {
            BallOutline o2 = ball_outline(I, B, ol.ok ? ol.cx : cx, ol.ok ? ol.cy : cy, r_guess,
                                          ramp0_px + 1.5 * smear_px, cfg.psf_sigma_px);
            if (o2.ok || !ol.ok) ol = o2;
        }
        const double d_ol = ol.ok ? 4.0 * std::sqrt(ellipse_minor(ol)) : 0.0;
        // blur and smear keep the matte's total: a matte that adds up to the outline's
        // disc is not biased by the shading, and its moments stand
        const double mass = ol.ok ? m0 / (4.0 * CV_PI * std::sqrt(std::max(1e-9, ol.sxx * ol.syy - ol.sxy * ol.sxy)))
                                  : kNaN;
        // edges off an ellipse are not the ball's outline alone
        const bool outline_good = ol.ok && ol.rms_px <= std::max(0.75, 0.03 * d_ol);
        if (outline_good) {
            // the outline's centre does not move with the shading
            r.x = roi.x + ol.cx;
            r.y = roi.y + ol.cy;
        }
        if (std::fabs(mass - 1.0) <= kMatteMassTol) {
            // the matte's own moments
        } else if (outline_good && smear_px <= 0.25 * d_ol && ellipse_major(ol) <= kRoundMax * kRoundMax * ellipse_minor(ol)) {
            // a smear l moves the half level across the motion inward (to sqrt(R^2 - l^2/16)):
            // below 1 % up to l = D / 4; along it the shading inside the smear's ramp moves
            // it either way, so the outline stands only where it is round (a sphere's image)
            r.sxx = ol.sxx;
            r.syy = ol.syy;
            r.sxy = ol.sxy;
            r.outline = true;
            r.d_perp = d_ol;
            r.d_area = 4.0 * std::pow(std::max(0.0, ol.sxx * ol.syy - ol.sxy * ol.sxy), 0.25);
            r.d_kurt = kNaN;
            r.psf_var = kNaN;
        } else {
            r.size_ok = false;
        }
    }
    if (sh_n >= 6) {
        double rm = sh_r / sh_n, chroma = sh_chroma / sh_n;
        double vi = sii / sh_n - (si / sh_n) * (si / sh_n), vb = sbb / sh_n - (sb / sh_n) * (sb / sh_n);
        double cib = sib / sh_n - (si / sh_n) * (sb / sh_n);
        double corr = vi > 0 && vb > 0 ? cib / std::sqrt(vi * vb) : 0.0;
        // a texture of at least ~3 grey levels (x3 channels) that the pixels follow
        r.shadow_color = rm > 0.25 && rm < 0.9 && chroma < 0.07;
        r.shadow = r.shadow_color && vb > 81.0 && corr > 0.6;
    }
    cv::Vec3f bgm(0, 0, 0);
    {
        int cxi = std::min(roi.width - 1, std::max(0, (int)cx));
        int cyi = std::min(roi.height - 1, std::max(0, (int)cy));
        bgm = B.at<cv::Vec3f>(cyi, cxi);
    }
    cv::Vec3f dd = C - bgm;
    r.contrast = std::sqrt(dd.dot(dd));
    return r;
}

// The ballistic test: the arc's newest detections are explained by a parabola
// whose acceleration points along gravity (image down within 40 degrees until
// flights have shown it, then within 15 degrees of it), implies a size of
// 1 cm to 1 m under g, is clearly above its noise, and the object is compact,
// of a steady size, moved at least two diameters and is no shadow.
bool BallDetector::Impl::is_ball(const Track &tr) const
{
    size_t n = tr.arc.size();
    if (n < 5) return false;
    size_t first = n - std::min(n, kFitLast);
    std::vector<double> ds;
    std::vector<TrackPoint> tp;
    for (size_t i = first; i < n; i++) {
        ds.push_back(tr.arc[i].d);
        tp.push_back({tr.arc[i].t, tr.arc[i].x, tr.arc[i].y, 1.0});
    }
    double D = median(ds);
    // the candidates a free fall explains (one wrong link, a frame merged with a hand, is left out)
    const double g = 9.81;
    FallPrior prior;
    prior.a_min = g * D / 1.0;
    prior.a_max = g * D / 0.01;
    prior.gx = gx;
    prior.gy = gy;
    prior.cos_min = g_n >= 1 ? std::cos(15.0 * CV_PI / 180.0) : std::cos(40.0 * CV_PI / 180.0);
    std::vector<bool> in;
    Parabola f = ransac_parabola(tp, std::max(1.0, 0.12 * D), 200, in, 1, prior);
    size_t n_in = (size_t)std::count(in.begin(), in.end(), true);
    if (!f.ok || n_in < 5 || 5 * n_in < 4 * tp.size() || !in.back()) return false;
    ds.clear();
    int shadows = 0, edges = 0;
    double path = 0.0;
    const Pt *prev = nullptr;
    for (size_t i = first; i < n; i++) {
        if (!in[i - first]) continue;
        ds.push_back(tr.arc[i].d);
        shadows += tr.arc[i].m.shadow ? 1 : 0;
        edges += tr.arc[i].m.at_edge ? 1 : 0;
        if (prev) path += std::hypot(tr.arc[i].x - prev->x, tr.arc[i].y - prev->y);
        prev = &tr.arc[i];
    }
    std::sort(ds.begin(), ds.end());
    double a = std::hypot(f.ax, f.ay);
    double cosang = a > 0 ? (f.ax * gx + f.ay * gy) / a : -1.0;
    double a_se = std::hypot(f.ax_se, f.ay_se);
    bool a_ok = a > 4.0 * a_se;
    bool fit_ok = f.rms_px <= std::max(0.6, 0.1 * D);
    bool steady = ds.front() > 0.6 * ds.back();
    bool moved = path >= 2.0 * D;
    bool no_shadow = shadows * 2 < (int)n_in && edges * 2 < (int)n_in;
    if (std::getenv("GS_BALL_DEBUG"))
        std::fprintf(stderr, "ball? t=%.3f n=%zu D=%.1f a=%.0f (%.0f,%.0f) se=%.0f cos=%.2f size=%.3f rms=%.2f steady=%d moved=%.1f shadows=%d -> %d\n",
                     tr.arc.back().t, f.n, D, a, f.ax, f.ay, a_se, cosang, a > 0 ? g * D / a : 0.0, f.rms_px,
                     steady, path / std::max(1e-9, D), shadows, a_ok && fit_ok && steady && moved && no_shadow);
    return a_ok && fit_ok && steady && moved && no_shadow;
}

// A shadow cast by a flying ball flies a parabola too. A track darker than the
// background in the background's own colour is taken for a shadow while another
// track, not so coloured, moves in step with it (its arc began within two frames
// and it accelerates the same way); alone it may be a grey or black ball.
bool BallDetector::Impl::shadow_of_another(const Track &tr) const
{
    size_t n = tr.arc.size(), sc = 0;
    for (const Pt &p : tr.arc) sc += p.m.shadow_color ? 1 : 0;
    if (2 * sc <= n || !tr.fit.ok) return false;
    for (const Track &o : tracks) {
        if (&o == &tr || o.arc.size() < 3 || !o.fit.ok || o.last.t != tr.last.t) continue;
        size_t oc = 0;
        for (const Pt &p : o.arc) oc += p.m.shadow_color ? 1 : 0;
        if (2 * oc > o.arc.size()) continue;
        bool same_start = std::fabs(o.arc.front().t - tr.arc.front().t) <= 2.5 * dt || o.arc.size() >= n;
        double a1 = std::hypot(tr.fit.ax, tr.fit.ay), a2 = std::hypot(o.fit.ax, o.fit.ay);
        double va = tr.fit.vy_at(tr.last.t), vb = o.fit.vy_at(o.last.t);
        bool same_motion = a2 > 0.5 * a1 && a2 < 2.0 * a1 && va * vb > 0;
        if (same_start && same_motion) return true;
    }
    return false;
}

void BallDetector::Impl::rs_segment(const std::vector<Pt> &seg0, int rows)
{
    // drop two samples at each end (contact) and require a long, tall flight
    if (seg0.size() < 10) return;
    std::vector<Pt> seg(seg0.begin() + 2, seg0.end() - 2);
    double ymin = 1e30, ymax = -1e30;
    for (const auto &h : seg) { ymin = std::min(ymin, h.y); ymax = std::max(ymax, h.y); }
    if (ymax - ymin < 0.1 * rows) return;
    size_t n = seg.size();
    std::vector<double> v(n);
    for (size_t i = 0; i < n; i++) {
        size_t a = i > 0 ? i - 1 : i, b = i + 1 < n ? i + 1 : i;
        v[i] = (seg[b].y - seg[a].y) / (seg[b].t - seg[a].t);
    }
    double sse[kRsSteps];
    std::vector<TrackPoint> tp(n);
    for (int k = 0; k < kRsSteps; k++) {
        double ks = rs_k_rel(k) * dt / rows;
        for (size_t i = 0; i < n; i++) tp[i] = {seg[i].t, seg[i].x, seg[i].y - v[i] * ks * (seg[i].y - 0.5 * rows), 1.0};
        // the vertical residual only (x is not sheared by a vertical velocity)
        std::vector<TrackPoint> ty(tp);
        for (auto &q : ty) q.x_px = 0.0;
        Parabola f = fit_parabola(ty);
        if (!f.ok) return;
        sse[k] = 2.0 * f.rms_px * f.rms_px;
    }
    for (int k = 0; k < kRsSteps; k++) rs_sse[k] += sse[k];
    rs_segments++;
    int best = 0;
    for (int k = 1; k < kRsSteps; k++)
        if (rs_sse[k] < rs_sse[best]) best = k;
    int zero = (kRsSteps - 1) / 2;
    // only a clear improvement counts (a global shutter stays uncorrected): the rms at
    // least 40 % lower, at a k inside the grid (a k at its edge fits something else,
    // e.g. a hand still holding the ball at the segment's start)
    bool inside = best > 0 && best < kRsSteps - 1;
    // and only a residual above the centres' own noise (a quarter pixel) has a shutter to explain
    bool visible = rs_sse[zero] / rs_segments > 0.25 * 0.25;
    rs_k = inside && visible && rs_sse[best] < 0.36 * rs_sse[zero] ? rs_k_rel(best) * dt / rows : 0.0;
    if (std::getenv("GS_BALL_DEBUG"))
        std::fprintf(stderr, "rolling shutter: %d flights, k_rel %.2f, rms %.2f -> %.2f px\n", rs_segments,
                     rs_k_rel(best), std::sqrt(rs_sse[zero] / rs_segments),
                     std::sqrt(rs_sse[best] / rs_segments));
}

void BallDetector::Impl::rs_correct(double vx, double vy, double rows, double *x, double *y) const
{
    if (rs_k == 0.0 || !std::isfinite(vx) || !std::isfinite(vy)) return;
    double dtr = rs_k * (*y - 0.5 * rows);
    *x -= vx * dtr;
    *y -= vy * dtr;
}

// Frame times missing just before this frame (0 to 3): a ball seen in each of the
// last frames, whose parabola explains them well, finds this frame's blob only where
// its parabola is k + 1 frame times on. Every ball that shows it must agree; one
// whose next position fits (or none fits: a bounce, a catch) shows nothing.
int BallDetector::Impl::dropped_frames(const std::vector<Blob> &blobs, double t_s) const
{
    if (!std::isfinite(prev_t) || !(dt > 0.0)) return 0;
    constexpr int kMaxDropped = 3;
    int vote = -1;
    std::vector<TrackPoint> tp;
    for (const Track &tr : tracks) {
        if (!tr.confirmed || !tr.has_last || tr.last.t != prev_t || tr.recent.size() < kRecentKeep) continue;
        // seen in every frame of late (a track that skipped frames proves nothing)
        bool consecutive = true;
        for (size_t i = 1; i < tr.recent.size(); i++)
            if (tr.recent[i].frame != tr.recent[i - 1].frame + 1) consecutive = false;
        if (!consecutive) continue;
        double D = std::max(tr.d, 2.0);
        // the parabola of the newest detections, one left out (a contact, a merge)
        // when that explains the others best
        Parabola fit;
        for (size_t skip = 0; skip <= tr.recent.size(); skip++) {
            tp.clear();
            for (size_t i = 0; i < tr.recent.size(); i++)
                if (i != skip) tp.push_back({tr.recent[i].t, tr.recent[i].x, tr.recent[i].y, 1.0});
            Parabola f = fit_parabola(tp);
            if (f.ok && (!fit.ok || f.rms_px < fit.rms_px)) fit = f;
        }
        double tol = std::max(1.5, 0.05 * D);
        if (!fit.ok || !(fit.rms_px < tol)) continue;
        double e[kMaxDropped + 1];
        for (int k = 0; k <= kMaxDropped; k++) {
            double t = t_s + k * dt, px = fit.x(t), py = fit.y(t);
            e[k] = std::numeric_limits<double>::infinity();
            for (const Blob &b : blobs) {
                double sr = b.d_minor_s / scale / D;
                if (sr > 0.5 && sr < 2.0) e[k] = std::min(e[k], std::hypot(b.cx_s / scale - px, b.cy_s / scale - py));
            }
        }
        if (std::getenv("GS_BALL_DEBUG"))
            std::fprintf(stderr, "gap? t=%.3f D=%.1f rms=%.2f e=%.1f %.1f %.1f %.1f\n", t_s, D, fit.rms_px, e[0], e[1],
                         e[2], e[3]);
        int best = 0;
        for (int k = 1; k <= kMaxDropped; k++)
            if (e[k] < e[best]) best = k;
        if (!(e[best] < 0.15 * D + 3.0 * tol)) continue;
        // the other frame counts miss by a quarter diameter or more, and four times as far
        bool sure = true;
        for (int k = 0; k <= kMaxDropped; k++)
            if (k != best && !(e[k] > std::max(0.25 * D, 4.0 * std::max(e[best], 1.0)))) sure = false;
        if (!sure) continue;
        if (vote >= 0 && vote != best) return 0;
        vote = best;
    }
    return std::max(vote, 0);
}

// One detection as reported: centre corrected for the rolling shutter with the
// velocity then; the diameter only where the matte is trustworthy.
bool BallDetector::Impl::make_obs(const Track &tr, const Pt &p, double vx, double vy, int rows, BallObs &o) const
{
    const Meas &ms = p.m;
    if (!ms.ok) return false;
    o.track = tr.id;
    o.frame = p.frame;
    o.t_s = p.t;
    o.x_px = ms.x;
    o.y_px = ms.y;
    rs_correct(vx, vy, rows, &o.x_px, &o.y_px);
    double conf = 1.0;
    bool good = true, moments = true;
    if (ms.at_edge) { conf *= 0.3; good = false; moments = false; }
    if (!ms.size_ok) { good = false; moments = false; }
    if (ms.ratio > cfg.max_blur_ratio) good = false;
    conf *= std::max(0.2, 1.0 - 0.3 * std::max(0.0, ms.ratio - 1.2));
    // the area and the width agree for an unoccluded ball (blur keeps both)
    double cons = ms.d_area / ms.d_perp;
    if (cons < 0.85 || cons > 1.25) { good = false; moments = false; conf *= 0.5; }
    if (ms.contrast < 30.0) { conf *= 0.5; }
    // a sudden change of size: partly hidden or merged with something (its centre is off too)
    if (std::isfinite(tr.d_prev) && std::fabs(ms.d_perp / tr.d_prev - 1.0) > 0.08 && ms.ratio < cfg.max_blur_ratio) {
        good = false;
        conf *= 0.2;
    }
    if (ms.d_perp < cfg.min_diameter_px || ms.d_perp > max_d_px) { good = false; moments = false; conf *= 0.5; }
    o.diameter_px = good ? ms.d_perp : kNaN;
    o.diameter_kurt_px = good ? ms.d_kurt : kNaN;
    o.psf_var_px2 = good ? ms.psf_var : kNaN;
    o.confidence = std::min(1.0, std::max(0.05, conf));
    if (moments) {
        o.moments_blur_free = ms.outline;
        o.sxx = ms.sxx;
        o.syy = ms.syy;
        o.sxy = ms.sxy;
        // the rolling shutter shears the ball's image as it moves its centre:
        // x' = x + vx k dy, y' = y + (1 + vy k) dy; undo it on the moments
        if (rs_k != 0.0 && std::isfinite(vx) && std::isfinite(vy)) {
            double a = vx * rs_k, b = 1.0 + vy * rs_k;
            if (std::fabs(b) > 0.2) {
                // M = [[1, a], [0, b]], Sigma = M^-1 Sigma' M^-T
                double i00 = 1.0, i01 = -a / b, i11 = 1.0 / b;
                double sxx = o.sxx, syy = o.syy, sxy = o.sxy;
                o.sxx = i00 * i00 * sxx + 2 * i00 * i01 * sxy + i01 * i01 * syy;
                o.sxy = i00 * i11 * sxy + i01 * i11 * syy;
                o.syy = i11 * i11 * syy;
            }
        }
    } else {
        o.sxx = o.syy = o.sxy = kNaN;
    }
    return true;
}

void BallDetector::Impl::process(const cv::Mat &bgr, double t_s, std::vector<BallObs> &out)
{
    out.clear();
    if (bgr.empty() || bgr.type() != CV_8UC3) return;
    if (std::isfinite(last_t) && t_s > last_t) {
        double d = t_s - last_t;
        dt = frame == 1 ? d : dt + 0.1 * (std::min(d, 3.0 * dt) - dt);
    }
    last_t = t_s;
    t_s += clock_shift_s;
    const int64_t fidx = frame;
    frame++;
    scale = std::min(1.0, 960.0 / std::max(bgr.cols, bgr.rows));
    max_d_px = cfg.max_diameter_px > 0.0 ? cfg.max_diameter_px : std::min(bgr.cols, bgr.rows) / 3.0;
    if (scale < 1.0)
        cv::resize(bgr, small, cv::Size(), scale, scale, cv::INTER_AREA);
    else
        small = bgr;
    if (bg_full.empty() || bg_full.size() != bgr.size()) {
        bgr.convertTo(bg_full, CV_32FC3);
        small.convertTo(bg_small, CV_32FC3);
        tracks.clear();
        return;
    }
    // motion: difference to the background, any channel (brighter, darker, any hue)
    cv::Mat mx;
    max_channel_diff(small, bg_small, mx);
    // the threshold: motion_min, or well above the frame's typical difference when
    // compression noise, flicker or a fade lift it (4 robust sigmas of it)
    double thr = cfg.motion_min;
    {
        int hist[256] = {0};
        int step = std::max(1, (int)(mx.total() / 20000));
        int cnt = 0;
        const uchar *pm = mx.ptr<uchar>(0);
        if (mx.isContinuous())
            for (size_t i = 0; i < mx.total(); i += (size_t)step) { hist[pm[i]]++; cnt++; }
        int acc = 0, med = 0;
        for (; med < 255 && acc + hist[med] < cnt / 2; med++) acc += hist[med];
        thr = std::max(thr, 4.0 * 1.4826 * med);
    }
    motion = mx > thr;
    double moving_share = cv::countNonZero(motion) / (double)motion.total();
    cv::Rect roi_s(0, 0, small.cols, small.rows);
    if (cfg.roi_set) {
        cv::Rect r((int)(cfg.roi_x * scale), (int)(cfg.roi_y * scale), (int)(cfg.roi_w * scale),
                   (int)(cfg.roi_h * scale));
        cv::Mat keep = cv::Mat::zeros(motion.size(), CV_8U);
        keep(r & roi_s).setTo(255);
        motion &= keep;
    }
    std::vector<Blob> blobs;
    if (hue_set) {
        constexpr int kReach = 2;  // the dilation's radius
        cv::Mat md;
        double h = hue / 2.0, tol = hue_tol / 2.0;
        int smin = (int)std::lround(sat_min * 255.0), vmin = (int)std::lround(val_min * 255.0);
        double lo = h - tol, hi = h + tol;
        // the colour only matters near motion: per band of rows, the motion dilated
        // and HSV over the columns within the kernel's reach of it (the moving share
        // of a frame is small)
        cand.create(small.size(), CV_8U);
        cand.setTo(0);
        constexpr int kBand = 16;
        for (int y0 = 0; y0 < small.rows; y0 += kBand) {
            const int y1 = std::min(small.rows, y0 + kBand);
            const int ya = std::max(0, y0 - kReach), yb = std::min(small.rows, y1 + kReach);
            cv::Rect mr = cv::boundingRect(motion(cv::Range(ya, yb), cv::Range::all()));
            if (mr.area() <= 0) continue;
            const int xa = std::max(0, mr.x - kReach), xb = std::min(small.cols, mr.x + mr.width + kReach);
            // the dilation's input: those columns and rows with the kernel's reach around them
            const int xi = std::max(0, xa - kReach), xj = std::min(small.cols, xb + kReach);
            cv::Mat md_ext;
            dilate_ellipse(motion(cv::Range(ya, yb), cv::Range(xi, xj)), md_ext, kReach);
            md = md_ext(cv::Range(y0 - ya, y1 - ya), cv::Range(xa - xi, xb - xi));
            cv::Rect r(xa, y0, xb - xa, y1 - y0);
            cv::cvtColor(small(r), hsv, cv::COLOR_BGR2HSV);
            cv::Mat cm;
            if (lo < 0) {
                cv::Mat a, b;
                cv::inRange(hsv, cv::Scalar(0, smin, vmin), cv::Scalar(hi, 255, 255), a);
                cv::inRange(hsv, cv::Scalar(lo + 180.0, smin, vmin), cv::Scalar(180, 255, 255), b);
                cm = a | b;
            } else if (hi > 180) {
                cv::Mat a, b;
                cv::inRange(hsv, cv::Scalar(lo, smin, vmin), cv::Scalar(180, 255, 255), a);
                cv::inRange(hsv, cv::Scalar(0, smin, vmin), cv::Scalar(hi - 180.0, 255, 255), b);
                cm = a | b;
            } else {
                cv::inRange(hsv, cv::Scalar(lo, smin, vmin), cv::Scalar(hi, 255, 255), cm);
            }
            cv::Mat dst = cand(r);
            cv::bitwise_and(cm, md, dst);
        }
    } else {
        cand = motion;
    }
    // close small gaps (a ball's highlight or a thin seam can split it); specks go
    // by size in find_blobs
    cv::morphologyEx(cand, cand, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)));
    find_blobs(cand, blobs);
    if (const char *dd = std::getenv("GS_BALL_DEBUG_DIR")) {
        char path[512];
        std::snprintf(path, sizeof path, "%s/m%04ld.png", dd, frame);
        cv::Mat vis = small.clone();
        vis.setTo(cv::Scalar(0, 0, 255), motion);
        vis.setTo(cv::Scalar(255, 0, 0), cand);
        for (const Blob &b : blobs) cv::rectangle(vis, b.box_s, cv::Scalar(0, 255, 0), 1);
        cv::imwrite(path, vis);
    }

    // a phone's encoder may drop frames and still stamp a constant rate: the balls'
    // own parabolas then say how many frame times really passed
    if (int k = dropped_frames(blobs, t_s); k > 0) {
        if (std::getenv("GS_BALL_DEBUG")) std::fprintf(stderr, "clock: %d frame(s) dropped before %.3f s\n", k, t_s);
        clock_shift_s += k * dt;
        t_s += k * dt;
    }
    prev_t = t_s;

    // association: each track's prediction (its arc's parabola, else its chord),
    // confirmed balls first, then the longest tracks; greedy by normalised distance
    const double diag = std::hypot(bgr.cols, bgr.rows);
    for (auto &tr : tracks) tr.matched = false;
    std::vector<int> blob_track(blobs.size(), -1);
    struct Pair { int rank; double cost; size_t b, t; };
    std::vector<Pair> pairs;
    for (size_t ti = 0; ti < tracks.size(); ti++) {
        const Track &tr = tracks[ti];
        if (!tr.has_last) continue;
        double h = t_s - tr.last.t;
        double px, py, gate;
        size_t na = tr.arc.size();
        double D = std::max(tr.d, 2.0);
        if (na >= 3 && tr.fit.ok) {
            px = tr.fit.x(t_s);
            py = tr.fit.y(t_s);
            double v = std::hypot(tr.fit.vx_at(tr.last.t), tr.fit.vy_at(tr.last.t));
            // a bounce or a catch turns the velocity: the gate admits a turn of a frame's travel
            gate = 2.0 + 0.6 * D + 3.0 * tr.fit.rms_px + (tr.confirmed ? 1.2 : 0.3) * v * h;
        } else if (tr.has_last && na >= 2) {
            const Pt &a = tr.arc[na - 2], &b = tr.arc[na - 1];
            double hv = b.t - a.t;
            double vx = hv > 0 ? (b.x - a.x) / hv : 0.0, vy = hv > 0 ? (b.y - a.y) / hv : 0.0;
            // gravity of up to a 1 cm ball's over the step
            double amax = 9.81 * D / 0.01;
            px = b.x + vx * h;
            py = b.y + vy * h;
            gate = 2.0 + 1.0 * D + 0.5 * std::min(amax * h * h, 0.1 * diag) + 0.5 * std::hypot(vx, vy) * h;
        } else {
            px = tr.last.x;
            py = tr.last.y;
            gate = std::max(5.0 * D, 0.08 * diag);
        }
        gate *= 1.0 + 0.5 * tr.misses;
        int rank = tr.confirmed ? 0 : (na >= 3 ? 1 : 2);
        for (size_t bi = 0; bi < blobs.size(); bi++) {
            double bx = blobs[bi].cx_s / scale, by = blobs[bi].cy_s / scale;
            double d = std::hypot(bx - px, by - py);
            double sr = blobs[bi].d_minor_s / scale / std::max(1e-6, D);
            if (d < gate && sr > 0.5 && sr < 2.0) pairs.push_back({rank, d / gate, bi, ti});
        }
    }
    std::sort(pairs.begin(), pairs.end(), [](const Pair &a, const Pair &b) {
        return a.rank != b.rank ? a.rank < b.rank : a.cost < b.cost;
    });
    for (const auto &p : pairs) {
        if (blob_track[p.b] >= 0 || tracks[p.t].matched) continue;
        blob_track[p.b] = (int)p.t;
        tracks[p.t].matched = true;
    }
    if (const char *dbg = std::getenv("GS_BALL_DEBUG"); dbg && dbg[0] == '2') {
        for (size_t bi = 0; bi < blobs.size(); bi++) {
            int ti = blob_track[bi];
            std::fprintf(stderr, "f%ld blob %zu (%.0f,%.0f) d=%.1f el=%.2f -> track %d (n=%zu%s)\n", frame, bi,
                         blobs[bi].cx_s / scale, blobs[bi].cy_s / scale, blobs[bi].d_minor_s / scale, blobs[bi].elong, ti,
                         ti >= 0 ? tracks[(size_t)ti].arc.size() : 0, ti >= 0 && tracks[(size_t)ti].confirmed ? " ball" : "");
        }
    }
    // new tentative tracks for the rest
    for (size_t bi = 0; bi < blobs.size(); bi++) {
        if (blob_track[bi] >= 0) continue;
        if (tracks.size() >= kMaxTracks) {
            // make room: the tentative track unseen longest, or the shortest
            auto worst = tracks.end();
            for (auto it = tracks.begin(); it != tracks.end(); ++it) {
                if (it->confirmed || it->matched) continue;
                if (worst == tracks.end() || it->misses > worst->misses ||
                    (it->misses == worst->misses && it->arc.size() < worst->arc.size()))
                    worst = it;
            }
            if (worst == tracks.end()) break;
            for (auto &bt : blob_track)
                if (bt > (int)(worst - tracks.begin())) bt--;
            tracks.erase(worst);
        }
        Track tr;
        tr.matched = true;
        tracks.push_back(tr);
        blob_track[bi] = (int)tracks.size() - 1;
    }

    // measure and update
    keep_s.clear();
    std::vector<size_t> newly;  // tracks confirmed this frame
    for (size_t bi = 0; bi < blobs.size(); bi++) {
        const Blob &b = blobs[bi];
        int ti = blob_track[bi];
        if (ti < 0) continue;
        Track &tr = tracks[(size_t)ti];
        Meas ms = measure(bgr, b, tr.have_color ? &tr : nullptr);
        Pt p;
        p.t = t_s;
        p.frame = fidx;
        p.x = ms.ok ? ms.x : b.cx_s / scale;
        p.y = ms.ok ? ms.y : b.cy_s / scale;
        p.d = ms.ok && ms.ratio < cfg.max_blur_ratio ? ms.d_perp : b.d_minor_s / scale;
        p.m = ms;
        bool fresh = tr.hits == 0;
        tr.d_prev = tr.hits >= 3 ? tr.d : kNaN;
        tr.d = fresh ? p.d : tr.d + 0.3 * (p.d - tr.d);
        tr.hits++;
        tr.misses = 0;
        if (ms.ok && ms.ratio < 1.25 && !ms.at_edge) {
            if (!tr.have_color) tr.color = ms.color;
            else tr.color += 0.2f * (ms.color - tr.color);
            tr.have_color = true;
        }
        // the arc breaks where the parabola no longer explains the newest detection
        // (a bounce, a catch, a hit); the new arc starts at it
        bool brk = false;
        if (tr.arc.size() >= 4 && tr.fit.ok) {
            double e = std::hypot(tr.fit.x(t_s) - p.x, tr.fit.y(t_s) - p.y);
            // a short arc's extrapolation is uncertain: its limit is wider
            double k = tr.arc.size() < 8 ? 1.8 : 1.0;
            brk = e > k * std::max({1.5, 3.0 * tr.fit.rms_px, 0.15 * tr.d});
        }
        if (std::isfinite(tr.last.t) && tr.has_last && t_s - tr.last.t > 0.2) brk = true;
        if (brk) {
            if (tr.confirmed) rs_segment(tr.arc, bgr.rows);
            tr.arc.clear();
        }
        tr.arc.push_back(p);
        if (tr.arc.size() > kArcKeep) tr.arc.erase(tr.arc.begin());
        tr.last = p;
        tr.has_last = true;
        tr.recent.push_back(p);
        if (tr.recent.size() > kRecentKeep) tr.recent.erase(tr.recent.begin());
        tr.fit = tr.arc.size() >= 3 ? fit_points(tr.arc, kFitLast) : Parabola();
        if (tr.confirmed || tr.arc.size() >= 3) {
            cv::Rect r = b.box_s;
            int m = (int)std::ceil(0.5 * b.d_eq_s) + 2;
            keep_s.push_back(cv::Rect(r.x - m, r.y - m, r.width + 2 * m, r.height + 2 * m) & roi_s);
        }
        if (!tr.confirmed && is_ball(tr) && !shadow_of_another(tr)) {
            // a ball unseen for two frames or more is probably this one, found again
            // elsewhere (thrown from where it was not seen resting): it ends and
            // its number goes to the new one
            for (auto &o : tracks)
                if (&o != &tr && o.confirmed && o.misses >= 2) o.misses = 1 << 20;
            int n_conf = 0;
            for (const auto &o : tracks) n_conf += o.confirmed && o.misses < (1 << 20) ? 1 : 0;
            if (n_conf < cfg.max_balls) {
                std::vector<bool> used(64, false);
                for (const auto &o : tracks)
                    if (o.confirmed && o.misses < (1 << 20) && o.id >= 0 && o.id < 64) used[(size_t)o.id] = true;
                int id = 0;
                while (used[(size_t)id]) id++;
                tr.id = id;
                tr.confirmed = true;
                tr.t_confirmed = t_s;
                newly.push_back((size_t)ti);
                // gravity's direction in the image, from the flights seen
                double a = std::hypot(tr.fit.ax, tr.fit.ay);
                if (a > 0.0) {
                    double ux = tr.fit.ax / a, uy = tr.fit.ay / a;
                    g_n++;
                    gx += (ux - gx) / g_n;
                    gy += (uy - gy) / g_n;
                    double gn = std::hypot(gx, gy);
                    gx /= gn;
                    gy /= gn;
                }
                continue;  // its whole arc is reported below
            }
        }
        if (!tr.confirmed) continue;
        BallObs o;
        double vx = tr.fit.ok ? tr.fit.vx_at(t_s) : kNaN, vy = tr.fit.ok ? tr.fit.vy_at(t_s) : kNaN;
        if (tr.arc.size() < 3 && tr.arc.size() >= 1) {
            // just after a break: the chord from the detection before (contact in between)
            vx = vy = kNaN;
        }
        if (make_obs(tr, p, vx, vy, bgr.rows, o)) out.push_back(o);
    }
    // newly confirmed balls: their arc so far (the backlog) or just this frame
    for (size_t ti : newly) {
        Track &tr = tracks[ti];
        size_t from = backlog ? 0 : tr.arc.size() - 1;
        for (size_t i = from; i < tr.arc.size(); i++) {
            const Pt &p = tr.arc[i];
            BallObs o;
            // the size test's sudden-change check against the running size then: not known; skip it
            double dp = tr.d_prev;
            tr.d_prev = kNaN;
            if (make_obs(tr, p, tr.fit.vx_at(p.t), tr.fit.vy_at(p.t), bgr.rows, o)) out.push_back(o);
            tr.d_prev = dp;
        }
    }
    std::stable_sort(out.begin(), out.end(), [](const BallObs &a, const BallObs &b) {
        return a.track != b.track ? a.track < b.track : a.t_s < b.t_s;
    });
    // tracks lost for a while end: balls after 0.25 s, candidates after two frames
    int max_miss = std::max(3, (int)std::lround(0.25 / std::max(1e-4, dt)));
    for (auto &tr : tracks) {
        if (!tr.matched) tr.misses++;
        if (tr.confirmed && tr.misses == max_miss + 1) rs_segment(tr.arc, bgr.rows);  // its last flight
    }
    tracks.erase(std::remove_if(tracks.begin(), tracks.end(),
                                [&](const Track &tr) { return tr.misses > (tr.confirmed ? max_miss : 2); }),
                 tracks.end());

    // backgrounds follow slow changes (a time constant of 0.8 s), not the balls:
    // an unmasked update (SIMD, 8-bit source) with the balls' regions put back is
    // ~5x cheaper than a masked one
    double rate = 1.0 - std::exp(-std::max(1e-4, dt) / 0.8);
    // most of the frame changed (a fade, the light, an exposure step): catch up fast
    if (moving_share > 0.25) rate = std::max(rate, 0.3);
    // the first frames: a running mean (the first frame alone may hold anything)
    if (frame < 16) rate = std::max(rate, 1.0 / (double)frame);

    cv::Rect roi_f(0, 0, bgr.cols, bgr.rows);
    std::vector<cv::Rect> keep_f;
    std::vector<cv::Mat> saved_s, saved_f;
    for (const cv::Rect &r : keep_s) {
        cv::Rect rf((int)std::floor(r.x / scale) - 1, (int)std::floor(r.y / scale) - 1,
                    (int)std::ceil(r.width / scale) + 3, (int)std::ceil(r.height / scale) + 3);
        keep_f.push_back(rf & roi_f);
        saved_s.push_back(bg_small(r).clone());
        saved_f.push_back(bg_full(keep_f.back()).clone());
    }
    cv::accumulateWeighted(small, bg_small, rate);
    // the full-resolution background serves only the mattes at the balls: each band
    // of rows learns at 20 Hz or more with the rate of the frames it skips, not at
    // every frame of a fast camera (its memory traffic is the detector's largest)
    int every = frame < 16 ? 1 : std::max(1, (int)std::floor(1.0 / (20.0 * std::max(1e-4, dt))));
    if (every == 1) {
        cv::accumulateWeighted(bgr, bg_full, rate);
    } else {
        double rate_k = 1.0 - std::pow(1.0 - rate, every);
        constexpr int kBandRows = 8;
        for (int y0 = kBandRows * (int)(frame % every); y0 < bgr.rows; y0 += kBandRows * every) {
            cv::Range rows(y0, std::min(bgr.rows, y0 + kBandRows));
            cv::Mat dst = bg_full.rowRange(rows);
            cv::accumulateWeighted(bgr.rowRange(rows), dst, rate_k);
        }
    }
    for (size_t i = keep_s.size(); i-- > 0;) {
        saved_s[i].copyTo(bg_small(keep_s[i]));
        saved_f[i].copyTo(bg_full(keep_f[i]));
    }
}

BallDetector::BallDetector(const BallConfig &cfg) : p_(new Impl(cfg)) {}
BallDetector::~BallDetector() = default;

void BallDetector::process(const cv::Mat &bgr, double t_s, std::vector<BallObs> &out)
{
    p_->process(bgr, t_s, out);
}

void BallDetector::set_backlog(bool on) { p_->backlog = on; }

double BallDetector::rolling_shutter_s_per_row() const { return p_->rs_k; }
double BallDetector::clock_shift_s() const { return p_->clock_shift_s; }

}  // namespace gs
