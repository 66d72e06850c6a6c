// overlay.cpp - frames with detections, flights and numbers; contact sheet; plot.
#include "overlay.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

extern "C" {
#include "gravscale/gs_fit.h"
}

namespace gs {

namespace {

const cv::Scalar kTrackColors[] = {
    {0, 200, 255}, {255, 160, 0}, {255, 0, 200}, {0, 255, 120}, {80, 80, 255}, {255, 255, 0},
};
const cv::Scalar kAccepted(60, 220, 60), kRejected(40, 40, 230), kWhite(255, 255, 255),
    kBlack(0, 0, 0);

cv::Scalar track_color(int track)
{
    return kTrackColors[static_cast<size_t>(std::max(track, 0)) % (sizeof kTrackColors / sizeof kTrackColors[0])];
}

std::string fmt(const char *f, double v)
{
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}

std::string lower_ext(const std::string &path)
{
    size_t dot = path.find_last_of('.');
    size_t slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string e = path.substr(dot);
    for (char &c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

// text with a dark outline, readable on any background
void label(cv::Mat &img, const std::string &s, cv::Point org, double scale, cv::Scalar color, int thick)
{
    cv::putText(img, s, org, cv::FONT_HERSHEY_SIMPLEX, scale, kBlack, thick + 2, cv::LINE_AA);
    cv::putText(img, s, org, cv::FONT_HERSHEY_SIMPLEX, scale, color, thick, cv::LINE_AA);
}

cv::Point2d curve_at(const JumpRecord &j, double t)
{
    double d = t - j.t0_s;
    return {j.x0 + j.vx * d + 0.5 * j.ax * d * d, j.y0 + j.vy * d + 0.5 * j.ay * d * d};
}

// fixed-point coordinates for sub-pixel drawing
constexpr int kShift = 4;
cv::Point fx(cv::Point2d p)
{
    return {static_cast<int>(std::lround(p.x * (1 << kShift))), static_cast<int>(std::lround(p.y * (1 << kShift)))};
}

int64_t nearest_frame(const RunRecord &r, double t)
{
    if (r.frame_t.empty()) return -1;
    auto it = std::lower_bound(r.frame_t.begin(), r.frame_t.end(), t);
    int64_t i = it - r.frame_t.begin();
    if (i >= static_cast<int64_t>(r.frame_t.size())) return static_cast<int64_t>(r.frame_t.size()) - 1;
    if (i > 0 && t - r.frame_t[static_cast<size_t>(i - 1)] < r.frame_t[static_cast<size_t>(i)] - t) i--;
    return i;
}

double nice_step(double range, int target)
{
    if (!(range > 0)) return 1.0;
    double raw = range / target;
    double p = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * p >= raw) return m * p;
    return 10.0 * p;
}

}  // namespace

void fit_jump_curves(RunRecord &r)
{
    for (JumpRecord &j : r.jumps) {
        j.has_curve = false;
        if (!(std::isfinite(j.t_takeoff_s) && std::isfinite(j.t_land_s) && j.t_land_s > j.t_takeoff_s)) continue;
        // the fit counts in microseconds: centre and length of the window
        const int64_t t0_us = gs_time_us_of_s(0.5 * (j.t_takeoff_s + j.t_land_s));
        const int64_t tscale_us = gs_time_us_of_s(j.t_land_s - j.t_takeoff_s);
        if (t0_us == GS_T_NONE || tscale_us == GS_T_NONE || tscale_us <= 0) continue;
        gs_fit f;
        gs_fit_init(&f, t0_us, tscale_us);
        for (size_t i = 0; i < r.frame_t.size(); i++) {
            double t = r.frame_t[i];
            if (t < j.t_takeoff_s || t > j.t_land_s) continue;
            const int64_t t_us = gs_time_us_of_s(t);
            for (const ObsRecord &o : r.frame_obs[i])
                if (o.track == static_cast<int>(j.track))
                    gs_fit_add(&f, t_us, o.x_px, o.y_px, std::max(o.confidence, 1e-3));
        }
        gs_fit_result fr;
        if (gs_fit_solve(&f, &fr) != GS_OK) continue;
        j.has_curve = true;
        j.t0_s = gs_time_s_of_us(fr.t0_us);
        j.x0 = fr.x0_px;
        j.vx = fr.vx_px_s;
        j.ax = fr.ax_px_s2;
        j.y0 = fr.y0_px;
        j.vy = fr.vy_px_s;
        j.ay = fr.ay_px_s2;
    }
}

static std::string subject_name(const RunRecord &r) { return r.person ? "person" : "ball"; }

void draw_overlay(cv::Mat &img, const RunRecord &r, int64_t index)
{
    if (img.empty() || index < 0 || index >= static_cast<int64_t>(r.frame_t.size())) return;
    const size_t fi = static_cast<size_t>(index);
    const double t = r.frame_t[fi];
    const double s = std::max(0.45, img.rows / 720.0);  // line and text scale
    const int th = std::max(1, static_cast<int>(std::lround(2 * s)));
    const double ts = 0.55 * s;

    // flights: the fitted parabola from take-off to landing, shown from take-off until 1 s after landing
    for (const JumpRecord &j : r.jumps) {
        if (!j.has_curve || t < j.t_takeoff_s || t > j.t_land_s + 1.0) continue;
        cv::Scalar c = j.accepted ? kAccepted : kRejected;
        std::vector<cv::Point> pts;
        const int n = 48;
        for (int k = 0; k <= n; k++) pts.push_back(fx(curve_at(j, j.t_takeoff_s + (j.t_land_s - j.t_takeoff_s) * k / n)));
        bool flying = t <= j.t_land_s;
        cv::polylines(img, pts, false, c, flying ? th : std::max(1, th / 2), cv::LINE_AA, kShift);
        cv::Point2d apex = curve_at(j, j.t_apex_s);
        cv::drawMarker(img, cv::Point(static_cast<int>(apex.x), static_cast<int>(apex.y)), c, cv::MARKER_TRIANGLE_DOWN,
                       static_cast<int>(14 * s), th, cv::LINE_AA);
        std::string txt = "#" + std::to_string(j.index) + " a=" + fmt("%.0f", j.a_px_s2) + " px/s2 q=" +
                          fmt("%.3f", j.q_m_per_px * 1000.0) + " mm/px ";
        txt += j.accepted ? (r.person ? "h=" : "d=") + fmt("%.1f", j.height_m * 100.0) + " cm" : "rejected: " + j.reason;
        label(img, txt, cv::Point(static_cast<int>(apex.x + 12 * s), static_cast<int>(apex.y - 10 * s)), ts, c, th / 2 + 1);
    }

    // trails of the last second and this frame's detections
    for (size_t k = fi + 1; k-- > 0;) {
        if (t - r.frame_t[k] > 1.0) break;
        for (const ObsRecord &o : r.frame_obs[k]) {
            if (k == fi) continue;
            cv::circle(img, fx({o.x_px, o.y_px}), static_cast<int>(2 * s) << kShift, track_color(o.track), -1,
                       cv::LINE_AA, kShift);
        }
    }
    if (fi < r.frame_kp.size() && r.frame_kp[fi].size() == 33) {
        // BlazePose's skeleton: face, arms, trunk, legs and feet
        static const int bones[][2] = {{11, 12}, {11, 13}, {13, 15}, {12, 14}, {14, 16}, {11, 23}, {12, 24},
                                       {23, 24}, {23, 25}, {25, 27}, {24, 26}, {26, 28}, {27, 29}, {29, 31},
                                       {27, 31}, {28, 30}, {30, 32}, {28, 32}, {0, 2},   {0, 5},   {2, 7},
                                       {5, 8},   {9, 10}};
        const std::vector<cv::Point3f> &k = r.frame_kp[fi];
        for (const auto &b : bones) {
            if (k[b[0]].z < 0.3f || k[b[1]].z < 0.3f) continue;
            cv::line(img, fx({k[b[0]].x, k[b[0]].y}), fx({k[b[1]].x, k[b[1]].y}), kWhite, th, cv::LINE_AA, kShift);
        }
        for (const cv::Point3f &p : k)
            if (p.z >= 0.3f)
                cv::circle(img, fx({p.x, p.y}), static_cast<int>(3 * s) << kShift, kAccepted, -1, cv::LINE_AA, kShift);
    }
    for (const ObsRecord &o : r.frame_obs[fi]) {
        cv::Scalar c = track_color(o.track);
        if (std::isfinite(o.diameter_px))
            cv::circle(img, fx({o.x_px, o.y_px}), static_cast<int>(std::lround(0.5 * o.diameter_px * (1 << kShift))),
                       c, th, cv::LINE_AA, kShift);
        cv::drawMarker(img, cv::Point(static_cast<int>(o.x_px), static_cast<int>(o.y_px)), c, cv::MARKER_CROSS,
                       static_cast<int>(8 * s), 1, cv::LINE_AA);
        double rad = std::isfinite(o.diameter_px) ? 0.5 * o.diameter_px : 0.0;
        label(img, r.person ? std::string("COM") : "ball " + std::to_string(o.track) + " " + fmt("%.1f", o.diameter_px) + " px",
              cv::Point(static_cast<int>(o.x_px + rad + 6 * s), static_cast<int>(o.y_px)), ts, c, th / 2 + 1);
    }

    // header: time, rate, and each track's result so far
    int y = static_cast<int>(28 * s);
    label(img, "t=" + fmt("%.3f", t) + " s  frame " + std::to_string(index) + "  " + fmt("%.2f", r.fps) +
                   " fps (" + r.fps_origin + ")",
          cv::Point(static_cast<int>(10 * s), y), ts, kWhite, th / 2 + 1);
    std::map<uint32_t, const JumpRecord *> latest;
    for (const JumpRecord &j : r.jumps)
        if (j.accepted && j.t_land_s <= t) latest[j.track] = &j;
    for (const auto &kv : latest) {
        y += static_cast<int>(26 * s);
        const JumpRecord &j = *kv.second;
        label(img, subject_name(r) + " " + std::to_string(kv.first) + ": " + fmt("%.1f", j.running_height_m * 100.0) + " cm over " +
                       std::to_string(j.running_n) + " flight(s)",
              cv::Point(static_cast<int>(10 * s), y), ts, track_color(static_cast<int>(kv.first)), th / 2 + 1);
    }
    for (const JumpRecord &j : r.jumps) {
        if (t >= j.t_takeoff_s && t <= j.t_land_s) {
            y += static_cast<int>(26 * s);
            label(img, "in flight (" + subject_name(r) + " " + std::to_string(j.track) + ", #" + std::to_string(j.index) + ")",
                  cv::Point(static_cast<int>(10 * s), y), ts, j.accepted ? kAccepted : kRejected, th / 2 + 1);
        }
    }
}

std::vector<int64_t> contact_sheet_frames(const RunRecord &r, size_t max_tiles)
{
    std::vector<int64_t> out;
    const int64_t n = static_cast<int64_t>(r.frame_t.size());
    if (n == 0 || max_tiles == 0) return out;
    bool all3 = r.jumps.size() * 3 <= max_tiles;
    for (const JumpRecord &j : r.jumps) {
        if (all3) {
            out.push_back(nearest_frame(r, j.t_takeoff_s));
            out.push_back(nearest_frame(r, j.t_apex_s));
            out.push_back(nearest_frame(r, j.t_land_s));
        } else {
            out.push_back(nearest_frame(r, j.t_apex_s));
        }
    }
    if (out.empty()) {
        size_t k = std::min<size_t>(max_tiles, 8);
        for (size_t i = 0; i < k; i++) out.push_back(static_cast<int64_t>((n - 1) * (2 * i + 1) / (2 * k)));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    out.erase(std::remove(out.begin(), out.end(), -1), out.end());
    if (out.size() > max_tiles) {
        std::vector<int64_t> thin;
        for (size_t i = 0; i < max_tiles; i++) thin.push_back(out[i * out.size() / max_tiles]);
        out = thin;
    }
    return out;
}

bool OverlayWriter::is_sheet_path(const std::string &path)
{
    std::string e = lower_ext(path);
    return e == ".png" || e == ".jpg" || e == ".jpeg";
}

bool OverlayWriter::open(const std::string &path, const RunRecord &r, double play_fps, std::string &err)
{
    path_ = path;
    sheet_ = is_sheet_path(path);
    if (sheet_) {
        pick_ = contact_sheet_frames(r, 12);
        return true;
    }
    std::string e = lower_ext(path);
    int fourcc;
    if (e == ".avi")
        fourcc = cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
    else if (e == ".mp4" || e == ".mov")
        fourcc = cv::VideoWriter::fourcc('m', 'p', '4', 'v');
    else if (e == ".mkv")
        fourcc = cv::VideoWriter::fourcc('F', 'F', 'V', '1');
    else {
        err = "the overlay must end in .avi, .mp4, .mov, .mkv (a video) or .png, .jpg (a contact sheet)";
        return false;
    }
    double fps = std::isfinite(play_fps) && play_fps > 0 ? play_fps : 30.0;
    if (!video_.open(path, cv::CAP_FFMPEG, fourcc, fps, r.frame_size, true) || !video_.isOpened()) {
        err = "cannot write the overlay video";
        return false;
    }
    return true;
}

bool OverlayWriter::wants(int64_t index) const
{
    return !sheet_ || std::binary_search(pick_.begin(), pick_.end(), index);
}

bool OverlayWriter::add(const cv::Mat &img, int64_t index, std::string &err)
{
    (void)err;
    if (!sheet_) {
        video_.write(img);
        return true;
    }
    if (!wants(index)) return true;
    const int tile_w = std::min(640, img.cols);
    cv::Mat tile;
    cv::resize(img, tile, cv::Size(tile_w, std::max(1, img.rows * tile_w / std::max(1, img.cols))), 0, 0, cv::INTER_AREA);
    tiles_.push_back(tile);
    return true;
}

bool OverlayWriter::close(std::string &err)
{
    if (!sheet_) {
        video_.release();
        return true;
    }
    if (tiles_.empty()) {
        err = "no frame for the contact sheet";
        return false;
    }
    const int cols = tiles_.size() <= 4 ? static_cast<int>(tiles_.size()) : (tiles_.size() <= 9 ? 3 : 4);
    const int rows = static_cast<int>((tiles_.size() + cols - 1) / cols);
    const int tw = tiles_[0].cols, tht = tiles_[0].rows, gap = 4;
    cv::Mat sheet(rows * tht + (rows + 1) * gap, cols * tw + (cols + 1) * gap, CV_8UC3, cv::Scalar(32, 32, 32));
    for (size_t i = 0; i < tiles_.size(); i++) {
        int rr = static_cast<int>(i) / cols, cc = static_cast<int>(i) % cols;
        tiles_[i].copyTo(sheet(cv::Rect(gap + cc * (tw + gap), gap + rr * (tht + gap), tw, tht)));
    }
    bool ok = false;
    try {
        ok = cv::imwrite(path_, sheet);
    } catch (const cv::Exception &) {
        ok = false;
    }
    if (!ok) err = "cannot write the contact sheet";
    return ok;
}

bool write_plot(const RunRecord &r, const std::string &path, std::string &err)
{
    const int W = 1400, H = 940, L = 90, R = 30, T = 70, gapv = 60;
    const int h_top = 520, h_bot = H - T - h_top - gapv - 50;
    cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
    const cv::Scalar grid(225, 225, 225), axis(90, 90, 90), text(40, 40, 40);

    double t_lo = INFINITY, t_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY, x_lo = INFINITY, x_hi = -INFINITY;
    for (size_t i = 0; i < r.frame_t.size(); i++) {
        for (const ObsRecord &o : r.frame_obs[i]) {
            t_lo = std::min(t_lo, r.frame_t[i]);
            t_hi = std::max(t_hi, r.frame_t[i]);
            y_lo = std::min(y_lo, -o.y_px);
            y_hi = std::max(y_hi, -o.y_px);
            x_lo = std::min(x_lo, o.x_px);
            x_hi = std::max(x_hi, o.x_px);
        }
    }
    if (!(t_hi >= t_lo)) {  // nothing detected: empty axes over the clip
        t_lo = r.frame_t.empty() ? 0.0 : r.frame_t.front();
        t_hi = r.frame_t.empty() ? 1.0 : r.frame_t.back();
        y_lo = -r.frame_size.height;
        y_hi = 0;
        x_lo = 0;
        x_hi = r.frame_size.width;
    }
    auto pad = [](double &lo, double &hi, double frac, double min_span) {
        double span = std::max(hi - lo, min_span);
        double mid = 0.5 * (lo + hi);
        lo = mid - 0.5 * span * (1 + 2 * frac);
        hi = mid + 0.5 * span * (1 + 2 * frac);
    };
    pad(t_lo, t_hi, 0.02, 0.1);
    pad(y_lo, y_hi, 0.06, 10);
    pad(x_lo, x_hi, 0.06, 10);

    struct Panel {
        cv::Rect box;
        double v_lo, v_hi;
        const char *name;
    };
    Panel top{cv::Rect(L, T, W - L - R, h_top), y_lo, y_hi, "up (-y) [px]"};
    Panel bot{cv::Rect(L, T + h_top + gapv, W - L - R, h_bot), x_lo, x_hi, "x [px]"};
    auto X = [&](double t) { return top.box.x + (t - t_lo) / (t_hi - t_lo) * top.box.width; };
    auto Y = [](const Panel &p, double v) { return p.box.y + p.box.height - (v - p.v_lo) / (p.v_hi - p.v_lo) * p.box.height; };
    auto P = [&](const Panel &p, double t, double v) { return fx({X(t), Y(p, v)}); };

    for (const Panel *p : {&top, &bot}) {
        // flight windows shaded
        for (const JumpRecord &j : r.jumps) {
            if (!(std::isfinite(j.t_takeoff_s) && std::isfinite(j.t_land_s))) continue;
            int x0 = static_cast<int>(std::max<double>(p->box.x, X(j.t_takeoff_s)));
            int x1 = static_cast<int>(std::min<double>(p->box.x + p->box.width, X(j.t_land_s)));
            if (x1 > x0)
                cv::rectangle(img, cv::Rect(x0, p->box.y, x1 - x0, p->box.height),
                              j.accepted ? cv::Scalar(225, 245, 225) : cv::Scalar(225, 225, 250), -1);
        }
        double st = nice_step(t_hi - t_lo, 10);
        for (double v = std::ceil(t_lo / st) * st; v <= t_hi; v += st) {
            int x = static_cast<int>(X(v));
            cv::line(img, {x, p->box.y}, {x, p->box.y + p->box.height}, grid, 1);
            cv::putText(img, fmt(st < 0.1 ? "%.2f" : "%.1f", v), {x - 14, p->box.y + p->box.height + 18},
                        cv::FONT_HERSHEY_SIMPLEX, 0.45, text, 1, cv::LINE_AA);
        }
        double sv = nice_step(p->v_hi - p->v_lo, 6);
        for (double v = std::ceil(p->v_lo / sv) * sv; v <= p->v_hi; v += sv) {
            int y = static_cast<int>(Y(*p, v));
            cv::line(img, {p->box.x, y}, {p->box.x + p->box.width, y}, grid, 1);
            cv::putText(img, fmt("%.0f", v), {p->box.x - 62, y + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.45, text, 1,
                        cv::LINE_AA);
        }
        cv::rectangle(img, p->box, axis, 1);
        cv::putText(img, p->name, {p->box.x + 6, p->box.y + 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, text, 1, cv::LINE_AA);
        cv::putText(img, "t [s]", {p->box.x + p->box.width - 40, p->box.y + p->box.height + 36},
                    cv::FONT_HERSHEY_SIMPLEX, 0.5, text, 1, cv::LINE_AA);
    }

    // samples
    for (size_t i = 0; i < r.frame_t.size(); i++) {
        for (const ObsRecord &o : r.frame_obs[i]) {
            cv::Scalar c = track_color(o.track);
            cv::circle(img, P(top, r.frame_t[i], -o.y_px), 3 << kShift, c, -1, cv::LINE_AA, kShift);
            cv::circle(img, P(bot, r.frame_t[i], o.x_px), 3 << kShift, c, -1, cv::LINE_AA, kShift);
        }
    }
    // fitted parabolas and their numbers
    for (const JumpRecord &j : r.jumps) {
        if (!j.has_curve) continue;
        cv::Scalar c = j.accepted ? cv::Scalar(30, 150, 30) : cv::Scalar(30, 30, 200);
        std::vector<cv::Point> up, xs;
        const int n = 64;
        for (int k = 0; k <= n; k++) {
            double tt = j.t_takeoff_s + (j.t_land_s - j.t_takeoff_s) * k / n;
            cv::Point2d q = curve_at(j, tt);
            up.push_back(P(top, tt, -q.y));
            xs.push_back(P(bot, tt, q.x));
        }
        cv::polylines(img, up, false, c, 2, cv::LINE_AA, kShift);
        cv::polylines(img, xs, false, c, 2, cv::LINE_AA, kShift);
        cv::Point2d apex = curve_at(j, j.t_apex_s);
        int ax = static_cast<int>(X(j.t_apex_s)) - 40, ay = static_cast<int>(Y(top, -apex.y)) - 34;
        ay = std::max(ay, top.box.y + 30);
        std::string l1 = subject_name(r) + " " + std::to_string(j.track) + " #" + std::to_string(j.index) + " a=" + fmt("%.0f", j.a_px_s2);
        std::string l2 = j.accepted ? "d=" + fmt("%.1f", j.height_m * 100) + " cm" : j.reason;
        cv::putText(img, l1, {ax, ay}, cv::FONT_HERSHEY_SIMPLEX, 0.42, c, 1, cv::LINE_AA);
        cv::putText(img, l2, {ax, ay + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.42, c, 1, cv::LINE_AA);
    }
    // title
    std::string title = r.source + "  (" + fmt("%.2f", r.fps) + " fps, " + r.fps_origin + ")";
    cv::putText(img, title, {L, 28}, cv::FONT_HERSHEY_SIMPLEX, 0.65, text, 1, cv::LINE_AA);
    std::string sum;
    for (const SummaryRecord &s : r.summaries) {
        sum += subject_name(r) + " " + std::to_string(s.track) + ": ";
        sum += std::isfinite(s.height_m) ? fmt("%.2f cm", s.height_m * 100) + " [" + fmt("%.2f", s.lo_m * 100) + ", " +
                                               fmt("%.2f", s.hi_m * 100) + "]"
                                         : std::string("no size");
        sum += " from " + std::to_string(s.n_jumps) + " flight(s), " + std::to_string(s.n_rejected) + " rejected   ";
    }
    cv::putText(img, sum, {L, 54}, cv::FONT_HERSHEY_SIMPLEX, 0.55, text, 1, cv::LINE_AA);

    bool ok = false;
    try {
        ok = cv::imwrite(path, img);
    } catch (const cv::Exception &) {
        ok = false;
    }
    if (!ok) err = "cannot write the plot (a .png or .jpg path in a writable folder)";
    return ok;
}

}  // namespace gs
