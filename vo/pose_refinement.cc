#include "vo/pose_refinement.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <stdexcept>

namespace rovo {
namespace {

// r = b - pi0(cam_from_rig * rig_from_world * X), with rig_from_world = (angle-axis, translation) as
// the only unknowns; cam_from_rig, X and b are constants.
struct FixedPointBearingCost {
  FixedPointBearingCost(const Eigen::Vector3d& bearing_in_cam, const Eigen::Vector3d& point_in_world,
                        const Rigid3& cam_from_rig)
      : bearing(bearing_in_cam),
        point(point_in_world),
        cam_rotation(cam_from_rig.RotationMatrix()),
        cam_translation(cam_from_rig.translation) {}

  template <typename T>
  bool operator()(const T* rig_from_world_aa, const T* rig_from_world_t, T* residual) const {
    T x[3] = {T(point.x()), T(point.y()), T(point.z())};
    T in_rig[3];
    ceres::AngleAxisRotatePoint(rig_from_world_aa, x, in_rig);
    T p[3];
    for (int r = 0; r < 3; ++r) in_rig[r] += rig_from_world_t[r];
    for (int r = 0; r < 3; ++r) {
      p[r] = cam_rotation(r, 0) * in_rig[0] + cam_rotation(r, 1) * in_rig[1] + cam_rotation(r, 2) * in_rig[2] +
             cam_translation(r);
    }
    const T norm = ceres::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int r = 0; r < 3; ++r) residual[r] = T(bearing(r)) - p[r] / norm;
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& bearing_in_cam, const Eigen::Vector3d& point_in_world,
                                     const Rigid3& cam_from_rig) {
    return new ceres::AutoDiffCostFunction<FixedPointBearingCost, 3, 3, 3>(
        new FixedPointBearingCost(bearing_in_cam, point_in_world, cam_from_rig));
  }

  Eigen::Vector3d bearing, point;
  Eigen::Matrix3d cam_rotation;
  Eigen::Vector3d cam_translation;
};

bool Selected(const std::vector<std::vector<char>>& inliers, size_t j, size_t i) {
  return inliers.empty() || inliers[j][i] != 0;
}

}  // namespace

void PoseRefinementOptions::Check() const {
  if (!(cauchy_scale_rad > 0.0)) throw std::invalid_argument("PoseRefinementOptions.cauchy_scale_rad must be > 0");
  if (max_iterations < 1) throw std::invalid_argument("PoseRefinementOptions.max_iterations must be >= 1");
}

PoseRefinementResult RefineRigPose(const std::vector<std::vector<BearingPointCorrespondence>>& correspondences,
                                   const std::vector<Rigid3>& cam_from_rig,
                                   const std::vector<std::vector<char>>& inliers, const Rigid3& initial_rig_from_world,
                                   const PoseRefinementOptions& options) {
  options.Check();
  PoseRefinementResult result;
  result.rig_from_world = initial_rig_from_world;
  Eigen::Vector3d aa = initial_rig_from_world.AxisAngle();
  Eigen::Vector3d trans = initial_rig_from_world.translation;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::CauchyLoss loss(options.cauchy_scale_rad);
  for (size_t j = 0; j < correspondences.size(); ++j) {
    for (size_t i = 0; i < correspondences[j].size(); ++i) {
      if (!Selected(inliers, j, i)) continue;
      const auto& c = correspondences[j][i];
      problem.AddResidualBlock(FixedPointBearingCost::Create(c.bearing_in_cam, c.point_in_world, cam_from_rig[j]),
                               &loss, aa.data(), trans.data());
      ++result.num_residuals;
    }
  }
  if (result.num_residuals < 3) return result;
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.usable = summary.IsSolutionUsable();
  if (result.usable) result.rig_from_world = Rigid3::FromAxisAngle(aa, trans);
  return result;
}

double MeanAngularError(const std::vector<std::vector<BearingPointCorrespondence>>& correspondences,
                        const std::vector<Rigid3>& cam_from_rig, const std::vector<std::vector<char>>& inliers,
                        const Rigid3& rig_from_world) {
  double sum = 0.0;
  int n = 0;
  for (size_t j = 0; j < correspondences.size(); ++j) {
    const Rigid3 cam_from_world = cam_from_rig[j] * rig_from_world;
    for (size_t i = 0; i < correspondences[j].size(); ++i) {
      if (!Selected(inliers, j, i)) continue;
      sum += AngleBetween(correspondences[j][i].bearing_in_cam, cam_from_world * correspondences[j][i].point_in_world);
      ++n;
    }
  }
  return n > 0 ? sum / n : 0.0;
}

}  // namespace rovo
