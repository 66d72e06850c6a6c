// camera_motion.hpp - is the camera still? Tracks background corners from frame
// to frame (pyramidal Lucas-Kanade on a reduced grey image) and chains the
// robust similarity transforms, so every frame gets the camera's displacement
// since the first frame. The method assumes a static camera: a handheld one
// adds its own acceleration to the body's, and this is how that gets noticed.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace gs {

struct CameraMotionConfig {
    int max_features = 150;        // background corners tracked
    double work_width_px = 640.0;  // frames are reduced to at most this width
    double min_spacing_px = 12.0;  // between corners, at the working width
    int min_inliers = 12;          // fewer: the frame's motion is unknown
    // something else moving next to a subject: corners in a ring around each
    // excluded region (its size x ring_rel beyond the region's own margin) that
    // move against the background's motion by more than other_px (full-frame px)
    double ring_rel = 0.5;
    int ring_features = 60;
    double other_px = 4.0;
};

// The camera's motion at one frame, in full-frame pixels.
struct CameraMotionFrame {
    bool valid = false;            // false: too few background corners matched
    double dx_px = 0.0;            // where the first frame's image centre is now, minus the centre
    double dy_px = 0.0;
    double rot_deg = 0.0;          // rotation since the first frame, clockwise on screen (y down)
    double scale = 1.0;            // zoom since the first frame
    double step_px = 0.0;          // displacement of the image centre since the previous frame
    int inliers = 0;
    int other = 0;                 // corners around the subjects moving against the background
};

// cv::resize(src, dst, Size(), f, f, INTER_AREA) for 8-bit grey and 0 < f <= 1,
// with the same pixels (OpenCV's area weights, summed in its order in float),
// without OpenCV's per-weight read-modify-write of one accumulator, which makes
// a non-integer reduction (720 -> 640 px) cost several times a whole-factor one.
void resize_area_grey(const cv::Mat &src, cv::Mat &dst, double f);
// cv::resize(src, dst, ds, 0, 0, INTER_AREA) for 8-bit images of any channels,
// with the same pixels and the same per-axis scales (the pose detector's input)
void resize_area(const cv::Mat &src, cv::Mat &dst, cv::Size ds);

// Scratch memory of good_features, kept from call to call.
struct CornerWork {
    cv::Mat dx, dy, eig;
    std::vector<double> box;
    std::vector<const float *> cand;
    std::vector<int> xs;
    std::vector<std::vector<cv::Point2f>> grid;
};

// cv::goodFeaturesToTrack(img, corners, max_corners, quality, min_distance, mask,
// block) (minimum eigenvalue, gradient 3, block 3 or 5) with the same corners in
// the same order: the eigenvalues' box sums in double in OpenCV's order (AVX2
// when the CPU has it), the candidates taken best first from a heap instead of
// all sorted.
void good_features(const cv::Mat &img, std::vector<cv::Point2f> &corners, int max_corners, double quality,
                   double min_distance, const cv::Mat &mask, int block, CornerWork &work);

// The Scharr derivative levels of a Lucas-Kanade pyramid, laid out as
// cv::buildOpticalFlowPyramid lays them out (CV_16SC2, the level's size plus a
// window-sized zero border on each side) and with the same values, computed
// only where cv::calcOpticalFlowPyrLK reads them: the windows around the points
// it is given, at every level. Tracking 150 corners on a 640 px wide frame
// reads about an eighth of the finest level, the largest and costliest.
class LkDerivatives {
public:
    // levels: the image levels (cv::buildOpticalFlowPyramid without derivatives),
    // whose derivatives start out not computed
    void reset(const std::vector<cv::Mat> &levels, cv::Size win);
    // computes the derivatives calcOpticalFlowPyrLK(pyramid(), ..., pts, ..., win)
    // reads at every level (those not computed yet)
    void cover(const std::vector<cv::Point2f> &pts);
    // [image 0, derivatives 0, image 1, derivatives 1, ...] for calcOpticalFlowPyrLK's previous pyramid
    const std::vector<cv::Mat> &pyramid() const { return pyr_; }

private:
    void cover_level(int level, const std::vector<cv::Point2f> &pts);
    void fill(int level, int x0, int x1, int y0, int y1);
    cv::Size win_;
    std::vector<cv::Mat> pyr_;          // images and derivative regions, interleaved
    std::vector<cv::Mat> bordered_;     // each level's derivatives with their zero border
    std::vector<std::vector<uchar>> done_;  // per level, per row, per span of 8 columns: computed
    std::vector<uchar> whole_;          // per level: all of it computed
};

class CameraMotion {
public:
    explicit CameraMotion(const CameraMotionConfig &cfg = CameraMotionConfig());
    // exclude: regions of moving subjects (full-frame pixels) kept out of the corners
    void process(const cv::Mat &bgr, const std::vector<cv::Rect> &exclude, CameraMotionFrame *out);
    // map a point of this frame into the first frame's coordinates (stabilised)
    cv::Point2d to_reference(cv::Point2d p) const;

private:
    int other_motion(const std::vector<cv::Mat> &pyr, const std::vector<cv::Rect> &ex, const cv::Mat &m) const;
    CameraMotionConfig cfg_;
    double scale_ = 1.0;           // working / full
    std::vector<cv::Mat> prev_pyr_; // previous working grey frame's Lucas-Kanade pyramid
    std::vector<cv::Mat> spare_pyr_; // the one before, whose memory the next pyramid takes
    mutable LkDerivatives prev_deriv_; // prev_pyr_'s derivatives, where Lucas-Kanade reads them
    cv::Mat grey_, cur_, mask_;     // this frame's grey, working image and corner mask
    mutable cv::Mat ring_mask_;     // other_motion's ring
    mutable CornerWork corner_work_;
    std::vector<cv::Point2f> pts_; // corners in prev_
    cv::Matx23d cur_from_ref_;     // full-frame pixels: reference -> current
    bool have_ = false;
    long frames_ = 0;
    cv::Size full_;
};

}  // namespace gs
