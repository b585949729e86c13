#pragma once
// How well calibrations explain each frame's own overlap matches (`rovo study calibration
// --fit-frames`): evidence for or against a rig's calibration file when no frame is ground truth.
//
// Per listed frame, the ring's overlap matches of that shot alone (views placed by the dataset's rig,
// KLT-refined as in the start-up's later passes) are judged (RingCalibrator::Fit) by three
// calibrations: the dataset's as given; the dataset's extrinsics with the lenses' angle scale that the
// converged start-up results estimated (their median), which tells whether the lens correction
// carries over to frames that did not produce it; and each converged start-up result itself. A
// calibration that explains more matches with smaller residuals, on frames that did not produce it,
// fits the images better.

#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/rigid3.h"

namespace rovo {

struct FitCalibration {
  std::vector<Rigid3> cam_from_rig;
  double angle_scale = 1.0;
};

// How one calibration explains a set of matches.
struct FitScore {
  int inliers = 0;           // epipolar residual below the start-up's inlier threshold, in front of both
  double median_deg = -1.0;  // median |epipolar residual| over all the matches; -1: no match
};

// One ring pair of one frame (camera_a = camera_b = -1: all pairs of the frame).
struct OverlapFitRow {
  int frame = 0;
  int camera_a = -1, camera_b = -1;
  int matches = 0;
  FitScore given;         // the dataset's calibration
  FitScore given_scaled;  // its extrinsics with the results' median angle scale
  FitScore results;       // per result, then the median over results
};

struct OverlapFit {
  int results = 0;                  // converged start-up results judged (0: none; the other scores stay -1 / 0)
  double angle_scale = 1.0;         // the median of their angle scales
  std::vector<OverlapFitRow> rows;  // per frame: its pairs, then the frame's total
};

OverlapFit FitOverlaps(const std::string& dataset_dir, const DatasetInfo& info, const std::vector<int>& frames,
                       const std::vector<FitCalibration>& results);

// Markdown table of `fit`.
std::string OverlapFitTable(const OverlapFit& fit);

}  // namespace rovo
