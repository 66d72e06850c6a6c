// detector.cpp - the detector switch of `gravscale cam`.
#include "detector.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace gs {

Detector::~Detector() = default;

namespace {

class BallDet : public Detector {
public:
    explicit BallDet(const BallConfig &c) : det_(c) {}
    gs_layout layout() const override { return GS_LAYOUT_POINT; }
    void process(const cv::Mat &bgr, double t_s, std::vector<DetectorObs> &out) override
    {
        out.clear();
        det_.process(bgr, t_s, balls_);
        for (const BallObs &b : balls_) {
            if (b.track < 0) continue;
            DetectorObs o;
            o.track = b.track;
            o.x_px = b.x_px;
            o.y_px = b.y_px;
            o.size_px = b.diameter_px;
            o.confidence = b.confidence;
            out.push_back(o);
        }
    }

private:
    BallDetector det_;
    std::vector<BallObs> balls_;
};

}  // namespace

bool detector_known(const std::string &name) { return name == "ball"; }
const char *detector_names() { return "ball"; }
bool detector_is_small_object(const std::string &name) { return name == "ball"; }

void detector_config_sections(DetectorConfigs &c, std::vector<gs_cfg_section> &out)
{
    out.push_back({"ball", ball_config_set, &c.ball});
}

bool detector_config_check(const DetectorConfigs &c, gs_cfg_error &e)
{
    if (ball_config_check(c.ball, e.msg, sizeof e.msg) != GS_OK) {
        std::snprintf(e.section, sizeof e.section, "ball");
        return false;
    }
    return true;
}

std::unique_ptr<Detector> make_detector(const std::string &name, const DetectorConfigs &c, std::string &err)
{
    if (name == "ball") return std::make_unique<BallDet>(c.ball);
    if (name == "pose")
        err = "the pose detector is not in this build yet (detector = ball)";
    else
        err = "unknown detector '" + name + "' (" + detector_names() + ")";
    return nullptr;
}

}  // namespace gs
