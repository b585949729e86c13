#include "eval/studies/overlap_fit.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "vo/image_loader.h"
#include "vo/ring_calibration.h"
#include "vo/startup_calibration.h"

namespace rovo {
namespace {

template <typename T>
T Median(std::vector<T> v) {
  if (v.empty()) return T(-1);
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The score of `fits` (one per pair) over pair `k`, or over every pair when k < 0.
FitScore Score(const std::vector<RingPairFit>& fits, int k) {
  FitScore s;
  std::vector<double> residuals;
  for (int i = 0; i < static_cast<int>(fits.size()); ++i) {
    if (k >= 0 && i != k) continue;
    s.inliers += fits[i].inliers;
    residuals.insert(residuals.end(), fits[i].residuals_deg.begin(), fits[i].residuals_deg.end());
  }
  s.median_deg = Median(residuals);
  return s;
}

// The median over results of their scores.
FitScore MedianScore(const std::vector<std::vector<RingPairFit>>& by_result, int k) {
  std::vector<int> inliers;
  std::vector<double> medians;
  for (const auto& fits : by_result) {
    const FitScore s = Score(fits, k);
    inliers.push_back(s.inliers);
    medians.push_back(s.median_deg);
  }
  return {by_result.empty() ? 0 : Median(inliers), Median(medians)};
}

std::string Deg3(double v) {
  if (v < 0.0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

std::string Cells(const FitScore& s, bool present) {
  if (!present) return " - | - |";
  return " " + std::to_string(s.inliers) + " | " + Deg3(s.median_deg) + " |";
}

}  // namespace

OverlapFit FitOverlaps(const std::string& dataset_dir, const DatasetInfo& info, const std::vector<int>& frames,
                       const std::vector<FitCalibration>& results) {
  const StartupCalibrationOptions startup;
  RingCalibrationOptions options = startup.ring;
  options.refine_matches = startup.refine_second_pass;
  const std::vector<cv::Mat> masks = LoadStaticMasks(dataset_dir, info.rig, info.has_static_masks);
  OverlapFit fit;
  fit.results = static_cast<int>(results.size());
  std::vector<double> scales;
  scales.reserve(results.size());
  for (const FitCalibration& r : results) scales.push_back(r.angle_scale);
  if (!scales.empty()) fit.angle_scale = Median(scales);
  for (int frame : frames) {
    if (frame < 0 || frame >= info.frame_count) {
      throw std::invalid_argument("--fit-frames: " + std::to_string(frame) + " is not a frame of " +
                                  DatasetJsonPath(dataset_dir) + " (frame_count " + std::to_string(info.frame_count) +
                                  ")");
    }
    RingCalibrator ring(info.rig, masks, options);
    ring.AddFrame(LoadFrameImages(dataset_dir, info.rig, frame).images);
    const std::vector<RingPairFit> given = ring.Fit(info.rig.Extrinsics(), 1.0);
    const std::vector<RingPairFit> given_scaled = ring.Fit(info.rig.Extrinsics(), fit.angle_scale);
    std::vector<std::vector<RingPairFit>> by_result;
    by_result.reserve(results.size());
    for (const FitCalibration& r : results) {
      by_result.push_back(ring.Fit(r.cam_from_rig, r.angle_scale));
    }
    for (int k = 0; k <= static_cast<int>(given.size()); ++k) {
      const int pair = k < static_cast<int>(given.size()) ? k : -1;  // the last row: the frame's total
      OverlapFitRow row;
      row.frame = frame;
      if (pair >= 0) {
        row.camera_a = given[pair].camera_a;
        row.camera_b = given[pair].camera_b;
        row.matches = given[pair].matches;
      } else {
        for (const RingPairFit& f : given) row.matches += f.matches;
      }
      row.given = Score(given, pair);
      row.given_scaled = Score(given_scaled, pair);
      row.results = MedianScore(by_result, pair);
      fit.rows.push_back(row);
    }
  }
  return fit;
}

std::string OverlapFitTable(const OverlapFit& fit) {
  std::ostringstream s;
  char scale[32];
  std::snprintf(scale, sizeof scale, "%.4f", fit.angle_scale);
  const bool have = fit.results > 0;
  s << "| frame | pair | matches | dataset's calibration: inliers | median residual | its extrinsics, lens scale "
    << (have ? scale : "-") << ": inliers | median residual | start-up results (median of " << fit.results
    << "): inliers | median residual |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const OverlapFitRow& r : fit.rows) {
    s << "| " << r.frame << " | "
      << (r.camera_a < 0 ? std::string("all") : std::to_string(r.camera_a) + "-" + std::to_string(r.camera_b)) << " | "
      << r.matches << " |" << Cells(r.given, true) << Cells(r.given_scaled, have) << Cells(r.results, have) << "\n";
  }
  s << "\nOverlap matches of each frame alone. Inliers: epipolar residual below the start-up's inlier threshold, in "
       "front of both cameras. Median residual: over all the matches, degrees. Lens scale: the median of the "
       "converged start-up results' estimates of the lenses' off-axis angle scale.\n";
  return s.str();
}

}  // namespace rovo
