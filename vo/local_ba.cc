#include "vo/local_ba.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rovo {
namespace {

// [v]x, the cross-product matrix: [v]x w = v x w.
Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d h;
  h << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return h;
}

// Rotation matrix of an angle-axis vector phi (Rodrigues, the convention of ceres::AngleAxisRotatePoint)
// and the right Jacobian of SO(3): R(phi + d) = R(phi) Exp(Jr(phi) d) + O(d^2),
//   R  = I + sin(th)/th [phi]x + (1 - cos(th))/th^2 [phi]x^2,
//   Jr = I - (1 - cos(th))/th^2 [phi]x + (th - sin(th))/th^3 [phi]x^2,   th = |phi|.
void RotationAndRightJacobian(const double* phi, Eigen::Matrix3d* rotation, Eigen::Matrix3d* right_jacobian) {
  const Eigen::Map<const Eigen::Vector3d> v(phi);
  const double th2 = v.squaredNorm();
  const double th = std::sqrt(th2);
  double a, b, c;  // sin(th)/th, (1 - cos(th))/th^2, (th - sin(th))/th^3
  if (th < 1e-4) {
    a = 1.0 - th2 / 6.0;
    b = 0.5 - th2 / 24.0;
    c = 1.0 / 6.0 - th2 / 120.0;
  } else {
    const double s = std::sin(th), co = std::cos(th);
    a = s / th;
    b = (1.0 - co) / th2;
    c = (th - s) / (th2 * th);
  }
  const Eigen::Matrix3d hat = Hat(v);
  const Eigen::Matrix3d hat2 = hat * hat;
  *rotation = Eigen::Matrix3d::Identity() + a * hat + b * hat2;
  if (right_jacobian) *right_jacobian = Eigen::Matrix3d::Identity() - b * hat + c * hat2;
}

}  // namespace

// RotationAndRightJacobian through a small per-thread cache keyed by the angle-axis values: the
// residuals of one evaluation pass share a handful of poses, so each rotation is computed once per
// pass instead of once per residual (the result is the same bits either way).
void CachedRotation(const double* phi, Eigen::Matrix3d* rotation, Eigen::Matrix3d* right_jacobian) {
  struct Entry {
    double phi[3] = {0, 0, 0};
    Eigen::Matrix3d rotation, right_jacobian;
    bool valid = false;
  };
  constexpr int kEntries = 16;
  thread_local Entry cache[kEntries];
  thread_local int next = 0;
  for (Entry& e : cache) {
    if (e.valid && e.phi[0] == phi[0] && e.phi[1] == phi[1] && e.phi[2] == phi[2]) {
      *rotation = e.rotation;
      if (right_jacobian) *right_jacobian = e.right_jacobian;
      return;
    }
  }
  Entry& e = cache[next];
  next = (next + 1) % kEntries;
  RotationAndRightJacobian(phi, &e.rotation, &e.right_jacobian);
  std::copy(phi, phi + 3, e.phi);
  e.valid = true;
  *rotation = e.rotation;
  if (right_jacobian) *right_jacobian = e.right_jacobian;
}

Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& bearing) {
  // Cross with the coordinate axis least aligned with the bearing: never near-parallel.
  int axis = 0;
  bearing.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d e1 = bearing.cross(Eigen::Vector3d::Unit(axis)).normalized();
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = e1;
  basis.col(1) = bearing.cross(e1).normalized();
  return basis;
}

// r = B^T u,  u = q / |q|,  q = R_c p + t_c,  p = R_r X + t_r,  B = TangentBasis(b).
// Unknowns: rig_from_world (phi_r, t_r), cam_from_rig (phi_c, t_c), point_in_world X. With
// dr/dq = B^T (I - u u^T) / |q| =: M (2x3):
//   dr/dX = M R_c R_r,   dr/dt_r = M R_c,   dr/dt_c = M,
//   dr/dphi_c = -M R_c [p]x Jr(phi_c),   dr/dphi_r = -M R_c R_r [X]x Jr(phi_r).
// Analytic: about 4x cheaper than the same residual in autodiff Jets. Each Jacobian is written when
// its pointer is non-null: `jac_rig` 2x6 and `jac_cam` 2x6 (phi, t), `jac_point` 2x3, row-major; the
// cam Jacobian `cam_jr` is needed only for `jac_cam`.
bool EvaluateBearing(const Eigen::Matrix<double, 3, 2>& basis, const double* rig, const Eigen::Matrix3d& cam_rotation,
                     const Eigen::Vector3d& cam_t, const Eigen::Matrix3d* cam_jr, const double* point_data,
                     double* residuals, double* jac_rig, double* jac_cam, double* jac_point) {
  Eigen::Matrix3d rig_rotation, rig_jr;
  CachedRotation(rig, &rig_rotation, jac_rig ? &rig_jr : nullptr);
  const Eigen::Map<const Eigen::Vector3d> rig_t(rig + 3), point_in_world(point_data);
  const Eigen::Vector3d in_rig = rig_rotation * point_in_world + rig_t;
  const Eigen::Vector3d in_cam = cam_rotation * in_rig + cam_t;
  const double norm = in_cam.norm();
  if (!(norm > 0.0)) return false;
  const Eigen::Vector3d u = in_cam / norm;
  Eigen::Map<Eigen::Vector2d> residual(residuals);
  residual = basis.transpose() * u;
  if (!jac_rig && !jac_cam && !jac_point) return true;
  // M = B^T (I - u u^T) / |q| without forming the 3x3 projector.
  const Eigen::Matrix<double, 2, 3> m = (basis.transpose() - (basis.transpose() * u) * u.transpose()) / norm;
  const Eigen::Matrix<double, 2, 3> m_rc = m * cam_rotation;  // M R_c
  using RowMajor26 = Eigen::Matrix<double, 2, 6, Eigen::RowMajor>;
  using RowMajor23 = Eigen::Matrix<double, 2, 3, Eigen::RowMajor>;
  const Eigen::Matrix<double, 2, 3> m_rc_rr = m_rc * rig_rotation;  // M R_c R_r
  if (jac_rig) {
    Eigen::Map<RowMajor26> j(jac_rig);
    j.leftCols<3>() = -m_rc_rr * Hat(point_in_world) * rig_jr;
    j.rightCols<3>() = m_rc;
  }
  if (jac_cam) {
    Eigen::Map<RowMajor26> j(jac_cam);
    j.leftCols<3>() = -m_rc * Hat(in_rig) * *cam_jr;
    j.rightCols<3>() = m;
  }
  if (jac_point) {
    Eigen::Map<RowMajor23> j(jac_point);
    j = m_rc_rr;
  }
  return true;
}

// The residual above over the blocks (rig_from_world, cam_from_rig, X): online extrinsics.
class BearingResidual final : public ceres::SizedCostFunction<2, 6, 6, 3> {
 public:
  explicit BearingResidual(const Eigen::Vector3d& bearing_in_cam) : basis_(TangentBasis(bearing_in_cam)) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    Eigen::Matrix3d cam_rotation, cam_jr;
    const bool want_cam = jacobians && jacobians[1];
    CachedRotation(parameters[1], &cam_rotation, want_cam ? &cam_jr : nullptr);
    return EvaluateBearing(basis_, parameters[0], cam_rotation, Eigen::Map<const Eigen::Vector3d>(parameters[1] + 3),
                           &cam_jr, parameters[2], residuals, jacobians ? jacobians[0] : nullptr,
                           want_cam ? jacobians[1] : nullptr, jacobians ? jacobians[2] : nullptr);
  }

 private:
  Eigen::Matrix<double, 3, 2> basis_;
};

// The same residual with cam_from_rig held fixed (GTExt, NoisyExt): blocks (rig_from_world, X) only,
// which spares the solver a constant block per residual.
class FixedCameraBearingResidual final : public ceres::SizedCostFunction<2, 6, 3> {
 public:
  FixedCameraBearingResidual(const Eigen::Vector3d& bearing_in_cam, const Eigen::Matrix3d& cam_rotation,
                             const Eigen::Vector3d& cam_t)
      : basis_(TangentBasis(bearing_in_cam)), cam_rotation_(cam_rotation), cam_t_(cam_t) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    return EvaluateBearing(basis_, parameters[0], cam_rotation_, cam_t_, nullptr, parameters[1], residuals,
                           jacobians ? jacobians[0] : nullptr, nullptr, jacobians ? jacobians[1] : nullptr);
  }

 private:
  Eigen::Matrix<double, 3, 2> basis_;
  Eigen::Matrix3d cam_rotation_;
  Eigen::Vector3d cam_t_;
};

ceres::CostFunction* CreateBearingResidual(const Eigen::Vector3d& bearing_in_cam) {
  return new BearingResidual(bearing_in_cam);
}

namespace {

// r = s * (|c_j - c_i| - L0), c = -R^T t = -R(-aa) t; each block is (aa, t) of one cam_from_rig.
struct BaselineCost {
  BaselineCost(double length, double weight) : length0(length), scale(weight) {}

  template <typename T>
  bool operator()(const T* cam_i, const T* cam_j, T* residual) const {
    T c_i[3], c_j[3];
    const T minus_aa_i[3] = {-cam_i[0], -cam_i[1], -cam_i[2]};
    const T minus_aa_j[3] = {-cam_j[0], -cam_j[1], -cam_j[2]};
    ceres::AngleAxisRotatePoint(minus_aa_i, cam_i + 3, c_i);
    ceres::AngleAxisRotatePoint(minus_aa_j, cam_j + 3, c_j);
    T d2 = T(0.0);
    for (int r = 0; r < 3; ++r) d2 += (c_j[r] - c_i[r]) * (c_j[r] - c_i[r]);
    residual[0] = T(scale) * (ceres::sqrt(d2) - T(length0));
    return true;
  }

  static ceres::CostFunction* Create(double length, double weight) {
    return new ceres::AutoDiffCostFunction<BaselineCost, 1, 6, 6>(new BaselineCost(length, weight));
  }

  double length0, scale;
};

// One pose or extrinsic as a parameter block: (angle-axis in radians, translation).
using PoseParams = Eigen::Matrix<double, 6, 1>;

PoseParams ToParams(const Rigid3& x) {
  PoseParams p;
  p << x.AxisAngle(), x.translation;
  return p;
}
Rigid3 FromParams(const PoseParams& p) { return Rigid3::FromAxisAngle(p.head<3>(), p.tail<3>()); }

// Random-walk prior of online extrinsics between BA runs:
//   r = [ log(R * R0^T) / sigma_rot ; (c - c0) / sigma_centre ],  c = -R^T t,
// with (R0, c0) the extrinsics before this solve.
struct ExtrinsicPriorCost {
  ExtrinsicPriorCost(const Rigid3& cam_from_rig0, double sigma_rot_rad, double sigma_centre_m)
      : q0_inverse{cam_from_rig0.rotation.w(), -cam_from_rig0.rotation.x(), -cam_from_rig0.rotation.y(),
                   -cam_from_rig0.rotation.z()},
        centre0(cam_from_rig0.Inverse().translation),
        inv_sigma_rot(1.0 / sigma_rot_rad),
        inv_sigma_centre(1.0 / sigma_centre_m) {}

  template <typename T>
  bool operator()(const T* cam, T* residual) const {
    const T* aa = cam;
    const T* t = cam + 3;
    T q[4], q0i[4], dq[4];
    ceres::AngleAxisToQuaternion(aa, q);
    for (int k = 0; k < 4; ++k) q0i[k] = T(q0_inverse[k]);
    ceres::QuaternionProduct(q, q0i, dq);
    ceres::QuaternionToAngleAxis(dq, residual);
    for (int k = 0; k < 3; ++k) residual[k] *= T(inv_sigma_rot);
    T centre[3];
    const T minus_aa[3] = {-aa[0], -aa[1], -aa[2]};
    ceres::AngleAxisRotatePoint(minus_aa, t, centre);
    for (int k = 0; k < 3; ++k) residual[3 + k] = T(inv_sigma_centre) * (-centre[k] - T(centre0[k]));
    return true;
  }

  static ceres::CostFunction* Create(const Rigid3& cam_from_rig0, double sigma_rot_rad, double sigma_centre_m) {
    return new ceres::AutoDiffCostFunction<ExtrinsicPriorCost, 6, 6>(
        new ExtrinsicPriorCost(cam_from_rig0, sigma_rot_rad, sigma_centre_m));
  }

  double q0_inverse[4];  // w, x, y, z (Ceres' quaternion order)
  Eigen::Vector3d centre0;
  double inv_sigma_rot, inv_sigma_centre;
};

}  // namespace

void LocalBaOptions::Check() const {
  if (!(cauchy_scale_rad > 0.0)) throw std::invalid_argument("LocalBaOptions.cauchy_scale_rad must be > 0");
  if (!(multi_camera_weight > 0.0)) throw std::invalid_argument("LocalBaOptions.multi_camera_weight must be > 0");
  if (!(baseline_weight >= 0.0)) throw std::invalid_argument("LocalBaOptions.baseline_weight must be >= 0");
  if (max_iterations < 1) throw std::invalid_argument("LocalBaOptions.max_iterations must be >= 1");
  if (!(extrinsic_prior_deg >= 0.0) || !(extrinsic_prior_m > 0.0)) {
    throw std::invalid_argument("LocalBaOptions.extrinsic_prior_deg must be >= 0 and extrinsic_prior_m > 0");
  }
  if (num_threads < 1) throw std::invalid_argument("LocalBaOptions.num_threads must be >= 1");
  if (!(extrinsic_anchor_deg >= 0.0)) throw std::invalid_argument("LocalBaOptions.extrinsic_anchor_deg must be >= 0");
  if (!(extrinsic_anchor_m >= 0.0)) throw std::invalid_argument("LocalBaOptions.extrinsic_anchor_m must be >= 0");
}

std::vector<double> RingBaselineLengths(const std::vector<Rigid3>& cam_from_rig) {
  const size_t n = cam_from_rig.size();
  std::vector<double> out;
  if (n < 2) return out;
  for (size_t j = 0; j < n; ++j) {
    const size_t k = (j + 1) % n;
    if (n == 2 && j == 1) break;  // a single pair
    out.push_back((cam_from_rig[j].Inverse().translation - cam_from_rig[k].Inverse().translation).norm());
  }
  return out;
}

namespace {

// Online mode: the random-walk prior towards the extrinsics before this solve and, after a converged
// start-up calibration, the anchor towards its result (rotation, and the centre when
// extrinsic_anchor_m is set), on every free camera the window sees.
void AddExtrinsicPriors(const LocalBaProblem& problem, const LocalBaOptions& options, const std::vector<char>& cam_used,
                        PoseParams* cams, ceres::Problem* ceres_problem) {
  const int num_cams = static_cast<int>(problem.cam_from_rig.size());
  if (options.extrinsic_prior_deg > 0.0) {
    for (int j = 1; j < num_cams; ++j) {
      if (!cam_used[j]) continue;
      ceres_problem->AddResidualBlock(
          ExtrinsicPriorCost::Create(problem.cam_from_rig[j],
                                     options.extrinsic_prior_deg * M_PI / 180.0 / options.observation_sigma_rad,
                                     options.extrinsic_prior_m / options.observation_sigma_rad),
          nullptr, cams[j].data());
    }
  }
  if (options.extrinsic_anchor_deg > 0.0 && static_cast<int>(options.extrinsic_anchor.size()) == num_cams) {
    for (int j = 1; j < num_cams; ++j) {
      if (!cam_used[j]) continue;
      ceres_problem->AddResidualBlock(
          ExtrinsicPriorCost::Create(
              options.extrinsic_anchor[j], options.extrinsic_anchor_deg * M_PI / 180.0 / options.observation_sigma_rad,
              (options.extrinsic_anchor_m > 0.0 ? options.extrinsic_anchor_m : 1.0) / options.observation_sigma_rad),
          nullptr, cams[j].data());
    }
  }
}

}  // namespace

namespace {

// One local BA as COLMAP's BundleAdjuster runs it: SetUp builds the Ceres problem, Solve runs it,
// WriteBack copies the free blocks into the LocalBaProblem.
class LocalBaSolver {
 public:
  LocalBaSolver(LocalBaProblem& problem, const LocalBaOptions& options)
      : problem_(problem),
        options_(options),
        num_poses_(static_cast<int>(problem.rig_from_world.size())),
        num_cams_(static_cast<int>(problem.cam_from_rig.size())),
        blocks_(num_poses_ + num_cams_),
        poses_(blocks_.data()),
        cams_(blocks_.data() + num_poses_),
        cauchy_(options.cauchy_scale_rad),
        loss_single_(&cauchy_, 1.0, ceres::DO_NOT_TAKE_OWNERSHIP),
        loss_multi_(&cauchy_, options.multi_camera_weight, ceres::DO_NOT_TAKE_OWNERSHIP),
        ceres_problem_(ProblemOptions()) {}

  // The parameter blocks, residuals and priors; returns the number of observation residuals.
  int SetUp() {
    for (int i = 0; i < num_poses_; ++i) poses_[i] = ToParams(problem_.rig_from_world[i]);
    for (int j = 0; j < num_cams_; ++j) cams_[j] = ToParams(problem_.cam_from_rig[j]);
    const std::vector<double> baselines =
        problem_.baseline_lengths.empty() ? RingBaselineLengths(problem_.cam_from_rig) : problem_.baseline_lengths;
    const int num_residuals = AddObservations();
    if (pose_used_[0]) ceres_problem_.SetParameterBlockConstant(poses_[0].data());
    if (options_.optimize_extrinsics && options_.baseline_weight > 0.0) AddBaselines(baselines);
    // Fixed cameras that a baseline term brought in stay constant.
    for (int j = 0; j < num_cams_; ++j) {
      if (CameraFree(j) || !ceres_problem_.HasParameterBlock(cams_[j].data())) continue;
      ceres_problem_.SetParameterBlockConstant(cams_[j].data());
    }
    if (options_.optimize_extrinsics) AddExtrinsicPriors(problem_, options_, cam_used_, cams_, &ceres_problem_);
    return num_residuals;
  }

  ceres::Solver::Summary Solve() {
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_SCHUR;
    solver_options.linear_solver_ordering.reset(SchurOrdering());
    solver_options.max_num_iterations = options_.max_iterations;
    if (options_.max_time_s > 0.0) solver_options.max_solver_time_in_seconds = options_.max_time_s;
    solver_options.num_threads = options_.num_threads;
    solver_options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &ceres_problem_, &summary);
    return summary;
  }

  // Writes back only what was free (a round trip through angle-axis would perturb fixed blocks).
  void WriteBack() {
    for (int i = 1; i < num_poses_; ++i) {
      if (pose_used_[i]) problem_.rig_from_world[i] = FromParams(poses_[i]);
    }
    for (int j = 1; j < num_cams_ && options_.optimize_extrinsics; ++j) {
      if (cam_used_[j]) problem_.cam_from_rig[j] = FromParams(cams_[j]);
    }
  }

 private:
  static ceres::Problem::Options ProblemOptions() {
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    return problem_options;
  }

  bool CameraFree(int j) const { return options_.optimize_extrinsics && j != 0; }

  // The bearing residuals. A camera held fixed (all of them without online calibration, camera 0
  // always) enters its residuals as constants (FixedCameraBearingResidual); the others as parameter
  // blocks.
  int AddObservations() {
    std::vector<Eigen::Matrix3d> cam_rotations(num_cams_);
    for (int j = 0; j < num_cams_; ++j) RotationAndRightJacobian(cams_[j].data(), &cam_rotations[j], nullptr);
    pose_used_.assign(num_poses_, 0);
    cam_used_.assign(num_cams_, 0);
    point_used_.assign(problem_.points_in_world.size(), 0);
    int num_residuals = 0;
    for (const LocalBaObservation& o : problem_.observations) {
      const bool multi = o.point_index < static_cast<int>(problem_.point_num_cameras.size()) &&
                         problem_.point_num_cameras[o.point_index] >= 2;
      ceres::LossFunction* loss = multi ? &loss_multi_ : &loss_single_;
      double* point = problem_.points_in_world[o.point_index].data();
      if (CameraFree(o.camera)) {
        ceres_problem_.AddResidualBlock(CreateBearingResidual(o.bearing_in_cam), loss, poses_[o.pose_index].data(),
                                        cams_[o.camera].data(), point);
      } else {
        ceres_problem_.AddResidualBlock(
            new FixedCameraBearingResidual(o.bearing_in_cam, cam_rotations[o.camera], cams_[o.camera].tail<3>()), loss,
            poses_[o.pose_index].data(), point);
      }
      pose_used_[o.pose_index] = cam_used_[o.camera] = point_used_[o.point_index] = 1;
      ++num_residuals;
    }
    return num_residuals;
  }

  // The baseline length terms of the ring's neighbours that the window sees.
  void AddBaselines(const std::vector<double>& baselines) {
    for (size_t p = 0; p < baselines.size(); ++p) {
      const int a = static_cast<int>(p), b = static_cast<int>((p + 1) % num_cams_);
      if (!cam_used_[a] || !cam_used_[b]) continue;
      ceres_problem_.AddResidualBlock(BaselineCost::Create(baselines[p], options_.baseline_weight), nullptr,
                                      cams_[a].data(), cams_[b].data());
    }
  }

  // Schur ordering: landmarks first, then poses and extrinsics.
  ceres::ParameterBlockOrdering* SchurOrdering() {
    auto* ordering = new ceres::ParameterBlockOrdering;
    for (size_t i = 0; i < problem_.points_in_world.size(); ++i) {
      if (point_used_[i]) ordering->AddElementToGroup(problem_.points_in_world[i].data(), 0);
    }
    for (int i = 0; i < num_poses_; ++i) {
      if (pose_used_[i]) ordering->AddElementToGroup(poses_[i].data(), 1);
    }
    for (int j = 0; j < num_cams_; ++j) {
      if (ceres_problem_.HasParameterBlock(cams_[j].data())) ordering->AddElementToGroup(cams_[j].data(), 1);
    }
    return ordering;
  }

  LocalBaProblem& problem_;
  const LocalBaOptions& options_;
  const int num_poses_, num_cams_;
  // Poses and extrinsics live in ONE array, poses first: Ceres orders the blocks of an elimination
  // group by address, so two separate heap arrays would make the reduced system's order (and the
  // floating-point result) depend on the heap layout, i.e. differ from run to run.
  std::vector<PoseParams> blocks_;
  PoseParams* poses_;
  PoseParams* cams_;
  std::vector<char> pose_used_, cam_used_, point_used_;
  // Two shared losses (single- and multi-camera weight), owned here.
  ceres::CauchyLoss cauchy_;
  ceres::ScaledLoss loss_single_, loss_multi_;
  ceres::Problem ceres_problem_;
};

}  // namespace

LocalBaReport SolveLocalBa(LocalBaProblem& problem, const LocalBaOptions& options) {
  options.Check();
  LocalBaReport report;
  if (problem.rig_from_world.empty() || problem.observations.empty()) return report;
  LocalBaSolver solver(problem, options);
  report.num_residuals = solver.SetUp();
  const ceres::Solver::Summary summary = solver.Solve();
  report.usable = summary.IsSolutionUsable();
  report.iterations = static_cast<int>(summary.iterations.size());
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.seconds = summary.total_time_in_seconds;
  if (!report.usable) return report;
  solver.WriteBack();
  return report;
}

}  // namespace rovo
