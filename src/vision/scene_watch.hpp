// scene_watch.hpp - what the core cannot see from keypoints alone: whether the
// camera moved, the body touched the frame's border, or the body moved toward
// or away from the camera. Per-frame facts are recorded as frames pass; a
// flight's warning bits (GS_WARN_CAMERA_MOVED, _LEFT_FRAME, _OUT_OF_PLANE,
// _OTHER_MOTION) are
// judged over its window when the core reports it, and live warnings (a
// condition that starts) are given once per onset for guidance.
#pragma once

#include <cstdint>
#include <deque>

namespace gs {

struct SceneFrame {
    double t_s = 0.0;
    bool cam_valid = true;       // the camera's motion is known this frame
    double cam_dx_px = 0.0;      // camera displacement since the first frame (image centre)
    double cam_dy_px = 0.0;
    bool present = false;        // a body was detected
    bool at_border = false;      // head or feet at (or beyond) the frame's border
    double ground_y_px = 0.0;    // the feet's row (NaN unknown)
    double size_px = 0.0;        // body size this frame (NaN unknown), for thresholds
    int other = 0;               // corners right around the body moving against the background
};

struct SceneWatchConfig {
    double cam_moved_rel = 0.01;   // camera displacement within a flight above this x body size
    double cam_moved_min_px = 2.0; // ... and above this many pixels
    double depth_rel = 0.04;       // feet's row before take-off vs after landing: above this x body size
    double margin_s = 0.1;         // the window reaches this far beyond take-off and landing
    int other_corners = 6;         // a frame with this many corners moving beside the body sees other motion
    int other_frames = 3;          // ... in this many frames of the window: GS_WARN_OTHER_MOTION
    double other_reject = 0.25;    // ... in this share of the window's frames (and other_frames): reject
};

class SceneWatch {
public:
    explicit SceneWatch(const SceneWatchConfig &cfg = SceneWatchConfig()) : cfg_(cfg) {}
    void add(const SceneFrame &f);
    // GS_WARN_* bits for a flight from t_takeoff_s to t_land_s (NaN ends: the apex +- 0.3 s)
    uint32_t flight_warnings(double t_takeoff_s, double t_land_s, double t_apex_s) const;
    // frames of the flight's window that saw other motion beside the body, and all its frames
    int other_motion(double t_takeoff_s, double t_land_s, double t_apex_s, int *frames) const;
    // the flight is not to be trusted: other motion through other_reject of its window
    bool other_rejects(double t_takeoff_s, double t_land_s, double t_apex_s) const;
    // bits of conditions that started with the newest frame (each reported once per onset)
    uint32_t onsets();

private:
    SceneWatchConfig cfg_;
    std::deque<SceneFrame> frames_;  // the last few seconds
    uint32_t active_ = 0;
};

}  // namespace gs
