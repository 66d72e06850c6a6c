// warp_crop.hpp - the pose landmark network's input: the rotated crop,
// cv::warpAffine(src, dst, m, Size(side, side), INTER_LINEAR | WARP_INVERSE_MAP,
// BORDER_REPLICATE) for 8-bit BGR, with the same pixels, and its float blob.
// The crop uses OpenCV's own fixed-point arithmetic (the source position in 1/32
// pixel, its 15-bit bilinear weights, the rounding of the sum), the four taps of
// the three channels in two multiply-adds per pixel on CPUs with AVX2 (a 256 x
// 256 crop of a 720 x 1280 frame, a third of it beyond the border: 4.2 instead
// of 5.9 million instructions), with the source lines of the rows ahead
// prefetched, since a rotated ROI's reads jump between source rows and would
// wait on memory (0.74 instead of 1.3-1.5 ms a crop of a frame not in cache,
// about 0.7 ms either way when it is); elsewhere cv::warpAffine itself.
#pragma once

#include <opencv2/core.hpp>

namespace gs {

// m: 2 x 3 doubles, destination pixel -> source pixel (as WARP_INVERSE_MAP takes it)
void warp_crop_bgr(const cv::Mat &src, const cv::Mat &m, int side, cv::Mat &dst);

// cv::dnn::blobFromImage(bgr, blob, scale, Size(), Scalar(), true, false, CV_32F)
// for 8-bit BGR, with the same floats: 1 x 3 x rows x cols, planes R, G, B, each
// byte times scale rounded to a float; blob's memory is kept when its shape is.
void bgr_to_rgb_blob(const cv::Mat &bgr, double scale, cv::Mat &blob);

}  // namespace gs
