// pose_look.hpp - what the tracked person looks like: a small colour histogram
// per body part (trunk, upper arms, forearms, thighs, shanks, feet), sampled
// along the keypoints' segments and learnt over the first accepted frames of a
// track. A part whose colours in a new frame are far from the learnt ones is
// covered by something else (a passer-by in front) or the keypoints lie on
// someone else; its keypoints must not reach the core. Used by PoseTracker
// (keep_person); tested in tests/test_pose_crossing.cpp.
#ifndef GS_POSE_LOOK_HPP
#define GS_POSE_LOOK_HPP

#include <opencv2/core.hpp>

extern "C" {
#include "gravscale/gs_types.h"
}

namespace gs {

enum PoseLookPart {
    kLookTrunk = 0,
    kLookUpperArmL, kLookUpperArmR, kLookForearmL, kLookForearmR,
    kLookThighL, kLookThighR, kLookShankL, kLookShankR, kLookFootL, kLookFootR,
    kLookParts
};

constexpr int kLookBins = 20;  // 8 hues x 2 saturations, 4 greys
struct PoseLookHist {
    float bin[kLookBins] = {0};
    bool valid = false;
};

struct PoseLookConfig {
    double max_dist = 0.5;  // Bhattacharyya distance above which a part is someone else's
    int learn_frames = 6;   // accepted frames averaged into the reference at the start of a track
    double min_c = 0.5;     // keypoints below this confidence are not sampled
    double follow = 0.25;   // afterwards a matching part moves its reference this far toward the new look
                            // (a body's look changes with its pose: the shirt rides up in the flight)
};

// The colours of each part at keypoints kp (BlazePose-33, image px) in an 8-bit BGR image.
void pose_look_sample(const cv::Mat &bgr, const gs_kp *kp, double min_c, PoseLookHist out[kLookParts]);
// Bhattacharyya distance 0 (same) .. 1 (disjoint); NaN when either is not valid
double pose_look_distance(const PoseLookHist &a, const PoseLookHist &b);
// keypoints that belong to a part (its far end and what hangs on it), -1 terminated
const int *pose_look_part_keypoints(int part);

class PoseLook {
public:
    explicit PoseLook(const PoseLookConfig &cfg = PoseLookConfig()) : cfg_(cfg) {}
    void forget();
    bool learnt() const { return n_ >= cfg_.learn_frames; }
    // distances of the parts of this frame from the reference (NaN unknown)
    void compare(const PoseLookHist now[kLookParts], double dist[kLookParts]) const;
    // average into the reference while it is being learnt; afterwards follow
    // the parts whose distance (from compare) is below max_dist
    void learn(const PoseLookHist now[kLookParts], const double dist[kLookParts]);
    const PoseLookConfig &config() const { return cfg_; }

private:
    PoseLookConfig cfg_;
    PoseLookHist ref_[kLookParts];
    int count_[kLookParts] = {0};
    int n_ = 0;
};

}  // namespace gs

#endif
