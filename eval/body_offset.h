#pragma once
// Metrics that do not depend on the body frame a system reports.
//
// Every system reports the pose of its own body: rovo the rig with camera 0 as the gauge (so with a
// perturbed calibration its rig is turned by camera 0's error), a VIO its IMU, COLMAP a camera. With
// gt_i = world_from_rig of ground-truth frame i and est_i the associated estimate, a system that
// tracks perfectly but reports another body satisfies
//   est_i = W * gt_i * X,   W = est_world_from_gt_world (any), X = rig_from_body (fixed).
// SE(3) alignment removes W but not X, so relative-pose errors (drift, RPE) and origin-aligned errors
// count X as error. The relative motions A = gt_i^-1 gt_j and B = est_i^-1 est_j satisfy the hand-eye
// equation A X = X B, i.e. with X = (R, t):
//   rotation:    log(R_A) = R log(R_B)                   (rotation axes turn by R)
//   translation: t_A + (R_A - I) t = R t_B
// EstimateBodyOffset solves both in least squares over many pairs (i, j): R in closed form (Kabsch /
// SVD, as Park & Martin 1994 solve the rotation part, here over the rotation vectors and the
// translations together, which also fixes the rotation about the common axis of planar motion), t
// by linear least squares, alternating until neither changes. The motion determines t only along
// directions d with (R_A - I) d != 0: rotations about a single axis (planar driving) leave t's
// component along that axis free; it is reported and left at zero (it shifts every position by one
// constant, which SE(3) alignment removes, and changes no relative motion).

#include <string>
#include <vector>

#include "datasets/rigid3.h"
#include "datasets/trajectory.h"
#include "eval/metrics.h"

namespace rovo {

struct BodyOffset {
  bool valid = false;
  Rigid3 rig_from_body;  // X above; est_i * X^-1 is the estimate of gt_i up to W
  int motion_pairs = 0;
  int translation_rank = 0;                // directions of t the motion determines (0..3)
  std::vector<Eigen::Vector3d> free_axes;  // unit directions (rig frame) left free, 3 - rank of them
  double rotation_residual_deg = 0.0;      // RMS of angle(R_A R (R_B)^-1 R^-1) over the pairs
  std::string note;                        // why it is invalid, or which directions are free
};

// Hand-eye estimate of X from the associated poses (association pairs index gt and estimate).
// Invalid (with a note) when there are fewer than 3 poses or the motion cannot determine the
// rotation (its rotation vectors and translations all along one direction).
BodyOffset EstimateBodyOffset(const Trajectory& gt, const Trajectory& estimate, const Association& association);

// est_i * rig_from_body^-1 for every pose: the estimate expressed for the ground truth's body.
Trajectory RemoveBodyOffset(const Trajectory& estimate, const Rigid3& rig_from_body);

}  // namespace rovo
