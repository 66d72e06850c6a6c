// detector.hpp - what `gravscale cam` runs on each frame: a ball detector or
// the BlazePose network (one person). Each detector has a name, an optional config section
// and a layout for the core; adding one is a field in DetectorConfigs, its
// section in detector_config_sections() and a case in make_detector().
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "ball_detector.hpp"
#include "pose_blazepose.hpp"

extern "C" {
#include "gravscale/gs_config.h"
#include "gravscale/gs_types.h"
}

namespace gs {

// One tracked object in one frame.
struct DetectorObs {
    int track = 0;                  // pipeline index (0..)
    double x_px = 0, y_px = 0;      // GS_LAYOUT_POINT: the point
    double size_px = 0;             // GS_LAYOUT_POINT: its size (NaN unknown)
    double confidence = 0;
    std::vector<gs_kp> kp;          // body layouts: gs_layout_kp_count(layout) keypoints
};

class Detector {
public:
    virtual ~Detector();
    virtual gs_layout layout() const = 0;
    // Every frame in order; out is cleared first.
    virtual void process(const cv::Mat &bgr, double t_s, std::vector<DetectorObs> &out) = 0;
};

// The configuration sections of every detector ([ball], later [pose]).
struct DetectorConfigs {
    BallConfig ball;
    PoseConfig pose;
};

// Names accepted by [cam] detector and --detector.
bool detector_known(const std::string &name);
const char *detector_names();  // "ball, pose" (for messages)
// A detector of a small object gets a small plausible size range ([core] size_min_m/size_max_m defaults).
bool detector_is_small_object(const std::string &name);

// The sections, appended to the caller's table for gs_cfg_parse.
void detector_config_sections(DetectorConfigs &c, std::vector<gs_cfg_section> &out);
// Cross-key checks after parsing; false with section and msg filled.
bool detector_config_check(const DetectorConfigs &c, gs_cfg_error &e);

// nullptr with err when name is unknown or the detector cannot start.
std::unique_ptr<Detector> make_detector(const std::string &name, const DetectorConfigs &c, std::string &err);

}  // namespace gs
