// pose_look.cpp - see pose_look.hpp.
#include "pose_look.hpp"

#include <algorithm>
#include <cmath>

namespace gs {

namespace {

// the segments of each part: from, to (BlazePose-33); the trunk is the quad 11, 12, 24, 23
const int kSeg[kLookParts][2] = {{-1, -1},  {11, 13}, {12, 14}, {13, 15}, {14, 16},
                                 {23, 25}, {24, 26}, {25, 27}, {26, 28}, {27, 31}, {28, 32}};
const int kPartKp[kLookParts][8] = {
    {-1},                        // the trunk: the whole frame goes
    {13, -1},         {14, -1},  // elbows
    {15, 17, 19, 21, -1},        // wrist and hand
    {16, 18, 20, 22, -1},
    {25, -1},         {26, -1},  // knees
    {27, 29, 31, -1}, {28, 30, 32, -1},  // ankles, heels, foot index
    {31, -1},         {32, -1},  // foot index
};

bool usable(const gs_kp &p, double min_c)
{
    return std::isfinite(p.x_px) && std::isfinite(p.y_px) && p.c >= min_c;
}

void add_pixel(const cv::Mat &bgr, double x, double y, PoseLookHist &h, int &n)
{
    int ix = static_cast<int>(std::lround(x)), iy = static_cast<int>(std::lround(y));
    if (ix < 0 || iy < 0 || ix >= bgr.cols || iy >= bgr.rows) return;
    const cv::Vec3b &p = bgr.at<cv::Vec3b>(iy, ix);
    int b = p[0], g = p[1], r = p[2];
    int mx = std::max(b, std::max(g, r)), mn = std::min(b, std::min(g, r));
    int s = mx > 0 ? 255 * (mx - mn) / mx : 0;
    int bin;
    if (s < 60 || mx < 40) {
        bin = 16 + std::min(3, mx / 64);  // greys by value
    } else {
        double hue;  // degrees
        double d = mx - mn;
        if (mx == r) hue = 60.0 * std::fmod((g - b) / d + 6.0, 6.0);
        else if (mx == g) hue = 60.0 * ((b - r) / d + 2.0);
        else hue = 60.0 * ((r - g) / d + 4.0);
        int hb = std::min(7, static_cast<int>(hue / 45.0));
        bin = 2 * hb + (s >= 150 ? 1 : 0);
    }
    h.bin[bin] += 1.0f;
    n++;
}

void finish(PoseLookHist &h, int n)
{
    h.valid = n >= 8;
    if (!h.valid) return;
    for (float &v : h.bin) v /= static_cast<float>(n);
}

}  // namespace

const int *pose_look_part_keypoints(int part)
{
    static const int none[1] = {-1};
    return part >= 0 && part < kLookParts ? kPartKp[part] : none;
}

void pose_look_sample(const cv::Mat &bgr, const gs_kp *kp, double min_c, PoseLookHist out[kLookParts])
{
    for (int p = 0; p < kLookParts; p++) out[p] = PoseLookHist();
    if (bgr.empty() || bgr.type() != CV_8UC3) return;
    const gs_kp &ls = kp[11], &rs = kp[12], &lh = kp[23], &rh = kp[24];
    double trunk = NAN;
    if (usable(ls, min_c) && usable(rs, min_c) && usable(lh, min_c) && usable(rh, min_c)) {
        double sx = 0.5 * (ls.x_px + rs.x_px), sy = 0.5 * (ls.y_px + rs.y_px);
        double hx = 0.5 * (lh.x_px + rh.x_px), hy = 0.5 * (lh.y_px + rh.y_px);
        trunk = std::hypot(sx - hx, sy - hy);
        // the trunk: a grid inside the quad (shoulders to hips), away from its edges
        int n = 0;
        for (int i = 1; i < 8; i++) {
            double v = i / 8.0;
            double ax = ls.x_px + v * (lh.x_px - ls.x_px), ay = ls.y_px + v * (lh.y_px - ls.y_px);
            double bx = rs.x_px + v * (rh.x_px - rs.x_px), by = rs.y_px + v * (rh.y_px - rs.y_px);
            for (int j = 1; j < 6; j++) {
                double u = 0.2 + 0.6 * (j - 1) / 4.0;
                double x = ax + u * (bx - ax), y = ay + u * (by - ay);
                // a lateral view squeezes the quad: sample across the axis too
                for (int k = -1; k <= 1; k++) add_pixel(bgr, x + k * 0.08 * trunk, y, out[kLookTrunk], n);
            }
        }
        finish(out[kLookTrunk], n);
    }
    if (!std::isfinite(trunk) || trunk < 4.0) return;
    const double half = 0.07 * trunk;  // half a limb's width
    for (int p = 1; p < kLookParts; p++) {
        const gs_kp &a = kp[kSeg[p][0]], &b = kp[kSeg[p][1]];
        if (!usable(a, min_c) || !usable(b, min_c)) continue;
        double dx = b.x_px - a.x_px, dy = b.y_px - a.y_px, len = std::hypot(dx, dy);
        if (len < 2.0) continue;
        double nx = -dy / len, ny = dx / len;
        int n = 0;
        for (int i = 0; i < 10; i++) {
            double t = 0.15 + 0.7 * i / 9.0;
            for (int k = -1; k <= 1; k++)
                add_pixel(bgr, a.x_px + t * dx + k * half * nx, a.y_px + t * dy + k * half * ny, out[p], n);
        }
        finish(out[p], n);
    }
}

double pose_look_distance(const PoseLookHist &a, const PoseLookHist &b)
{
    if (!a.valid || !b.valid) return NAN;
    double bc = 0.0;
    for (int i = 0; i < kLookBins; i++) bc += std::sqrt(static_cast<double>(a.bin[i]) * b.bin[i]);
    return std::sqrt(std::max(0.0, 1.0 - std::min(1.0, bc)));
}

void PoseLook::forget()
{
    for (int p = 0; p < kLookParts; p++) {
        ref_[p] = PoseLookHist();
        count_[p] = 0;
    }
    n_ = 0;
}

void PoseLook::compare(const PoseLookHist now[kLookParts], double dist[kLookParts]) const
{
    for (int p = 0; p < kLookParts; p++)
        dist[p] = learnt() && count_[p] > 0 ? pose_look_distance(ref_[p], now[p]) : NAN;
}

void PoseLook::learn(const PoseLookHist now[kLookParts], const double dist[kLookParts])
{
    const bool follow = learnt();
    for (int p = 0; p < kLookParts; p++) {
        if (!now[p].valid) continue;
        if (follow && count_[p] > 0 && !(dist[p] < cfg_.max_dist)) continue;
        float w = follow && count_[p] > 0 ? static_cast<float>(cfg_.follow) : 1.0f / static_cast<float>(count_[p] + 1);
        for (int i = 0; i < kLookBins; i++) ref_[p].bin[i] += w * (now[p].bin[i] - ref_[p].bin[i]);
        ref_[p].valid = true;
        count_[p]++;
    }
    n_++;
}

}  // namespace gs
