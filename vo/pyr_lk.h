#pragma once
// Pyramidal Lucas-Kanade tracking with the results of cv::calcOpticalFlowPyrLK (OpenCV 4.6, x86-64)
// bit for bit, its inner loop in AVX2.
//
// OpenCV's arithmetic (modules/video/src/lkpyramid.cpp, built for SSE2): bilinear weights rounded to
// 14 bits; the patch, its Scharr derivatives and the moving image interpolated in integers; the
// gradient matrix and the mismatch vector summed in float, the first 8 columns of each window row in
// four float lanes and the other columns one by one. Integer sums do not depend on their order, float
// sums do. Here the integers of a whole 15-pixel row are computed at once, and the floats are added in
// OpenCV's order, except where the magnitudes of the one-by-one terms sum to less than 2^24: then every
// partial sum is an exact integer and the order cannot change it. Points and statuses equal OpenCV's
// for pyramids from cv::buildOpticalFlowPyramid (unit tests PyrLk.*), so tracks do not change.
//
// The previous image's pyramid may come without its derivatives: OpenCV then computes the Scharr
// derivatives of every level in full on each call, PyrLk only those of each point's window (integers,
// calcScharrDeriv's values and border rule), which spares building and storing them for whole images
// (BuildPyrLkPyramid).

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace rovo {

// Whether PyrLk serves these arguments: the CPU has AVX2, the window is 15 pixels wide and 3 to 32
// high, and both pyramids are 8-bit gray with a border of at least the window on every level. They
// must come from cv::buildOpticalFlowPyramid, `from_pyramid` with or without its derivatives, with
// this window or a larger one: the exact-sum shortcut relies on Scharr derivatives (|value| <= 16 * 255).
bool PyrLkApplies(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid, cv::Size window);

// cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, from[0, n), to[0, n), status[0, n), cv::noArray(),
// window, max_level, criteria, flags) with the default minimum eigenvalue (1e-4): computed here where
// PyrLkApplies, by OpenCV elsewhere.
// Throws std::invalid_argument for max_level < 0 (OpenCV asserts).
// With cv::OPTFLOW_USE_INITIAL_FLOW in flags, `to` holds the starts.
void PyrLk(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid, const cv::Point2f* from,
           cv::Point2f* to, uint8_t* status, int n, cv::Size window, int max_level, const cv::TermCriteria& criteria,
           int flags);

// cv::buildOpticalFlowPyramid(image, *pyramid, window, max_level), with the derivatives only where
// PyrLk would hand the window to OpenCV (no AVX2, a window not 15 wide or not 3-32 high): the
// pyramid PyrLk tracks from fastest. Returns the number of levels above the base.
int BuildPyrLkPyramid(const cv::Mat& image, std::vector<cv::Mat>* pyramid, cv::Size window, int max_level);

}  // namespace rovo
