#pragma once
// `rovo bench vo --floor`: the front-end's CPU per frame against the bare OpenCV calls it is made of.

#include "vo/vo_options.h"

namespace rovo {

// Per frame of options.io.frames (decoded beforehand): the front-end (Frontend::Process with the
// run's threads and front-end options, GTExt) and, on the same images on one thread, the floor: per
// view cv::remap with the warp's fixed-point maps (in bands of rows, as the front-end), cv::buildOpticalFlowPyramid,
// cv::calcOpticalFlowPyrLK of the previous frame's points with a backward pass from scratch, cv::FAST
// and ORB::compute of the strongest target_features_per_view corners; per pair of neighbouring views
// a k = 2 Hamming matching (cv::BFMatcher) both ways between the halves of the two views that face
// each other. The same parameters as the front-end's (window, levels, iterations, epsilon, FAST
// threshold, ORB settings). Prints CPU ms per frame of both, by stage, and their ratio, with the
// machine reference of `rovo bench vo`.
void RunVoFloorBenchmark(VoOptions options);

}  // namespace rovo
