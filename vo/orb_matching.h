#pragma once
// Brute-force matching of ORB descriptors (256 bits) with Lowe's ratio test both ways and a mutual
// check, for the start-up calibration's overlap views (ring_calibration.h).
//
// Equivalent to cv::BFMatcher(NORM_HAMMING)::knnMatch with k = 2 from a to b and from b to a, but every
// distance is computed once (each row's and each column's two nearest kept in one sweep) with the
// CPU's popcount: on 6000 x 6000 descriptors about a sixth of the two OpenCV calls' CPU time
// (orb_matching_benchmark.cc). Results are the same except where two candidates tie at distance 0.

#include <opencv2/core.hpp>
#include <utility>
#include <vector>

namespace rovo {

// (row in desc_a, row in desc_b) pairs: the nearest of each other, nearer than `max_distance` bits and
// than `max_ratio` times the second nearest, both ways. Descriptors: CV_8U rows of 32 bytes.
std::vector<std::pair<int, int>> MutualRatioOrbMatches(const cv::Mat& desc_a, const cv::Mat& desc_b, double max_ratio,
                                                       int max_distance);

}  // namespace rovo
