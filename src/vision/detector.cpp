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

// One person: BlazePose keypoints for the core's BlazePose-33 layout (c = 0 when
// nobody is seen). A mounted camera is static: no stabilisation here (the video
// command's PersonFront adds it, with the feet timing, for recorded clips).
class PoseDet : public Detector {
public:
    explicit PoseDet(const PoseConfig &c) : pose_(c) {}
    bool ok(std::string &err) const
    {
        if (pose_.ok()) return true;
        err = "pose networks: " + pose_.error();
        return false;
    }
    gs_layout layout() const override { return GS_LAYOUT_BLAZEPOSE33; }
    void process(const cv::Mat &bgr, double t_s, std::vector<DetectorObs> &out) override
    {
        out.clear();
        PoseOutput po;
        pose_.process(bgr, t_s, &po);
        DetectorObs o;
        o.track = 0;
        o.confidence = po.present ? po.presence : 0.0;
        o.kp.assign(po.kp, po.kp + kPoseKeypoints);
        if (!po.present)
            for (gs_kp &k : o.kp) k.c = 0.0f;
        out.push_back(o);  // every frame, so the core sees absences (visits end)
    }

private:
    PoseTracker pose_;
};

}  // namespace

bool detector_known(const std::string &name) { return name == "ball" || name == "pose"; }
const char *detector_names() { return "ball, pose"; }
bool detector_is_small_object(const std::string &name) { return name == "ball"; }

void detector_config_sections(DetectorConfigs &c, std::vector<gs_cfg_section> &out)
{
    out.push_back({"ball", ball_config_set, &c.ball});
    out.push_back({"pose", pose_config_set, &c.pose});
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
    if (name == "pose") {
        std::string merr;
        if (!pose_models_present(c.pose, merr)) {
            err = merr;
            return nullptr;
        }
        auto d = std::make_unique<PoseDet>(c.pose);
        if (!d->ok(err)) return nullptr;
        return d;
    }
    err = "unknown detector '" + name + "' (" + detector_names() + ")";
    return nullptr;
}

}  // namespace gs
