// lk_track.hpp - pyramidal Lucas-Kanade with cv::calcOpticalFlowPyrLK's points and status.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace gs {

// cv::calcOpticalFlowPyrLK(prev_pyr, next_pyr, from, to, status, cv::noArray(), win, max_level)
// with its default criteria (30 iterations, 0.01 px), flags 0 and minimum eigenvalue 1e-4:
// the same points and status bit for bit. prev_pyr: each level's image and its Scharr
// derivatives (buildOpticalFlowPyramid's layout with derivatives); next_pyr: the images.
// A 21x21 window on a CPU with AVX2 runs its own loop (integer interpolation sixteen
// pixels at a time, OpenCV's float sums in OpenCV's order); anything else runs OpenCV's.
void lk_track(const std::vector<cv::Mat> &prev_pyr, const std::vector<cv::Mat> &next_pyr,
              const std::vector<cv::Point2f> &from, std::vector<cv::Point2f> &to, std::vector<uchar> &status,
              cv::Size win, int max_level);

}  // namespace gs
