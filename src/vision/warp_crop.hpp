// warp_crop.hpp - the pose landmark network's rotated crop: cv::warpAffine(src,
// dst, m, Size(side, side), INTER_LINEAR | WARP_INVERSE_MAP, BORDER_REPLICATE)
// for 8-bit BGR, with the same pixels. OpenCV's own fixed-point arithmetic (the
// source position in 1/32 pixel, its 15-bit bilinear weights, the rounding of
// the sum), the four taps of the three channels in two multiply-adds per pixel
// on CPUs with AVX2 (a 256 x 256 crop of a 720 x 1280 frame, a third of it
// beyond the border: 4.2 instead of 5.9 million instructions); elsewhere
// cv::warpAffine itself.
#pragma once

#include <opencv2/core.hpp>

namespace gs {

// m: 2 x 3 doubles, destination pixel -> source pixel (as WARP_INVERSE_MAP takes it)
void warp_crop_bgr(const cv::Mat &src, const cv::Mat &m, int side, cv::Mat &dst);

}  // namespace gs
