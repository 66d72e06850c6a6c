// ball_detector.hpp - finds balls in free flight in a static camera's frames and
// measures their centre and size (sub-pixel) for the core's point layout.
//
// No colour is needed: candidates are compact blobs that differ from a running
// background (brighter or darker, any hue or none), or of a configured hue.
// They are linked across frames by a tracker whose motion model is the
// ballistic one, and a track is a ball only once a parabola of plausible
// acceleration (gravity's direction, a size of 1 cm to 1 m under g) explains
// its last candidates: a hand, a walker's head or a shadow that moves some
// other way is not reported. Each detection is measured at full resolution on
// a soft matte (alpha against the background along the ball's colour): the
// centre is the alpha centroid, the second moments give the width across the
// motion (which motion blur does not stretch) and, with the velocity, the
// size along any direction (ballistic.hpp). docs/ball.md has the details.
#ifndef GS_BALL_DETECTOR_HPP
#define GS_BALL_DETECTOR_HPP

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <cmath>

#include <opencv2/core.hpp>

extern "C" {
#include "gravscale/gs_config.h"
}

namespace gs {

// The [ball] section. Defaults: any colour (motion against the background).
struct BallConfig {
    bool color_auto = true;        // color = auto (any colour) | fixed (hue_deg given)
    double hue_deg = -1.0;         // 0..360 (OpenCV hue x 2); <0 unset
    double hue_tol_deg = 16.0;     // half-width of the hue band
    double sat_min = 0.25;         // 0..1, fixed colour only (auto learns its own)
    double val_min = 0.15;         // 0..1, fixed colour only
    double min_diameter_px = 4.0;  // full-resolution pixels
    double max_diameter_px = 0.0;  // 0: a third of the frame's smaller side
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
    int64_t frame = 0;   // the frame it was seen in (0-based count of process calls)
    double t_s = 0.0;    // that frame's time
    double x_px, y_px;   // centre, full-resolution pixels (alpha centroid; rolling shutter corrected)
    double diameter_px;  // across the motion; NaN when not measured well
    double diameter_kurt_px = NAN;  // the same from the 2nd and 4th moments: free of any Gaussian blur
    double psf_var_px2 = NAN;       // the blur's variance across the motion that implies
    double confidence;   // 0..1
    // the matte's second moments (px^2, the camera's blur still in), NaN when the
    // detection is no good for a size (at the frame's border, partly hidden, merged)
    double sxx = NAN, syy = NAN, sxy = NAN;
    // the moments are the ball's outline's (a ball of the background's chromaticity):
    // its sharp disc, without the camera's blur or the smear
    bool moments_blur_free = false;
};

class BallDetector {
public:
    explicit BallDetector(const BallConfig &cfg);
    ~BallDetector();
    BallDetector(const BallDetector &) = delete;
    BallDetector &operator=(const BallDetector &) = delete;

    // Every frame, in order (t_s increasing). out (cleared first) gets this
    // frame's balls; with set_backlog(true) also, when a track is first found to
    // be a ball, its earlier detections of the same flight (ordered by track,
    // then time: each track's times still increase from call to call).
    void process(const cv::Mat &bgr, double t_s, std::vector<BallObs> &out);
    void set_backlog(bool on);

    // Rolling shutter in use: seconds per row a ball's image is displaced by its
    // velocity times (row - rows/2); 0 when none was found (global shutter).
    double rolling_shutter_s_per_row() const;
    // time added to the stream's for frames the encoder dropped (the observations'
    // t_s include it)
    double clock_shift_s() const;

private:
    struct Impl;
    std::unique_ptr<Impl> p_;
};

// The detector's motion measure: per pixel the largest over the three channels of
// |img - background rounded to whole levels| (img CV_8UC3, bg CV_32FC3 of its size).
void max_channel_diff(const cv::Mat &img, const cv::Mat &bg, cv::Mat &out);

// cv::dilate(src, dst, MORPH_ELLIPSE of size 2r+1), the same pixels, by runs
// (src CV_8UC1; what lies outside src, even of a parent matrix, counts as empty).
void dilate_ellipse(const cv::Mat &src, cv::Mat &dst, int r);

}  // namespace gs

#endif
