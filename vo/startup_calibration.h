#pragma once
// OnlineExt's start-up calibration: from extrinsics that may be off by any sigma = 5 deg draw to
// within a fraction of a degree, before the local BA takes over (local_ba.h).
//
// The ring stage (ring_calibration.h), no extrinsic prior: each ring pair's rotation from descriptor
// matches over its whole overlap, pooled over `shots` synchronous shots, averaged around the ring and
// refined jointly with one angle scale of every lens; later passes on views placed by the previous
// result, the last one averaged over several view placements, and a rescue with weaker features.
// When the ring stage cannot calibrate (too few matches, an open or inconsistent ring) the starting
// extrinsics are kept and the report says "not converged" with the reason: the caller writes it to
// run.json and stderr.

#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "datasets/rig.h"
#include "datasets/rigid3.h"
#include "vo/image_loader.h"
#include "vo/ring_calibration.h"

namespace rovo {

struct StartupCalibrationOptions {
  int shots = 1;          // synchronous shots pooled by the ring stage
  int shot_spacing = 10;  // frames between two shots
  // More shots where the overlaps are poor: when the ring stage fails, or its weakest pair keeps
  // fewer than min_pair_inliers inliers, it runs again on up to max_shots shots (the same spacing,
  // fewer where the frames end) and that result stands if it converges. max_shots <= shots: never.
  int max_shots = 6;
  int min_pair_inliers = 300;
  RingCalibrationOptions ring;
  int ring_passes = 2;             // > 1: the ring stage again with views placed by the previous result
  bool refine_second_pass = true;  // KLT sub-pixel matches in the later passes (their views are aligned)
  // The later passes detect more and weaker corners (at least these) on denser views (up to
  // later_view_focal_px where the lenses hold it: RingCalibrationOptions::dense_view_focal_px): with
  // the views aligned, more matches make the result depend less on which corners were found.
  int later_orb_features = 6000;
  int later_orb_fast_threshold = 5;
  double later_view_focal_px = 450.0;
  double max_pass_change_deg = 0.5;  // a later pass moving a camera further: not converged
  // The last pass again from placements - 1 other view placements (every camera's turned by
  // placement_jitter_deg about a fixed axis), the converged results within max_pass_change_deg of the
  // first and with its lens decision (angle scale estimated or left at 1) averaged: which corners a
  // pass matches depends on where its views' pixel grid falls, and the mean depends less on it.
  int placements = 3;
  double placement_jitter_deg = 0.3;
  // When the ring passes fail, once more with more and weaker features (an overlap with little
  // texture, a real camera's low contrast).
  bool rescue = true;
  int rescue_orb_features = 6000;
  int rescue_orb_fast_threshold = 5;
  void Check() const;  // throws std::invalid_argument naming the field
};

struct StartupCalibrationReport {
  bool converged = false;
  std::string status;      // "converged", or why not
  std::vector<int> shots;  // frames used by the ring stage
  // Why the ring stage asked for more shots (StartupCalibrationOptions::max_shots; also when no frame
  // was left for one, or the attempt on them failed), or empty; first_shots: the frames of the first
  // attempt when the result is the second's.
  std::string more_shots_reason;
  std::vector<int> first_shots;
  // The ring passes' result (of the rescue when it ran). With placements averaged, cam_from_rig (as
  // cam_j_from_cam0 behind the first placement's camera 0) and angle_scale are their average; pairs,
  // loop error and uncertainty are the first placement's.
  RingCalibrationReport ring;
  bool rescued = false;                // the ring passes failed and the rescue ran
  std::string ring_failure;            // why the ring passes failed, when the rescue ran
  int placements_averaged = 0;         // converged view placements averaged (StartupCalibrationOptions::placements)
  double placement_spread_deg = -1.0;  // largest angle of one of them from their mean (cam_j_from_cam0)
  std::vector<Rigid3> cam_from_rig;    // the result (the start when nothing could be done)
  nlohmann::json ToJson() const;
};

// `rig`: lenses and names; `cam_from_rig`: the starting extrinsics. `load(frame)` returns a frame's
// images; the shots are first_frame, first_frame + shot_spacing, ... below end_frame (at most
// `shots` of them, or max_shots when the first attempt's overlaps are poor).
StartupCalibrationReport CalibrateAtStartup(const Rig& rig, const std::vector<Rigid3>& cam_from_rig,
                                            const std::function<LoadedFrame(int)>& load, int first_frame, int end_frame,
                                            const std::vector<cv::Mat>& static_masks,
                                            const StartupCalibrationOptions& options, bool quiet);

}  // namespace rovo
