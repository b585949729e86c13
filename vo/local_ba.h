#pragma once
// Local bundle adjustment with online extrinsic calibration (ROVO paper, Sec. IV-D):
//     min sum_t sum_j sum_i w_ij rho( | B_ijt^T pi0(cam_from_rig_j * rig_from_world_t * X_i) |^2 )
//         + sum_{(i,j) neighbours} ( s * ( |c_j - c_i| - L0_ij ) )^2
//         + sum_{j >= 1} |log(R_j R_j0^T)|^2 / sigma_r^2 + |c_j - c_j0|^2 / sigma_c^2   (optional prior)
// over the rig poses rig_from_world_t of the window, the landmarks X_i (point_in_world) and, in
// online mode, cam_from_rig_j of cameras 1..N-1. pi0(p) = p/|p|, B = TangentBasis(b) spans the plane
// perpendicular to the observed bearing b, so the 2-vector residual has norm sin(angle(b, pi0)) (the
// paper's angular error to first order) with no redundant third value. |sin| grows with the angle only
// up to 90 deg; observations enter the map only within the back-end's rejection bound (2 deg at most), far
// from that. rho = Cauchy, w_ij =
// multi_camera_weight for points seen by >= 2 cameras (they carry the metric scale), else 1.
// c_j = -R_j^T t_j is camera j's centre in the rig frame (cam_from_rig_j = (R_j, t_j)) and L0_ij its
// initial distance to its neighbour (ring order 0-1, 1-2, ..., N-1-0): without it the rig could
// grow or shrink and metric scale would be lost.
// Gauge: the oldest rig pose (index 0) is fixed; camera 0's cam_from_rig is fixed (rig.h).
// Parametrisation: one 6-vector block per pose and extrinsic, (angle-axis in radians, translation);
// Ceres DENSE_SCHUR with landmarks eliminated first (its <2, 3, 6> specialisation). Bounded time:
// max_iterations (and an optional wall-time limit, which trades determinism for latency). Deterministic for a fixed
// input with num_threads = 1.

#include <Eigen/Core>
#include <vector>

#include "datasets/rigid3.h"

namespace ceres {
class CostFunction;
}

namespace rovo {

struct LocalBaOptions {
  bool optimize_extrinsics = false;  // online extrinsic calibration
  double cauchy_scale_rad = 0.002;   // Cauchy scale on the bearing residual (sine of the angle; 0.11 deg)
  double multi_camera_weight = 2.0;  // w for points seen by >= 2 cameras
  double baseline_weight = 1000.0;   // s, per metre of baseline change
  // Online mode: a random-walk prior pulls each free cam_from_rig towards its value before the solve,
  // with these standard deviations per solve (rotation, camera centre); 0 deg = no prior. The rig
  // is rigid, so one window's evidence should move the extrinsics only a little: this averages the
  // windows' estimates instead of letting each window's errors through.
  double extrinsic_prior_deg = 0.005;
  double extrinsic_prior_m = 0.005;
  // Online mode: every solve also pulls each free cam_from_rig towards `extrinsic_anchor` (the start-up
  // calibration's result) with this rotation standard deviation; empty or 0 deg: none. The start-up
  // calibration sees thousands of overlap matches at once; one window's BA sees a few hundred.
  std::vector<Rigid3> extrinsic_anchor;
  double extrinsic_anchor_deg = 0.0;
  double extrinsic_anchor_m = 0.0;  // the anchor's centre standard deviation; 0: the centre is not held (1 m)
  // The bearing residuals are sines of angles (radians to first order), unweighted: the prior is scaled by this assumed
  // bearing noise so that both terms are in units of standard deviations.
  double observation_sigma_rad = 0.001;
  int max_iterations = 10;
  double max_time_s = 0.0;  // 0: no wall-time limit (deterministic)
  int num_threads = 1;
  void Check() const;
};

struct LocalBaObservation {
  int pose_index = 0;
  int camera = 0;
  int point_index = 0;
  Eigen::Vector3d bearing_in_cam;  // unit
};

struct LocalBaProblem {
  std::vector<Rigid3> rig_from_world;  // window poses, [0] = oldest (fixed)
  std::vector<Rigid3> cam_from_rig;    // [0] fixed
  std::vector<Eigen::Vector3d> points_in_world;
  std::vector<int> point_num_cameras;  // distinct cameras per point (weights)
  std::vector<LocalBaObservation> observations;
  std::vector<double> baseline_lengths;  // L0 of ring pair (j, j+1 mod N); empty = from cam_from_rig
};

struct LocalBaReport {
  bool usable = false;
  int num_residuals = 0;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double seconds = 0.0;
};

// Centre distances of ring neighbours (j, j+1 mod N) of a set of extrinsics.
std::vector<double> RingBaselineLengths(const std::vector<Rigid3>& cam_from_rig);

// Orthonormal basis (columns) of the plane perpendicular to the unit vector `bearing`.
Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& bearing);

// The bearing residual r = TangentBasis(b)^T pi0(cam_from_rig * rig_from_world * X) (2 values) over
// the blocks rig_from_world (6: angle-axis, translation), cam_from_rig (6: angle-axis, translation),
// point_in_world (3), with analytic Jacobians (local_ba.cc). The caller owns the returned object.
ceres::CostFunction* CreateBearingResidual(const Eigen::Vector3d& bearing_in_cam);

// Optimises `problem` in place.
LocalBaReport SolveLocalBa(LocalBaProblem& problem, const LocalBaOptions& options);

}  // namespace rovo
