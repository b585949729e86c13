#pragma once
// Integer sums over small image patches, the inner loops of the front-end's matching (ZNCC) and of its
// ORB orientation (intensity centroid). Each has a portable form and an AVX2 form chosen at run time
// (the build targets baseline x86-64); both return the same integers, so the results never depend on
// the machine.

#include <cstdint>
#include <opencv2/core.hpp>

namespace rovo {

// Reference rows of at most this many pixels (ZNCC patches up to 16 px wide).
constexpr int kPatchRowPixels = 16;

// Sums of a side x side patch b of `image` with top-left (x0, y0) against a reference a given as
// `side` rows of kPatchRowPixels int16 values, zero beyond `side`: sum a*b, sum b, sum b^2.
struct PatchSums {
  int32_t ab = 0, b = 0, bb = 0;
};
// Requires 1 <= side <= kPatchRowPixels, the patch inside the image and x0 + kPatchRowPixels <= cols
// (each row is read as kPatchRowPixels bytes).
PatchSums PatchSumsAgainst(const int16_t* reference_rows, const cv::Mat& image, int x0, int y0, int side);

// First moments of the disc of radius kDiscRadius around the pixel (cx, cy) of an 8-bit image:
// m10 = sum dx I(cx + dx, cy + dy), m01 = sum dy I(...), over |dy| <= kDiscRadius and
// |dx| <= DiscHalfWidth(|dy|) = floor(sqrt(r^2 - dy^2)), pixels outside the image left out.
constexpr int kDiscRadius = 15;
int DiscHalfWidth(int dy);
struct DiscMoments {
  int64_t m10 = 0, m01 = 0;
};
DiscMoments DiscMomentsAt(const cv::Mat& image, int cx, int cy);

// The two forms behind the functions above, for tests (the AVX2 ones only where CpuHasAvx2(), vo/cpu_dispatch.h;
// DiscMomentsAvx2 only where its 32-byte rows lie inside the image: DiscMomentsAvx2Fits).
namespace patch_kernels_internal {
PatchSums PatchSumsPortable(const int16_t* reference_rows, const cv::Mat& image, int x0, int y0, int side);
PatchSums PatchSumsAvx2(const int16_t* reference_rows, const cv::Mat& image, int x0, int y0, int side);
DiscMoments DiscMomentsPortable(const cv::Mat& image, int cx, int cy);
bool DiscMomentsAvx2Fits(const cv::Mat& image, int cx, int cy);
DiscMoments DiscMomentsAvx2(const cv::Mat& image, int cx, int cy);
}  // namespace patch_kernels_internal

}  // namespace rovo
