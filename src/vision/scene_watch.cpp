// scene_watch.cpp - per-flight and live warnings from recorded frame facts.
#include "scene_watch.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

extern "C" {
#include "gravscale/gs_event.h"
}

namespace gs {

namespace {
constexpr double kKeepS = 6.0;  // longer than any flight plus the core's landing latency

double median(std::vector<double> v)
{
    if (v.empty()) return NAN;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}
}  // namespace

void SceneWatch::add(const SceneFrame &f)
{
    frames_.push_back(f);
    while (!frames_.empty() && f.t_s - frames_.front().t_s > kKeepS) frames_.pop_front();
}

uint32_t SceneWatch::flight_warnings(double t0, double t1, double t_apex) const
{
    if (!std::isfinite(t0)) t0 = t_apex - 0.3;
    if (!std::isfinite(t1)) t1 = t_apex + 0.3;
    if (!std::isfinite(t0) || !std::isfinite(t1)) return 0;
    const double a = t0 - cfg_.margin_s, b = t1 + cfg_.margin_s;
    uint32_t w = 0;
    bool first = true;
    double x0 = 0, y0 = 0, moved = 0;
    std::vector<double> sizes, before, after;
    for (const SceneFrame &f : frames_) {
        if (f.t_s >= t0 - 0.4 && f.t_s < t0 - 0.05 && std::isfinite(f.ground_y_px)) before.push_back(f.ground_y_px);
        if (f.t_s > t1 + 0.05 && f.t_s <= t1 + 0.4 && std::isfinite(f.ground_y_px)) after.push_back(f.ground_y_px);
        if (f.t_s < a || f.t_s > b) continue;
        if (std::isfinite(f.size_px)) sizes.push_back(f.size_px);
        if (f.present && f.at_border) w |= GS_WARN_LEFT_FRAME;
        if (!f.cam_valid) {
            w |= GS_WARN_CAMERA_MOVED;  // unknown camera motion is no static camera either
            continue;
        }
        if (first) {
            x0 = f.cam_dx_px;
            y0 = f.cam_dy_px;
            first = false;
        }
        moved = std::max(moved, std::hypot(f.cam_dx_px - x0, f.cam_dy_px - y0));
    }
    double size = median(sizes);
    double thr = std::max(cfg_.cam_moved_min_px, std::isfinite(size) ? cfg_.cam_moved_rel * size : 0.0);
    if (moved > thr) w |= GS_WARN_CAMERA_MOVED;
    // someone (something) moved right beside the body: its keypoints may have followed
    int frames = 0;
    if (other_motion(t0, t1, t_apex, &frames) >= cfg_.other_frames) w |= GS_WARN_OTHER_MOTION;
    // the feet land on another row: the body moved in depth (or the camera tilted)
    double gb = median(before), ga = median(after);
    if (std::isfinite(gb) && std::isfinite(ga) && std::isfinite(size) && std::fabs(ga - gb) > cfg_.depth_rel * size)
        w |= GS_WARN_OUT_OF_PLANE;
    return w;
}

int SceneWatch::other_motion(double t0, double t1, double t_apex, int *frames) const
{
    *frames = 0;
    if (!std::isfinite(t0)) t0 = t_apex - 0.3;
    if (!std::isfinite(t1)) t1 = t_apex + 0.3;
    if (!std::isfinite(t0) || !std::isfinite(t1)) return 0;
    int n = 0;
    for (const SceneFrame &f : frames_) {
        if (f.t_s < t0 - cfg_.margin_s || f.t_s > t1 + cfg_.margin_s) continue;
        (*frames)++;
        if (f.other >= cfg_.other_corners) n++;
    }
    return n;
}

bool SceneWatch::other_rejects(double t0, double t1, double t_apex) const
{
    int frames = 0, n = other_motion(t0, t1, t_apex, &frames);
    return n >= cfg_.other_frames && n >= cfg_.other_reject * frames;
}

uint32_t SceneWatch::onsets()
{
    if (frames_.empty()) return 0;
    const SceneFrame &f = frames_.back();
    uint32_t now = 0;
    if (f.present && f.at_border) now |= GS_WARN_LEFT_FRAME;
    // the camera moved over the last half second by more than the threshold
    double size = std::isfinite(f.size_px) ? f.size_px : 0.0;
    double thr = std::max(cfg_.cam_moved_min_px, cfg_.cam_moved_rel * size);
    for (auto it = frames_.rbegin(); it != frames_.rend() && f.t_s - it->t_s <= 0.5; ++it) {
        if (!it->cam_valid || !f.cam_valid ||
            std::hypot(f.cam_dx_px - it->cam_dx_px, f.cam_dy_px - it->cam_dy_px) > thr) {
            now |= GS_WARN_CAMERA_MOVED;
            break;
        }
    }
    uint32_t started = now & ~active_;
    active_ = now;
    return started;
}

}  // namespace gs
