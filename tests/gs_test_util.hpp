// gs_test_util.hpp - helpers shared by the C++ end-to-end tests (header-only):
// running the program through the shell and capturing its stdout, reading the
// JSON lines it prints, files, and the rendered ball scene of test_video and
// test_cam. Include after unity.h; everything is in namespace gs_test.
#ifndef GS_TEST_UTIL_HPP
#define GS_TEST_UTIL_HPP

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <opencv2/core.hpp>

extern "C" {
#include "unity.h"
}

namespace gs_test {

// ---- files ----------------------------------------------------------------------

// A scratch file of this process: two test runs at once (a developer's and CI's,
// or two build trees) must not read each other's files.
inline std::string tmp_path(const char *name)
{
    return "/tmp/" + std::string(name) + "." + std::to_string(static_cast<long>(getpid()));
}

inline bool exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

// the whole file ("" when it cannot be opened)
inline std::string slurp(const std::string &path)
{
    FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) return "";
    std::string s;
    char buf[65536];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
    std::fclose(f);
    return s;
}

// ---- running the program through the shell ------------------------------------------

struct Run {
    int code = -1;
    std::string out;
};

// `cmd 2>stderr_to` through the shell (stderr_to: a file, or /dev/null); stdout
// captured. The exit code, or 128 when the program did not exit normally.
inline Run run_shell(const std::string &cmd, const std::string &stderr_to)
{
    std::string line = cmd + " 2>" + stderr_to;
    Run r;
    FILE *p = popen(line.c_str(), "r");
    TEST_ASSERT_NOT_NULL(p);
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
    int st = pclose(p);
    r.code = WIFEXITED(st) ? WEXITSTATUS(st) : 128;
    return r;
}

// ---- the JSON lines ------------------------------------------------------------------

enum LinesFlags : unsigned {
    kAnywhere = 0u,       // "event":"<event>" anywhere in the line; a last line without '\n' counts
    kAtLineStart = 1u,    // the line must begin with {"event":"<event>"
    kWholeLinesOnly = 2u  // a last line without '\n' (still being written) is left out
};

// the lines of one event type
inline std::vector<std::string> lines_of(const std::string &out, const std::string &event, unsigned flags = kAnywhere)
{
    std::vector<std::string> v;
    const bool at_start = (flags & kAtLineStart) != 0, whole_only = (flags & kWholeLinesOnly) != 0;
    std::string pat = std::string(at_start ? "{" : "") + "\"event\":\"" + event + "\"";
    size_t p = 0;
    while (p < out.size()) {
        size_t nl = out.find('\n', p);
        if (nl == std::string::npos) {
            if (whole_only) break;
            nl = out.size();
        }
        std::string line = out.substr(p, nl - p);
        if (at_start ? line.compare(0, pat.size(), pat) == 0 : line.find(pat) != std::string::npos) v.push_back(line);
        p = nl + 1;
    }
    return v;
}

// the number after "key": (NaN when null or absent)
inline double num(const std::string &line, const char *key)
{
    std::string pat = std::string("\"") + key + "\":";
    size_t k = line.find(pat);
    if (k == std::string::npos) return NAN;
    const char *s = line.c_str() + k + pat.size();
    char *end;
    double v = std::strtod(s, &end);
    return end == s ? NAN : v;
}

// ---- the rendered ball scene: a ball thrown n times on a grey background -------------
// Known truth: a ball of known diameter at a known scale q (m/px) under
// g = 9.81, so a_px = g / q. The tests add their frame rates to it.

struct BallScene {
    int width = 640, height = 480;
    double q_m_per_px = 0.004;  // scale at the ball
    double diameter_m = 0.08;   // 20 px
    int n_throws = 3;
    double flight_s = 0.8;  // real flight time of each throw
    double rest_s = 0.5;    // resting before each throw and at the end
    double empty_s = 0.3;   // the background alone at the start
    double x0_px = 150.0, y_rest_px = 400.0, drift_px_s = 100.0;
};

constexpr double kSceneG = 9.81;

inline double a_px(const BallScene &s) { return kSceneG / s.q_m_per_px; }
inline double d_px(const BallScene &s) { return s.diameter_m / s.q_m_per_px; }

// Ball centre at real time t; false once the scene is over.
inline bool ball_at(const BallScene &s, double t_clip, double &x, double &y, bool &visible)
{
    visible = t_clip >= s.empty_s;
    const double t = std::max(0.0, t_clip - s.empty_s);
    const double a = a_px(s), v_up = 0.5 * a * s.flight_s, cycle = s.rest_s + s.flight_s;
    int k = static_cast<int>(std::floor(t / cycle));
    if (k > s.n_throws) return false;
    double x_base = s.x0_px + s.drift_px_s * s.flight_s * std::min(k, s.n_throws);
    double tc = t - k * cycle;
    x = x_base;
    y = s.y_rest_px;
    if (k == s.n_throws) return tc <= s.rest_s;
    if (tc > s.rest_s) {
        double tf = tc - s.rest_s;
        y = s.y_rest_px - v_up * tf + 0.5 * a * tf * tf;
        x = x_base + s.drift_px_s * tf;
    }
    return true;
}

// A disc of exactly this centre and radius: each pixel blended by its covered
// fraction (16 x 16 sub-samples). cv::circle's anti-aliased disc is about half a
// pixel too wide, which alone would bias a 50 px diameter by 2.5 %.
inline void draw_disc(cv::Mat &img, double cx, double cy, double r, cv::Vec3b color)
{
    const int ss = 16;
    int x0 = std::max(0, static_cast<int>(std::floor(cx - r - 1))), x1 = std::min(img.cols - 1, static_cast<int>(std::ceil(cx + r + 1)));
    int y0 = std::max(0, static_cast<int>(std::floor(cy - r - 1))), y1 = std::min(img.rows - 1, static_cast<int>(std::ceil(cy + r + 1)));
    for (int y = y0; y <= y1; y++) {
        for (int x = x0; x <= x1; x++) {
            int in = 0;
            for (int j = 0; j < ss; j++) {
                double py = y + (j + 0.5) / ss - 0.5 - cy;  // pixel (x, y) covers [x-0.5, x+0.5)
                for (int i = 0; i < ss; i++) {
                    double px = x + (i + 0.5) / ss - 0.5 - cx;
                    in += px * px + py * py <= r * r;
                }
            }
            if (in == 0) continue;
            double a = static_cast<double>(in) / (ss * ss);
            cv::Vec3b &p = img.at<cv::Vec3b>(y, x);
            for (int c = 0; c < 3; c++) p[c] = cv::saturate_cast<uchar>(a * color[c] + (1 - a) * p[c]);
        }
    }
}

}  // namespace gs_test

#endif  // GS_TEST_UTIL_HPP
