// ball_detector.hpp - finds balls in free flight in a static camera's frames and
// measures their centre and diameter (sub-pixel) for the core's point layout.
//
// With no configuration the detector learns the ball's colour by itself: a
// moving, round, saturated blob whose track bends down like a thrown or
// dropped object fixes the hue; from then on it segments that colour (HSV)
// where the frame differs from a running background. Each detection is
// measured at full resolution on a soft matte (alpha against the background
// along the ball's colour): the centre is the alpha centroid, the diameter is
// 4 x sqrt(smallest eigenvalue of the alpha covariance), i.e. the width across
// the motion, which motion blur does not stretch. docs/ball.md has the details.
#ifndef GS_BALL_DETECTOR_HPP
#define GS_BALL_DETECTOR_HPP

#include <cstddef>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

extern "C" {
#include "gravscale/gs_config.h"
}

namespace gs {

// The [ball] section. Defaults: colour learned automatically.
struct BallConfig {
    bool color_auto = true;        // color = auto | fixed (hue_deg given)
    double hue_deg = -1.0;         // 0..360 (OpenCV hue x 2); <0 unset
    double hue_tol_deg = 16.0;     // half-width of the hue band
    double sat_min = 0.25;         // 0..1, fixed colour only (auto learns its own)
    double val_min = 0.15;         // 0..1, fixed colour only
    double min_diameter_px = 6.0;  // full-resolution pixels
    double max_diameter_px = 400.0;
    int max_balls = 4;             // tracks followed at once
    bool roi_set = false;          // roi = x,y,w,h (full-resolution pixels) | full
    int roi_x = 0, roi_y = 0, roi_w = 0, roi_h = 0;
    double motion_min = 18.0;      // 1..255: colour difference to the background that counts as motion
    double max_blur_ratio = 1.6;   // length/width above which no diameter is given
    double psf_sigma_px = 1.0;     // the camera's own blur (lens, demosaicing, compression), 1 sigma:
                                   // its variance is taken off the ball's across-motion variance
};

// gs_cfg_handler for [ball]; ctx is a BallConfig*.
gs_status ball_config_set(void *ctx, const char *key, size_t key_len, const char *value,
                          size_t value_len, char *msg, size_t cap);
// Cross-key checks after parsing (color = fixed needs hue_deg, diameter range).
gs_status ball_config_check(const BallConfig &cfg, char *msg, size_t cap);

struct BallObs {
    int track;           // 0.. (lowest id not held by another live track)
    double x_px, y_px;   // centre, full-resolution pixels (alpha centroid)
    double diameter_px;  // across the motion; NaN when not measured well
    double confidence;   // 0..1
};

class BallDetector {
public:
    explicit BallDetector(const BallConfig &cfg);
    ~BallDetector();
    BallDetector(const BallDetector &) = delete;
    BallDetector &operator=(const BallDetector &) = delete;

    // Every frame, in order (t_s increasing). Appends this frame's balls to out
    // (out is cleared first).
    void process(const cv::Mat &bgr, double t_s, std::vector<BallObs> &out);

    // The colour in use: true once known (configured or learned); hue in degrees.
    bool color_known(double *hue_deg = nullptr, double *sat_min = nullptr,
                     double *val_min = nullptr) const;

private:
    struct Impl;
    std::unique_ptr<Impl> p_;
};

}  // namespace gs

#endif
