#pragma once
// Start-up extrinsic calibration for OnlineExt from the inter-view matches of one frame.
//
// Online calibration in the local BA (local_ba.h) corrects small extrinsic errors over time, but with
// the suites' noise (sigma = 5 deg per axis, ~10 deg between cameras) the first frames have too few
// inter-view matches that pass the epipolar filter, and a map triangulated under wrong extrinsics
// misleads the first poses. So OnlineExt starts (RunVo) with a few rounds of
//     match with loose filters -> calibrate on this frame's inter-view points -> rebuild the warps
// at the first frame. One round is the local BA of local_ba.h restricted to one rig pose (fixed, the
// gauge with camera 0):
//     min over cam_from_rig_j (j >= 1) and X_i of
//         sum_i sum_j w_i rho_s( |b_ij - pi0(cam_from_rig_j * X_i)|^2 ) + baseline-length terms
// with X_i in the rig frame, seeded by triangulating each shared track under the current
// extrinsics (rays within `max_error_deg` of each other; near-parallel rays, i.e. far points, are
// placed at `far_distance_m` along their mean direction: they pin the relative rotation best) and a
// Cauchy scale s that follows the current uncertainty (an annealing schedule over the rounds).
// Observability: the rotation of each camera about axes other than `up` comes from the y-disparity
// of near and far points; the relative yaw only from far points, so what remains of it is left to
// the online BA over time (multi-frame tracks fix it through each camera's own parallax).

#include <vector>

#include "datasets/rigid3.h"
#include "vo/frontend.h"

namespace rovo {

struct ExtrinsicBootstrapOptions {
  double max_error_deg = 10.0;      // rays of one track may disagree by this much (current uncertainty)
  double far_distance_m = 200.0;    // depth given to near-parallel rays
  double min_parallax_deg = 0.3;    // below: treated as a far point
  int max_iterations = 30;          // Ceres iterations
  double baseline_weight = 1000.0;  // as LocalBaOptions
  double multi_camera_weight = 1.0;
};

struct ExtrinsicBootstrapReport {
  bool usable = false;
  int num_points = 0;  // shared tracks used
  int num_observations = 0;
  int points_per_pair_min = 0;           // fewest points in an overlap of ring neighbours
  double median_error_deg_before = 0.0;  // angular residual of the seeds under the old extrinsics
  double median_error_deg_after = 0.0;   // after the solve
  double max_change_deg = 0.0;           // largest rotation change of a cam_from_rig
  std::vector<Rigid3> cam_from_rig;      // calibrated (camera 0 unchanged)
};

// `frame`: one front-end frame whose features carry unified track ids (inter-view matches).
ExtrinsicBootstrapReport CalibrateExtrinsicsFromFrame(const FrontendFrame& frame,
                                                      const std::vector<Rigid3>& cam_from_rig,
                                                      const std::vector<double>& baseline_lengths,
                                                      const ExtrinsicBootstrapOptions& options);

}  // namespace rovo
