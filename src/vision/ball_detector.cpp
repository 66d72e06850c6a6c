// ball_detector.cpp - see ball_detector.hpp and docs/ball.md.
#include "ball_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace gs {

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kAlphaFloor = 0.12;  // alpha below this is background noise, shadow or halo

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
    if (key_is(key, key_len, "max_diameter_px"))
        return num_in(value, value_len, 2.0, 2000.0, &c->max_diameter_px, msg, cap);
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
    if (!(c.min_diameter_px < c.max_diameter_px)) {
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
    double elong;                   // sqrt(l1/l2) of the blob's mask
    double hue_deg, sat, val;       // mean colour (hue: saturation-weighted circular mean)
    bool at_edge;                   // touches the frame's border
};

struct Meas {
    bool ok = false;
    double x = kNaN, y = kNaN;      // alpha centroid, full resolution
    double d_perp = kNaN;           // 4 sqrt(lambda_min)
    double d_area = kNaN;           // 2 sqrt(sum alpha / pi)
    double ratio = kNaN;            // sqrt(lambda_max / lambda_min)
    bool at_edge = false;
    cv::Vec3f color;                // mean colour of the ball's core pixels
    double contrast = 0.0;          // |C - B|
};

struct Hist {
    double t, x, y, d;
};

struct Track {
    int id = -1;
    double x = 0, y = 0, vx = 0, vy = 0, t = 0;
    double d = 0;                  // running diameter estimate (full res)
    int hits = 0, misses = 0;
    bool have_color = false;
    cv::Vec3f color;               // ball colour from sharp frames
    std::vector<Hist> hist;        // recent centres (auto colour learning)
    std::vector<Blob> blobs;       // recent blobs (auto colour learning)
    std::vector<Hist> seg;         // raw centres since the last bounce (rolling shutter)
    bool matched = false;
    bool dead = false;             // dropped when the colour was learned from another track
};

// Rolling shutter: a row y is exposed k (y - H/2) later than the middle row, so a
// ball moving at v appears displaced by v k (y - H/2). k is unknown (readout time,
// either direction); it is chosen per clip as the value that makes the flights
// between bounces most parabolic (grid over k in frame-times per frame height).
constexpr int kRsSteps = 41;         // k_rel = -1 .. +1 in steps of 0.05
constexpr double kRsMax = 1.0;

double rs_k_rel(int i) { return -kRsMax + 2.0 * kRsMax * i / (kRsSteps - 1); }

// quadratic least squares y = c0 + c1 t + c2 t^2 ; returns rms residual
bool fit_quad(const std::vector<double> &t, const std::vector<double> &y, double c[3], double *rms)
{
    size_t n = t.size();
    if (n < 4) return false;
    double t0 = 0;
    for (double v : t) t0 += v;
    t0 /= (double)n;
    cv::Mat A((int)n, 3, CV_64F), b((int)n, 1, CV_64F), x;
    for (size_t i = 0; i < n; i++) {
        double u = t[i] - t0;
        A.at<double>((int)i, 0) = 1.0;
        A.at<double>((int)i, 1) = u;
        A.at<double>((int)i, 2) = u * u;
        b.at<double>((int)i, 0) = y[i];
    }
    if (!cv::solve(A, b, x, cv::DECOMP_SVD)) return false;
    double ss = 0;
    for (size_t i = 0; i < n; i++) {
        double u = t[i] - t0;
        double r = y[i] - (x.at<double>(0) + x.at<double>(1) * u + x.at<double>(2) * u * u);
        ss += r * r;
    }
    c[0] = x.at<double>(0);
    c[1] = x.at<double>(1);
    c[2] = x.at<double>(2);
    *rms = std::sqrt(ss / (double)(n > 3 ? n - 3 : 1));
    return true;
}

}  // namespace

struct BallDetector::Impl {
    BallConfig cfg;
    bool color_known = false;
    double hue = 0, hue_tol = 16, sat_min = 0.25, val_min = 0.15;
    double scale = 1.0;            // small = full * scale
    cv::Mat bg_small, bg_full;     // CV_32FC3 running backgrounds
    cv::Mat small, hsv, motion, cand;
    cv::Mat bg_sat;                // the background's HSV saturation (working resolution)
    long bg_sat_frame = -100;
    std::vector<cv::Rect> keep_s;  // regions (working resolution) the background must not learn this frame
    std::vector<Track> tracks;
    long frame = 0;
    double dt = 1.0 / 30.0;        // typical frame interval
    double last_t = kNaN;
    double rs_sse[kRsSteps] = {};  // accumulated quadratic-fit SSE per k over finished flights
    int rs_segments = 0;
    double rs_k = 0.0;             // seconds per row in use (0 = no correction)
    double rs_ay[kRsSteps] = {};   // last fitted vertical acceleration per k (px/s^2)
    double rs_ay_best = 0.0;

    void rs_segment(const std::vector<Hist> &seg, int rows);
    void rs_correct(const Track &tr, double rows, double *x, double *y) const;

    explicit Impl(const BallConfig &c) : cfg(c)
    {
        hue_tol = c.hue_tol_deg;
        if (!c.color_auto && c.hue_deg >= 0.0) {
            color_known = true;
            hue = c.hue_deg;
            sat_min = c.sat_min;
            val_min = c.val_min;
        }
    }

    void find_blobs(const cv::Mat &mask, std::vector<Blob> &blobs, bool need_sat);
    Meas measure(const cv::Mat &bgr, const Blob &b, const Track *tr);
    void learn_color(Track &tr);
    bool ballistic(const Track &tr) const;
    void process(const cv::Mat &bgr, double t_s, std::vector<BallObs> &out);
};

void BallDetector::Impl::find_blobs(const cv::Mat &mask, std::vector<Blob> &blobs, bool need_sat)
{
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    double dmin = cfg.min_diameter_px * scale, dmax = cfg.max_diameter_px * scale;
    for (const auto &c : contours) {
        cv::Rect box = cv::boundingRect(c);
        if (box.width < 0.5 * dmin && box.height < 0.5 * dmin) continue;
        if (box.width > 4.5 * dmax || box.height > 4.5 * dmax) continue;
        cv::Mat m = cv::Mat::zeros(box.size(), CV_8U);
        std::vector<std::vector<cv::Point>> one{c};
        cv::drawContours(m, one, 0, cv::Scalar(255), cv::FILLED, cv::LINE_8, cv::noArray(), 0,
                         -box.tl());
        cv::Moments mo = cv::moments(m, true);
        if (mo.m00 < 4.0) continue;
        double area = mo.m00;
        double deq = 2.0 * std::sqrt(area / CV_PI);
        double mu20 = mo.mu20 / area, mu02 = mo.mu02 / area, mu11 = mo.mu11 / area;
        double tr = mu20 + mu02, det = mu20 * mu02 - mu11 * mu11;
        double disc = std::sqrt(std::max(0.0, tr * tr / 4.0 - det));
        double l1 = tr / 2.0 + disc, l2 = std::max(1e-6, tr / 2.0 - disc);
        double elong = std::sqrt(l1 / l2);
        double dminor = 4.0 * std::sqrt(l2);
        if (dminor < 0.6 * dmin || dminor > 1.3 * dmax) continue;
        if (elong > 4.0) continue;
        // solidity: a ball (blurred or not) is convex
        std::vector<cv::Point> hull;
        cv::convexHull(c, hull);
        double harea = cv::contourArea(hull);
        if (harea > 0 && area / (harea + 0.5 * cv::arcLength(hull, true)) < 0.72) continue;
        Blob b;
        b.box_s = box;
        b.hull_s = hull;
        b.cx_s = box.x + mo.m10 / mo.m00;
        b.cy_s = box.y + mo.m01 / mo.m00;
        b.d_eq_s = deq;
        b.elong = elong;
        b.at_edge = box.x <= 0 || box.y <= 0 || box.br().x >= mask.cols || box.br().y >= mask.rows;
        // colour statistics of the blob
        cv::Mat h = hsv(box);
        double sx = 0, sy = 0, ss = 0, sv = 0, n = 0;
        for (int y = 0; y < box.height; y++) {
            const uchar *mr = m.ptr<uchar>(y);
            const cv::Vec3b *hr = h.ptr<cv::Vec3b>(y);
            for (int x = 0; x < box.width; x++) {
                if (!mr[x]) continue;
                double s = hr[x][1] / 255.0, a = hr[x][0] * 2.0 * CV_PI / 180.0;
                sx += s * std::cos(a);
                sy += s * std::sin(a);
                ss += s;
                sv += hr[x][2] / 255.0;
                n += 1;
            }
        }
        b.hue_deg = std::fmod(std::atan2(sy, sx) * 180.0 / CV_PI + 360.0, 360.0);
        b.sat = ss / n;
        b.val = sv / n;
        if (need_sat && b.sat < 0.18) continue;
        blobs.push_back(std::move(b));
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
    cv::fillConvexPoly(sup, hull, cv::Scalar(255));
    int k = (int)std::ceil(0.12 * dfull + 1.5 + inv);
    cv::dilate(sup, sup, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * k + 1, 2 * k + 1)));
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
    if (px.size() < 8) return r;
    size_t top = std::max<size_t>(4, px.size() / 4);
    std::nth_element(px.begin(), px.begin() + (long)top, px.end(),
                     [](const auto &a, const auto &c) { return a.first > c.first; });
    cv::Vec3f C(0, 0, 0);
    for (size_t i = 0; i < top; i++) C += px[i].second;
    C *= 1.0f / (float)top;
    cv::Mat alpha(roi.size(), CV_32F, cv::Scalar(0));
    // A shaded ball is its colour times a shading factor s (the side away from the
    // light is darker): I = u C + (1 - alpha) B with u = alpha s unknown too, so
    // alpha comes from a 2x2 least-squares unmixing against C and B. Where C and B
    // are nearly parallel (the same chromaticity) that is ill-posed and the plain
    // projection alpha = (I-B).(C-B)/|C-B|^2 (s = 1) is used.
    auto compute_alpha = [&](const cv::Vec3f &col) {
        const double cc = col.dot(col);
        for (int y = 0; y < roi.height; y++) {
            const uchar *s = sup.ptr<uchar>(y);
            const cv::Vec3b *ir = I.ptr<cv::Vec3b>(y);
            const cv::Vec3f *br = B.ptr<cv::Vec3f>(y);
            float *ar = alpha.ptr<float>(y);
            for (int x = 0; x < roi.width; x++) {
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
                    a = (float)(1.0 - beta);
                } else {
                    a = (iv - br[x]).dot(v) / vv;
                }
                ar[x] = std::min(1.5f, std::max(-0.5f, a));
            }
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
    // moments
    double m0 = 0, mx = 0, my = 0, mxx = 0, myy = 0, mxy = 0;
    for (int y = 0; y < roi.height; y++) {
        const float *ar = alpha.ptr<float>(y);
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
        }
    }
    if (!(m0 > 4.0)) return r;
    double cx = mx / m0, cy = my / m0;
    double sxx = mxx / m0 - cx * cx, syy = myy / m0 - cy * cy, sxy = mxy / m0 - cx * cy;
    double trc = sxx + syy, det = sxx * syy - sxy * sxy;
    double disc = std::sqrt(std::max(0.0, trc * trc / 4.0 - det));
    double l1 = trc / 2.0 + disc, l2 = trc / 2.0 - disc;
    if (!(l2 > 0.0)) return r;
    r.ok = true;
    r.x = roi.x + cx;
    r.y = roi.y + cy;
    r.d_perp = 4.0 * std::sqrt(l2);
    r.d_area = 2.0 * std::sqrt(m0 / CV_PI);
    // a disc's variance D^2/16 plus the camera's blur variance: take the blur off
    // (it widens small balls by several per cent; floor: never below half the width)
    double psf2 = cfg.psf_sigma_px * cfg.psf_sigma_px;
    r.d_perp = 4.0 * std::sqrt(std::max(0.25 * l2, l2 - psf2));
    r.ratio = std::sqrt(l1 / l2);
    r.at_edge = (box & frame_r) != box;
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

bool BallDetector::Impl::ballistic(const Track &tr) const
{
    size_t n = tr.hist.size();
    if (n < 6) return false;
    // the last 0.1 s (at least 6 frames): at 120 fps six frames are too short to see a drop move
    size_t use = 6;
    while (use < n && use < tr.blobs.size() && tr.hist.back().t - tr.hist[n - use - 1].t <= 0.1 + 1e-6) use++;
    std::vector<double> t, x, y;
    std::vector<double> ds;
    for (size_t i = n - use; i < n; i++) {
        t.push_back(tr.hist[i].t);
        x.push_back(tr.hist[i].x);
        y.push_back(tr.hist[i].y);
        ds.push_back(tr.hist[i].d);
    }
    std::sort(ds.begin(), ds.end());
    double D = ds[ds.size() / 2];
    double cy[3], cx[3], ry, rx;
    if (!fit_quad(t, y, cy, &ry) || !fit_quad(t, x, cx, &rx)) return false;
    double ay = 2.0 * cy[2], ax = 2.0 * cx[2];
    double span = std::hypot(x.back() - x.front(), y.back() - y.front());
    // g / a_px = size in metres / D: sizes 2 cm .. 50 cm (with slack)
    bool a_ok = ay > 10.0 * D && ay < 1000.0 * D && std::fabs(ax) < 0.7 * ay;
    bool fit_ok = ry < std::max(1.5, 0.12 * D) && rx < std::max(1.5, 0.12 * D);
    if (std::getenv("GS_BALL_DEBUG"))
        std::fprintf(stderr, "ballistic? t=%.3f D=%.1f ay=%.1f ax=%.1f ry=%.2f rx=%.2f span=%.1f hue=%.0f sat=%.2f\n",
                     t.back(), D, ay, ax, ry, rx, span, tr.blobs.back().hue_deg, tr.blobs.back().sat);
    if (!(a_ok && fit_ok && span > 3.0 * D && ds.front() > 0.67 * ds.back())) return false;
    // one colour: the blobs' hues agree and are saturated; none touches the frame's edge
    double sx = 0, sy = 0;
    size_t nb = tr.blobs.size();
    if (nb < use) return false;
    for (size_t i = nb - use; i < nb; i++) {
        const Blob &b = tr.blobs[i];
        if (b.sat < 0.25 || b.at_edge) return false;
        sx += std::cos(b.hue_deg * CV_PI / 180.0);
        sy += std::sin(b.hue_deg * CV_PI / 180.0);
    }
    return std::hypot(sx, sy) / (double)use > 0.95;  // circular spread below ~18 degrees
}

void BallDetector::Impl::learn_color(Track &tr)
{
    double sx = 0, sy = 0;
    std::vector<double> s, v;
    for (size_t i = tr.blobs.size() - 6; i < tr.blobs.size(); i++) {
        const Blob &b = tr.blobs[i];
        double a = b.hue_deg * CV_PI / 180.0;
        sx += std::cos(a);
        sy += std::sin(a);
        s.push_back(b.sat);
        v.push_back(b.val);
    }
    std::sort(s.begin(), s.end());
    std::sort(v.begin(), v.end());
    hue = std::fmod(std::atan2(sy, sx) * 180.0 / CV_PI + 360.0, 360.0);
    sat_min = std::max(0.12, 0.45 * s[s.size() / 2]);
    val_min = std::max(0.08, 0.35 * v[v.size() / 2]);
    color_known = true;
}

void BallDetector::Impl::rs_segment(const std::vector<Hist> &seg0, int rows)
{
    // drop one sample at each end (contact) and require a long, tall flight
    if (seg0.size() < 14) return;
    std::vector<Hist> seg(seg0.begin() + 2, seg0.end() - 2);
    double ymin = 1e30, ymax = -1e30;
    for (const auto &h : seg) { ymin = std::min(ymin, h.y); ymax = std::max(ymax, h.y); }
    if (ymax - ymin < 0.2 * rows) return;
    size_t n = seg.size();
    std::vector<double> t(n), yc(n), v(n);
    for (size_t i = 0; i < n; i++) {
        size_t a = i > 0 ? i - 1 : i, b = i + 1 < n ? i + 1 : i;
        v[i] = (seg[b].y - seg[a].y) / (seg[b].t - seg[a].t);
        t[i] = seg[i].t;
    }
    double sse[kRsSteps];
    for (int k = 0; k < kRsSteps; k++) {
        double ks = rs_k_rel(k) * dt / rows;
        for (size_t i = 0; i < n; i++) yc[i] = seg[i].y - v[i] * ks * (seg[i].y - 0.5 * rows);
        double c[3], rms;
        if (!fit_quad(t, yc, c, &rms)) return;
        sse[k] = rms * rms;
        rs_ay[k] = 2.0 * c[2];
    }
    for (int k = 0; k < kRsSteps; k++) rs_sse[k] += sse[k];
    rs_segments++;
    int best = 0;
    for (int k = 1; k < kRsSteps; k++)
        if (rs_sse[k] < rs_sse[best]) best = k;
    rs_ay_best = rs_ay[best];
    int zero = (kRsSteps - 1) / 2;
    // only a clear improvement counts (a global shutter stays uncorrected): the rms at
    // least 40 % lower, at a k inside the grid (a k at its edge fits something else,
    // e.g. a hand still holding the ball at the segment's start: bounceAmeen's first drop)
    bool inside = best > 0 && best < kRsSteps - 1;
    rs_k = inside && rs_sse[best] < 0.36 * rs_sse[zero] ? rs_k_rel(best) * dt / rows : 0.0;
    if (std::getenv("GS_BALL_DEBUG"))
        std::fprintf(stderr, "rolling shutter: %d flights, k_rel %.2f, rms %.2f -> %.2f px\n", rs_segments,
                     rs_k_rel(best), std::sqrt(rs_sse[zero] / rs_segments),
                     std::sqrt(rs_sse[best] / rs_segments));
}

void BallDetector::Impl::rs_correct(const Track &tr, double rows, double *x, double *y) const
{
    if (rs_k == 0.0 || tr.seg.size() < 2) return;
    size_t n = tr.seg.size();
    const Hist &c = tr.seg[n - 1], &b = tr.seg[n - 2];
    double vx, vy;
    if (n >= 3) {  // second-order backward difference: exact on a parabola
        const Hist &a = tr.seg[n - 3];
        double h1 = c.t - b.t, h2 = b.t - a.t;
        if (!(h1 > 0 && h2 > 0)) return;
        double w0 = (2 * h1 + h2) / (h1 * (h1 + h2)), w1 = -(h1 + h2) / (h1 * h2), w2 = h1 / (h2 * (h1 + h2));
        vx = w0 * c.x + w1 * b.x + w2 * a.x;
        vy = w0 * c.y + w1 * b.y + w2 * a.y;
    } else {  // just after a bounce: the chord plus the known fall of half a frame
        double h = c.t - b.t;
        if (!(h > 0)) return;
        vx = (c.x - b.x) / h;
        vy = (c.y - b.y) / h + 0.5 * rs_ay_best * h;
    }
    double dtr = rs_k * (*y - 0.5 * rows);
    *x -= vx * dtr;
    *y -= vy * dtr;
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
    frame++;
    scale = std::min(1.0, 960.0 / bgr.cols);
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
    cv::cvtColor(small, hsv, cv::COLOR_BGR2HSV);
    // motion: difference to the background, any channel
    cv::Mat bg8, diff;  // in 8 bits: the threshold is whole grey levels anyway, and it is ~4x cheaper
    bg_small.convertTo(bg8, CV_8UC3);
    cv::absdiff(small, bg8, diff);
    std::vector<cv::Mat> ch;
    cv::split(diff, ch);
    cv::Mat mx = cv::max(cv::max(ch[0], ch[1]), ch[2]);
    motion = mx > cfg.motion_min;
    cv::Rect roi_s(0, 0, small.cols, small.rows);
    if (cfg.roi_set) {
        cv::Rect r((int)(cfg.roi_x * scale), (int)(cfg.roi_y * scale), (int)(cfg.roi_w * scale),
                   (int)(cfg.roi_h * scale));
        cv::Mat keep = cv::Mat::zeros(motion.size(), CV_8U);
        keep(r & roi_s).setTo(255);
        motion &= keep;
    }
    std::vector<Blob> blobs;
    if (color_known) {
        double h = hue / 2.0, tol = hue_tol / 2.0;
        int smin = (int)std::lround(sat_min * 255.0), vmin = (int)std::lround(val_min * 255.0);
        cv::Mat cm;
        double lo = h - tol, hi = h + tol;
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
        cv::Mat md;
        cv::dilate(motion, md, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
        cand = cm & md;
        cv::morphologyEx(cand, cand, cv::MORPH_CLOSE,
                         cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)));
        find_blobs(cand, blobs, false);
    } else {
        // colour learning needs a coloured ball: pixels more saturated than the
        // background there (shadows and ghosts keep the background's saturation)
        if (frame - bg_sat_frame >= 8) {  // the background changes slowly: its saturation is refreshed every 8 frames
            cv::Mat bghsv;
            cv::cvtColor(bg8, bghsv, cv::COLOR_BGR2HSV);
            cv::extractChannel(bghsv, bg_sat, 1);
            bg_sat_frame = frame;
        }
        cv::Mat sat, val, satd;
        cv::extractChannel(hsv, sat, 1);
        cv::extractChannel(hsv, val, 2);
        cv::subtract(sat, bg_sat, satd);
        cv::Mat sat_ok = (satd > 38) & (sat > 64) & (val > 25);
        motion &= sat_ok;
        cv::morphologyEx(motion, cand, cv::MORPH_OPEN,
                         cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)));
        cv::morphologyEx(cand, cand, cv::MORPH_CLOSE,
                         cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)));
        find_blobs(cand, blobs, true);
    }
    if (const char *dd = std::getenv("GS_BALL_DEBUG_DIR")) {
        char path[512];
        std::snprintf(path, sizeof path, "%s/m%04ld.png", dd, frame);
        cv::Mat vis = small.clone();
        vis.setTo(cv::Scalar(0, 0, 255), motion);
        vis.setTo(cv::Scalar(255, 0, 0), cand);
        cv::imwrite(path, vis);
    }
    if (blobs.size() > 64) blobs.resize(64);  // a scene change: do not chase noise

    // association: predicted position, greedy by distance
    for (auto &tr : tracks) tr.matched = false;
    std::vector<int> blob_track(blobs.size(), -1);
    struct Pair { double d; size_t b, t; };
    std::vector<Pair> pairs;
    for (size_t ti = 0; ti < tracks.size(); ti++) {
        const Track &tr = tracks[ti];
        double h = t_s - tr.t;
        double px = (tr.x + tr.vx * h) * scale, py = (tr.y + tr.vy * h) * scale;
        double speed = std::hypot(tr.vx, tr.vy) * h * scale;
        double gate = 1.5 * tr.d * scale + 0.6 * speed + 3.0 + (tr.misses + 1) * 0.5 * tr.d * scale;
        for (size_t bi = 0; bi < blobs.size(); bi++) {
            double d = std::hypot(blobs[bi].cx_s - px, blobs[bi].cy_s - py);
            double sr = blobs[bi].d_eq_s / std::max(1e-6, tr.d * scale);
            if (d < gate && sr > 0.4 && sr < 2.5) pairs.push_back({d, bi, ti});
        }
    }
    std::sort(pairs.begin(), pairs.end(), [](const Pair &a, const Pair &b) { return a.d < b.d; });
    for (const auto &p : pairs) {
        if (blob_track[p.b] >= 0 || tracks[p.t].matched) continue;
        blob_track[p.b] = (int)p.t;
        tracks[p.t].matched = true;
    }
    // new tracks for the rest (within max_balls, auto mode may follow more candidates)
    size_t max_tr = color_known ? (size_t)cfg.max_balls : (size_t)std::max(cfg.max_balls, 8);
    for (size_t bi = 0; bi < blobs.size(); bi++) {
        if (blob_track[bi] >= 0 || tracks.size() >= max_tr) continue;
        Track tr;
        std::vector<bool> used(64, false);
        for (const auto &o : tracks)
            if (o.id >= 0 && o.id < 64) used[(size_t)o.id] = true;
        int id = 0;
        while (used[(size_t)id]) id++;
        tr.id = id;
        tr.x = blobs[bi].cx_s / scale;
        tr.y = blobs[bi].cy_s / scale;
        tr.t = t_s;
        tr.d = blobs[bi].d_eq_s / scale;
        tr.matched = true;
        tracks.push_back(tr);
        blob_track[bi] = (int)tracks.size() - 1;
    }

    // measure and update
    keep_s.clear();
    for (size_t bi = 0; bi < blobs.size(); bi++) {
        const Blob &b = blobs[bi];
        cv::Rect r = b.box_s;
        int m = (int)std::ceil(0.5 * b.d_eq_s) + 2;
        r = cv::Rect(r.x - m, r.y - m, r.width + 2 * m, r.height + 2 * m) & roi_s;
        keep_s.push_back(r);
        int ti = blob_track[bi];
        if (ti < 0) continue;
        Track &tr = tracks[(size_t)ti];
        bool fresh = tr.hits == 0;
        Meas ms = measure(bgr, b, tr.have_color ? &tr : nullptr);
        double x = ms.ok ? ms.x : b.cx_s / scale, y = ms.ok ? ms.y : b.cy_s / scale;
        if (!fresh) {
            double h = t_s - tr.t;
            if (h > 0) {
                double vx = (x - tr.x) / h, vy = (y - tr.y) / h;
                double k = tr.hits == 1 ? 1.0 : 0.7;
                tr.vx += k * (vx - tr.vx);
                tr.vy += k * (vy - tr.vy);
            }
        }
        tr.x = x;
        tr.y = y;
        tr.t = t_s;
        tr.hits++;
        tr.misses = 0;
        double d_prev = tr.hits >= 3 ? tr.d : kNaN;
        double dmeas = ms.ok && ms.ratio < cfg.max_blur_ratio ? ms.d_perp : b.d_eq_s / scale;
        tr.d = fresh ? dmeas : tr.d + 0.3 * (dmeas - tr.d);
        if (ms.ok && ms.ratio < 1.25 && !ms.at_edge) {
            if (!tr.have_color) tr.color = ms.color;
            else tr.color += 0.2f * (ms.color - tr.color);
            tr.have_color = true;
        }
        tr.hist.push_back({t_s, x, y, dmeas});
        {
            // a bounce (falling, then rising) closes the flight segment
            size_t n = tr.seg.size();
            if (n >= 2 && tr.seg[n - 1].y - tr.seg[n - 2].y > 0.0 && y - tr.seg[n - 1].y < 0.0) {
                rs_segment(tr.seg, bgr.rows);
                tr.seg.erase(tr.seg.begin(), tr.seg.end() - 1);
            }
            if (!tr.seg.empty() && t_s - tr.seg.back().t > 0.2) tr.seg.clear();
            tr.seg.push_back({t_s, x, y, dmeas});
            if (tr.seg.size() > 400) tr.seg.erase(tr.seg.begin());
        }
        if (tr.hist.size() > 12) tr.hist.erase(tr.hist.begin());
        if (!color_known) {
            tr.blobs.push_back(b);
            if (tr.blobs.size() > 12) tr.blobs.erase(tr.blobs.begin());
            if (ballistic(tr)) {
                // the colour is known: the candidates of other colours go, the ball is track 0
                learn_color(tr);
                for (auto &o : tracks)
                    if (&o != &tr) o.dead = true;
                tr.id = 0;
            }
            continue;  // nothing is reported before the colour is known
        }
        if (tr.hits < 2 || !ms.ok || tr.dead) continue;
        BallObs o;
        o.track = tr.id;
        o.x_px = ms.x;
        o.y_px = ms.y;
        rs_correct(tr, bgr.rows, &o.x_px, &o.y_px);
        double conf = 1.0;
        bool good = true;
        if (ms.at_edge) { conf *= 0.3; good = false; }
        if (ms.ratio > cfg.max_blur_ratio) good = false;
        conf *= std::max(0.2, 1.0 - 0.3 * std::max(0.0, ms.ratio - 1.2));
        // the area and the width agree for an unoccluded ball (blur keeps both)
        double cons = ms.d_area / ms.d_perp;
        if (cons < 0.85 || cons > 1.2) { good = false; conf *= 0.5; }
        if (ms.contrast < 30.0) { conf *= 0.5; }
        // a sudden change of size: partly hidden or merged with something (its centre is off too)
        if (std::isfinite(d_prev) && std::fabs(ms.d_perp / d_prev - 1.0) > 0.08 && ms.ratio < cfg.max_blur_ratio) {
            good = false;
            conf *= 0.2;
        }
        if (ms.d_perp < cfg.min_diameter_px || ms.d_perp > cfg.max_diameter_px) { good = false; conf *= 0.5; }
        o.diameter_px = good ? ms.d_perp : kNaN;
        o.confidence = std::min(1.0, std::max(0.05, conf));
        out.push_back(o);
    }
    // tracks lost for a while end
    int max_miss = std::max(3, (int)std::lround(0.25 / std::max(1e-3, dt)));
    for (auto &tr : tracks)
        if (!tr.matched) tr.misses++;
    tracks.erase(std::remove_if(tracks.begin(), tracks.end(),
                                [&](const Track &tr) { return tr.dead || tr.misses > max_miss; }),
                 tracks.end());
    if (out.size() > (size_t)cfg.max_balls) out.resize((size_t)cfg.max_balls);

    // backgrounds follow slow changes, not the balls: an unmasked update (SIMD,
    // 8-bit source) with the balls' regions put back is ~5x cheaper than a masked one
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
    cv::accumulateWeighted(small, bg_small, 0.04);
    cv::accumulateWeighted(bgr, bg_full, 0.04);
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

bool BallDetector::color_known(double *hue_deg, double *sat_min, double *val_min) const
{
    if (hue_deg) *hue_deg = p_->hue;
    if (sat_min) *sat_min = p_->sat_min;
    if (val_min) *val_min = p_->val_min;
    return p_->color_known;
}

}  // namespace gs
