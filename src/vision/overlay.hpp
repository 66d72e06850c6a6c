// overlay.hpp - what a video run saw, and pictures of it: the detections,
// the flight windows, the fitted parabolas and the numbers drawn on frames (a
// video or a PNG contact sheet), and a plot of the tracked centre against time
// with the fits. OpenCV drawing only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace gs {

struct ObsRecord {
    int track;
    double x_px, y_px, diameter_px, confidence;
};

// One flight as the core reported it, plus a parabola fitted here (for
// drawing) to the observations inside its window.
struct JumpRecord {
    uint32_t track = 0, index = 0;
    double t_takeoff_s = NAN, t_land_s = NAN, t_apex_s = NAN;
    double a_px_s2 = NAN, g_dir_deg = NAN, q_m_per_px = NAN, size_px = NAN, height_m = NAN;
    bool accepted = false;
    std::string reason;
    double running_height_m = NAN;  // the track's aggregate after this flight (accepted ones)
    uint32_t running_n = 0;
    // drawing fit: x(t) = x0 + vx (t - t0) + ax/2 (t - t0)^2, same for y
    bool has_curve = false;
    double t0_s = 0, x0 = 0, vx = 0, ax = 0, y0 = 0, vy = 0, ay = 0;
};

struct SummaryRecord {
    uint32_t track = 0;
    double height_m = NAN, lo_m = NAN, hi_m = NAN;
    uint32_t n_jumps = 0, n_rejected = 0;
};

struct RunRecord {
    std::string source;       // file name shown in titles
    double fps = NAN;
    std::string fps_origin;
    cv::Size frame_size;
    std::vector<double> frame_t;                  // real time of each frame
    std::vector<std::vector<ObsRecord>> frame_obs;  // detections of each frame
    std::vector<JumpRecord> jumps;
    std::vector<SummaryRecord> summaries;
    bool person = false;                          // pose runs: a person's COM and skeleton
    std::vector<std::vector<cv::Point3f>> frame_kp;  // pose: 33 keypoints (x, y, confidence) per frame, or none
};

// Fit each jump's drawing parabola to the observations inside its window.
void fit_jump_curves(RunRecord &r);

// Draw everything known at frame `index` onto bgr (in place).
void draw_overlay(cv::Mat &bgr, const RunRecord &r, int64_t index);

// Frames for a contact sheet: take-off, apex and landing of each flight (at
// most max_tiles, then only apexes), or evenly spread when there was none.
std::vector<int64_t> contact_sheet_frames(const RunRecord &r, size_t max_tiles);

// The overlay output: a video (.avi MJPG, .mp4/.mov MPEG-4, .mkv FFV1) or,
// for .png/.jpg, a contact sheet of the frames contact_sheet_frames() picks.
class OverlayWriter {
public:
    static bool is_sheet_path(const std::string &path);
    // false with a reason in err
    bool open(const std::string &path, const RunRecord &r, double play_fps, std::string &err);
    bool wants(int64_t index) const;       // should this frame be drawn and added?
    bool add(const cv::Mat &drawn_bgr, int64_t index, std::string &err);
    bool close(std::string &err);          // writes the sheet

private:
    std::string path_;
    bool sheet_ = false;
    cv::VideoWriter video_;
    std::vector<int64_t> pick_;
    std::vector<cv::Mat> tiles_;
};

// The tracked centre against time (up = against image y) with the flight
// windows, the fitted parabolas and the numbers. false with a reason.
bool write_plot(const RunRecord &r, const std::string &path, std::string &err);

}  // namespace gs
