// ball_outline.hpp - a ball's outline from the step of |I - B| along rays.
//
// Where the ball and the background share one chromaticity (a grey, white,
// black or steel ball), its shading decides the sign and size of I - B inside
// the ball, but at its edge the image still steps from the ball's own colour
// to the background: the half level of that step lies on the outline whatever
// the shading, and (for a smear shorter than the radius) whatever the motion.
#pragma once

#include <opencv2/core.hpp>

namespace gs {

struct BallOutline {
    bool ok = false;            // enough rays with contrast, around the whole ball, and an ellipse fits them
    int rays = 0;               // rays cast
    int rays_contrast = 0;      // rays whose edge steps clearly above the noise
    double cx = 0, cy = 0;      // the fitted ellipse's centre (the ROI's pixels)
    double sxx = 0, syy = 0, sxy = 0;  // covariance of the uniform ellipse (px^2)
    double rms_px = 0;          // the inlier rays' radial residual
};

// the uniform ellipse's covariance's eigenvalues (px^2): D^2 / 16 along its axes
double ellipse_major(const BallOutline &o);
double ellipse_minor(const BallOutline &o);

// I: the frame's ROI (CV_8UC3); B: the background there (CV_32FC3); (x0, y0) a
// point inside the ball; r_guess_px its rough radius; ramp_px how far inside the
// edge its ramp reaches (blur and smear); psf_sigma_px the camera's blur.
BallOutline ball_outline(const cv::Mat &I, const cv::Mat &B, double x0, double y0, double r_guess_px,
                         double ramp_px, double psf_sigma_px);

}  // namespace gs
