#include "vo/ring_model.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>
#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/relative_pose/RotationOnlySacProblem.hpp>

namespace rovo::ring {
namespace {

// Angle (sine) of b's bearing, rotated into a, to the epipolar plane through the baseline t_a and
// a's bearing, all in camera a's frame:  e = (b_a x t_a) . (R_ab b_b) / |b_a x t_a|.
struct FixedBaselineEpipolarError {
  FixedBaselineEpipolarError(const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& bearing_b,
                             const Eigen::Vector3d& baseline_in_a)
      : normal_in_a(bearing_a.cross(baseline_in_a).normalized()), bearing_b(bearing_b) {}
  template <typename T>
  bool operator()(const T* q_ab, T* residual) const {
    const Eigen::Quaternion<T> q(q_ab[3], q_ab[0], q_ab[1], q_ab[2]);
    residual[0] = normal_in_a.cast<T>().dot(q * bearing_b.cast<T>());
    return true;
  }
  Eigen::Vector3d normal_in_a, bearing_b;
};

// Whether the rays from camera a along `ray_a` and from camera b (at `baseline_in_a`, direction only)
// along `ray_b` (both in a's frame) meet in front of both cameras. Nearly parallel rays (a far
// point) pass: their depths are not determined.
bool InFrontOfBoth(const Eigen::Vector3d& ray_a, const Eigen::Vector3d& ray_b, const Eigen::Vector3d& baseline_in_a) {
  // depth_a ray_a - depth_b ray_b = baseline, in the least-squares sense.
  const double aa = ray_a.dot(ray_a), ab = ray_a.dot(ray_b), bb = ray_b.dot(ray_b);
  const double det = aa * bb - ab * ab;
  if (det < 1e-6) return true;  // rays within about 0.06 deg of each other
  const double ta = ray_a.dot(baseline_in_a), tb = ray_b.dot(baseline_in_a);
  const double depth_a = (bb * ta - ab * tb) / det;
  const double depth_b = (ab * ta - aa * tb) / det;
  return depth_a > 0.0 && depth_b > 0.0;
}

// R_ab minimising the robust epipolar residuals of the matches `used` for the baseline direction
// `baseline_in_a`, from `start`.
Eigen::Quaterniond RefineWithBaseline(const opengv::bearingVectors_t& bearings_a,
                                      const opengv::bearingVectors_t& bearings_b, const std::vector<int>& used,
                                      const Eigen::Vector3d& baseline_in_a, Eigen::Quaterniond start,
                                      double scale_rad) {
  ceres::Problem problem;
  problem.AddParameterBlock(start.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  for (int k : used) {
    if (bearings_a[k].cross(baseline_in_a).norm() < 1e-6) continue;  // bearing along the baseline: no plane
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FixedBaselineEpipolarError, 1, 4>(
                                 new FixedBaselineEpipolarError(bearings_a[k], bearings_b[k], baseline_in_a)),
                             new ceres::CauchyLoss(scale_rad), start.coeffs().data());
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return start.normalized();
}

}  // namespace

// One pair's rotation from its pooled matches. The translation between the centres is known in the
// rig frame; in camera a's frame its direction is known up to a's own extrinsic error. A free
// translation (5-point relative pose) lets depth and baseline direction absorb rotation error along
// the epipolar lines: measured on quick cloudy_urban, 98 % inliers and pair rotations 3-9 deg off.
// So: a rotation-only RANSAC (OpenGV, Arun on 2 points) with a threshold wide enough for the parallax
// removes gross mismatches, then R_ab is refined on the epipolar residuals with the baseline direction
// held at its nominal value (Cauchy), and the inliers re-selected at the final threshold.
RingPairEstimate EstimatePair(const OverlapPair& p, const Rig& rig, const RingCalibrationOptions& o,
                              std::vector<int>* inliers) {
  RingPairEstimate e;
  e.camera_a = p.a;
  e.camera_b = p.b;
  e.matches = static_cast<int>(p.bearings_a.size());
  if (e.matches < o.min_inliers) return e;
  using opengv::sac_problems::relative_pose::RotationOnlySacProblem;
  opengv::relative_pose::CentralRelativeAdapter adapter(p.bearings_a, p.bearings_b);
  opengv::sac::Ransac<RotationOnlySacProblem> ransac;
  ransac.sac_model_ = std::make_shared<RotationOnlySacProblem>(adapter, /*randomSeed=*/false);
  ransac.threshold_ = 1.0 - std::cos(o.max_parallax_deg * kDeg);
  ransac.max_iterations_ = o.ransac_iterations;
  if (!ransac.computeModel() || static_cast<int>(ransac.inliers_.size()) < o.min_inliers) return e;
  const std::vector<int>& ransac_inliers = ransac.inliers_;
  const Eigen::Matrix3d r12 = ransac.model_coefficients_;
  // OpenGV's R12 maps viewpoint 2 (b) into viewpoint 1 (a).
  Eigen::Quaterniond a_from_b(r12);
  const Rigid3& cam_a = rig.cameras[p.a].cam_from_rig;
  const Eigen::Vector3d baseline_in_a =
      (cam_a.rotation * (CameraPositionInRig(rig.cameras[p.b].cam_from_rig) - CameraPositionInRig(cam_a))).normalized();
  const double threshold = o.inlier_threshold_deg * kDeg;
  std::vector<int> used = ransac_inliers;
  for (int round = 0; round < 3; ++round) {
    a_from_b = RefineWithBaseline(p.bearings_a, p.bearings_b, used, baseline_in_a, a_from_b, threshold);
    std::vector<int> next;
    const int candidates = o.reselect_all ? e.matches : static_cast<int>(ransac_inliers.size());
    for (int c = 0; c < candidates; ++c) {
      const int k = o.reselect_all ? c : ransac_inliers[c];
      const FixedBaselineEpipolarError f(p.bearings_a[k], p.bearings_b[k], baseline_in_a);
      double r = 0.0;
      const double q[4] = {a_from_b.x(), a_from_b.y(), a_from_b.z(), a_from_b.w()};
      f(q, &r);
      if (std::abs(r) < threshold && InFrontOfBoth(p.bearings_a[k], a_from_b * p.bearings_b[k], baseline_in_a)) {
        next.push_back(k);
      }
    }
    used.swap(next);
    if (static_cast<int>(used.size()) < o.min_inliers) return e;
  }
  e.inliers = static_cast<int>(used.size());
  *inliers = used;
  e.camb_from_cama = a_from_b.inverse().normalized();
  const Eigen::Quaterniond nominal = rig.cameras[p.b].cam_from_rig.rotation * cam_a.rotation.inverse();
  e.change_deg = RotationDistanceDeg(e.camb_from_cama, nominal);
  e.usable = true;
  return e;
}

namespace {

// Residual of one pair rotation in the ring average (AverageRing): Log(R_b R_a^T R_ba^T).
struct PairRotationError {
  explicit PairRotationError(const Eigen::Quaterniond& camb_from_cama) : measured_inverse(camb_from_cama.inverse()) {}
  template <typename T>
  bool operator()(const T* q_a, const T* q_b, T* residual) const {
    // Quaternions stored x, y, z, w (Eigen); R_b R_a^T R_ba^T as a quaternion, then its angle-axis.
    const Eigen::Quaternion<T> qa(q_a[3], q_a[0], q_a[1], q_a[2]);
    const Eigen::Quaternion<T> qb(q_b[3], q_b[0], q_b[1], q_b[2]);
    const Eigen::Quaternion<T> e = qb * qa.conjugate() * measured_inverse.cast<T>();
    const T wxyz[4] = {e.w(), e.x(), e.y(), e.z()};
    ceres::QuaternionToAngleAxis(wxyz, residual);
    return true;
  }
  Eigen::Quaterniond measured_inverse;
};

}  // namespace

std::vector<Eigen::Quaterniond> AverageRing(const std::vector<RingPairEstimate>& pairs, int num_cams,
                                            std::vector<Eigen::Quaterniond> rotations) {
  ceres::Problem problem;
  for (auto& q : rotations) problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  problem.SetParameterBlockConstant(rotations[0].coeffs().data());
  for (const RingPairEstimate& p : pairs) {
    if (!p.usable) continue;
    auto* cost = new ceres::AutoDiffCostFunction<PairRotationError, 3, 4, 4>(new PairRotationError(p.camb_from_cama));
    problem.AddResidualBlock(cost,
                             new ceres::ScaledLoss(nullptr, static_cast<double>(p.inliers), ceres::TAKE_OWNERSHIP),
                             rotations[p.camera_a].coeffs().data(), rotations[p.camera_b].coeffs().data());
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  if (num_cams > 1) ceres::Solve(options, &problem, &summary);
  for (auto& q : rotations) q.normalize();
  return rotations;
}

namespace {

// A camera-frame bearing whose angle off the optical axis (+z) can be scaled by 1 + kappa: the lens
// model's error that the ring can see (a lens calibrated with angles too small near the rim). The
// angle and the length of the bearing's xy part are computed once.
struct OffAxisBearing {
  explicit OffAxisBearing(const Eigen::Vector3d& b)
      : bearing(b), r(std::hypot(b.x(), b.y())), theta(std::atan2(r, b.z())) {}
  template <typename T>
  Eigen::Matrix<T, 3, 1> Scaled(const T& kappa) const {
    if (r < 1e-12) return bearing.cast<T>();
    using std::cos;
    using std::sin;
    const T angle = T(theta) * (T(1.0) + kappa);
    const T s = sin(angle) / T(r);
    return Eigen::Matrix<T, 3, 1>(s * T(bearing.x()), s * T(bearing.y()), cos(angle));
  }
  Eigen::Vector3d bearing;
  double r, theta;
};

Eigen::Vector3d ScaledBearing(const Eigen::Vector3d& bearing, double kappa) {
  return kappa == 0.0 ? bearing : OffAxisBearing(bearing).Scaled<double>(kappa);
}

// The ring's epipolar residual with each baseline direction following its camera:
//   e = (b_a x t_a) . (R_a R_b^T b_b) / |b_a x t_a|,   t_a = R_a (c_b - c_a),   R_j = rotation of cam_j_from_rig.
template <typename T>
T RingEpipolarResidual(const T* q_a, const T* q_b, const Eigen::Matrix<T, 3, 1>& bearing_a,
                       const Eigen::Matrix<T, 3, 1>& bearing_b, const Eigen::Vector3d& baseline_in_rig) {
  const Eigen::Quaternion<T> qa(q_a[3], q_a[0], q_a[1], q_a[2]);
  const Eigen::Quaternion<T> qb(q_b[3], q_b[0], q_b[1], q_b[2]);
  const Eigen::Matrix<T, 3, 1> t_a = qa * baseline_in_rig.cast<T>();
  const Eigen::Matrix<T, 3, 1> n = bearing_a.cross(t_a);
  const Eigen::Matrix<T, 3, 1> r = qa * (qb.conjugate() * bearing_b);
  return n.dot(r) / (n.norm() + T(1e-12));
}

// RingEpipolarResidual with the lenses as given.
struct RingEpipolarError {
  RingEpipolarError(const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& bearing_b,
                    const Eigen::Vector3d& baseline_in_rig)
      : bearing_a(bearing_a), bearing_b(bearing_b), baseline_in_rig(baseline_in_rig) {}
  template <typename T>
  bool operator()(const T* q_a, const T* q_b, T* residual) const {
    residual[0] = RingEpipolarResidual<T>(q_a, q_b, bearing_a.cast<T>(), bearing_b.cast<T>(), baseline_in_rig);
    return true;
  }
  Eigen::Vector3d bearing_a, bearing_b, baseline_in_rig;
};

// RingEpipolarResidual with both bearings' off-axis angles scaled by 1 + kappa (a parameter).
struct ScaledRingEpipolarError {
  ScaledRingEpipolarError(const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& bearing_b,
                          const Eigen::Vector3d& baseline_in_rig)
      : bearing_a(bearing_a), bearing_b(bearing_b), baseline_in_rig(baseline_in_rig) {}
  template <typename T>
  bool operator()(const T* q_a, const T* q_b, const T* kappa, T* residual) const {
    residual[0] =
        RingEpipolarResidual<T>(q_a, q_b, bearing_a.Scaled(kappa[0]), bearing_b.Scaled(kappa[0]), baseline_in_rig);
    return true;
  }
  OffAxisBearing bearing_a, bearing_b;
  Eigen::Vector3d baseline_in_rig;
};

// kappa near 0 (a weak prior of standard deviation `sigma`, as strong as ten matches at the Cauchy
// scale `scale_rad` for an error of sigma).
struct AngleScalePrior {
  explicit AngleScalePrior(double weight) : weight(weight) {}
  template <typename T>
  bool operator()(const T* kappa, T* residual) const {
    residual[0] = T(weight) * kappa[0];
    return true;
  }
  double weight;
};

// Camera 0's rotation stays near its given value (a weak prior: the common rotation of the cameras
// against their centres is seen only through the parallax of near points).
struct RotationPrior {
  RotationPrior(const Eigen::Quaterniond& prior, double weight) : prior_inverse(prior.inverse()), weight(weight) {}
  template <typename T>
  bool operator()(const T* q, T* residual) const {
    const Eigen::Quaternion<T> e = Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]) * prior_inverse.cast<T>();
    const T wxyz[4] = {e.w(), e.x(), e.y(), e.z()};
    ceres::QuaternionToAngleAxis(wxyz, residual);
    for (int k = 0; k < 3; ++k) residual[k] *= T(weight);
    return true;
  }
  Eigen::Quaterniond prior_inverse;
  double weight;
};

}  // namespace

Eigen::Vector3d PairBaselineInRig(const OverlapPair& p, const Rig& rig) {
  return CameraPositionInRig(rig.cameras[p.b].cam_from_rig) - CameraPositionInRig(rig.cameras[p.a].cam_from_rig);
}

namespace {

// |RingEpipolarResidual| of bearings `b_a`, `b_b` (already scaled) of pair `p` under `model`.
double RingResidual(const OverlapPair& p, const Eigen::Vector3d& b_a, const Eigen::Vector3d& b_b,
                    const Eigen::Vector3d& baseline_in_rig, const RingModel& model) {
  return std::abs(RingEpipolarResidual<double>(model.rotations[p.a].coeffs().data(),
                                               model.rotations[p.b].coeffs().data(), b_a, b_b, baseline_in_rig));
}

}  // namespace

// |RingEpipolarResidual| of match `i` of pair `p` under `model`.
double RingResidual(const OverlapPair& p, int i, const Eigen::Vector3d& baseline_in_rig, const RingModel& model) {
  return RingResidual(p, ScaledBearing(p.bearings_a[i], model.kappa), ScaledBearing(p.bearings_b[i], model.kappa),
                      baseline_in_rig, model);
}

namespace {

// The ring's epipolar residuals of the `inliers` (per pair) as blocks of `problem` on `model`'s
// rotations, and on its angle scale when that is free or not 0 (Cauchy at `scale_rad`; plain least
// squares when scale_rad <= 0). `residuals`, when given, receives their |values| at `model`.
void AddRingResiduals(const std::vector<OverlapPair>& pairs, const std::vector<std::vector<int>>& inliers,
                      const Rig& rig, double scale_rad, bool scale_free, RingModel* model, ceres::Problem* problem,
                      std::vector<double>* residuals = nullptr) {
  const bool scaled = scale_free || model->kappa != 0.0;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const OverlapPair& p = pairs[k];
    const Eigen::Vector3d baseline = PairBaselineInRig(p, rig);
    double* q_a = model->rotations[p.a].coeffs().data();
    double* q_b = model->rotations[p.b].coeffs().data();
    for (int i : inliers[k]) {
      if (residuals) residuals->push_back(RingResidual(p, i, baseline, *model));
      ceres::LossFunction* loss = scale_rad > 0.0 ? new ceres::CauchyLoss(scale_rad) : nullptr;
      if (scaled) {
        problem->AddResidualBlock(new ceres::AutoDiffCostFunction<ScaledRingEpipolarError, 1, 4, 4, 1>(
                                      new ScaledRingEpipolarError(p.bearings_a[i], p.bearings_b[i], baseline)),
                                  loss, q_a, q_b, &model->kappa);
      } else {
        problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RingEpipolarError, 1, 4, 4>(
                                      new RingEpipolarError(p.bearings_a[i], p.bearings_b[i], baseline)),
                                  loss, q_a, q_b);
      }
    }
  }
  if (scaled && !scale_free) problem->SetParameterBlockConstant(&model->kappa);
}

}  // namespace

// Refines every cam_j_from_rig rotation on all pairs' inlier matches at once (RingEpipolarError,
// Cauchy at `scale_rad`), camera 0 held near its start by RotationPrior; the angle scale too when
// `angle_scale_sigma` > 0 (AngleScalePrior), else it stays at its start.
RingModel RefineRing(const std::vector<OverlapPair>& pairs, const std::vector<std::vector<int>>& inliers,
                     const Rig& rig, RingModel model, double scale_rad, double prior_sigma_deg,
                     double angle_scale_sigma) {
  ceres::Problem problem;
  for (auto& q : model.rotations) problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  AddRingResiduals(pairs, inliers, rig, scale_rad, angle_scale_sigma > 0.0, &model, &problem);
  // Priors as strong as ten matches at the Cauchy scale for an error of one sigma.
  const double weight = std::sqrt(10.0) * scale_rad / (prior_sigma_deg * kDeg);
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<RotationPrior, 3, 4>(new RotationPrior(model.rotations[0], weight)), nullptr,
      model.rotations[0].coeffs().data());
  if (angle_scale_sigma > 0.0) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<AngleScalePrior, 1, 1>(
                                 new AngleScalePrior(std::sqrt(10.0) * scale_rad / angle_scale_sigma)),
                             nullptr, &model.kappa);
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 100;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (auto& q : model.rotations) q.normalize();
  return model;
}

// One-sigma uncertainty (degrees) of the worst-determined camera's rotation relative to camera 0 at
// the joint solution: the covariance of the epipolar least-squares problem on the inliers with
// camera 0 held (and the angle scale free when it is estimated), scaled by the residuals' robust
// variance, largest eigenvalue over cameras 1..N-1. A near-field overlap leaves the rotation about
// the epipolar planes' normal (roughly the yaw of a pair) nearly free, because depth absorbs it:
// this is where that shows. -1: not computable.
// camera_zero_free: every camera free, and the result is camera 0's one sigma alone (how well the
// matches, without the prior, know the cameras' common turn against their centres).
double RingUncertaintyDeg(const std::vector<OverlapPair>& pairs, const std::vector<std::vector<int>>& inliers,
                          const Rig& rig, RingModel model, bool angle_scale_free, bool camera_zero_free) {
  ceres::Problem problem;
  for (auto& q : model.rotations) problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  if (!camera_zero_free) problem.SetParameterBlockConstant(model.rotations[0].coeffs().data());
  std::vector<double> residuals;
  AddRingResiduals(pairs, inliers, rig, 0.0, angle_scale_free, &model, &problem, &residuals);
  if (residuals.size() < 10) return -1.0;
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  const double sigma = 1.4826 * residuals[residuals.size() / 2];
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.null_space_rank = -1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  const size_t first = camera_zero_free ? 0 : 1, end = camera_zero_free ? 1 : model.rotations.size();
  for (size_t j = first; j < end; ++j) {
    blocks.emplace_back(model.rotations[j].coeffs().data(), model.rotations[j].coeffs().data());
  }
  if (!covariance.Compute(blocks, &problem)) return -1.0;
  double worst = 0.0;
  for (size_t j = first; j < end; ++j) {
    Eigen::Matrix3d c;
    covariance.GetCovarianceMatrixInTangentSpace({model.rotations[j].coeffs().data()}, c.data());
    const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(c).eigenvalues().maxCoeff();
    // Ceres' quaternion tangent is half the rotation vector.
    worst = std::max(worst, 2.0 * std::sqrt(std::max(0.0, largest)) * sigma / kDeg);
  }
  return worst;
}

namespace {

// RingEpipolarResidual of `model`'s cameras all turned by one rig-frame rotation (the parameter).
struct CommonRotationError {
  CommonRotationError(const Eigen::Quaterniond& cam_a_from_rig, const Eigen::Quaterniond& cam_b_from_rig,
                      const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& bearing_b,
                      const Eigen::Vector3d& baseline_in_rig)
      : qa(cam_a_from_rig),
        qb(cam_b_from_rig),
        bearing_a(bearing_a),
        bearing_b(bearing_b),
        baseline_in_rig(baseline_in_rig) {}
  template <typename T>
  bool operator()(const T* q_turn, T* residual) const {
    const Eigen::Quaternion<T> turn(q_turn[3], q_turn[0], q_turn[1], q_turn[2]);
    const Eigen::Quaternion<T> a = qa.cast<T>() * turn, b = qb.cast<T>() * turn;
    residual[0] = RingEpipolarResidual<T>(a.coeffs().data(), b.coeffs().data(), bearing_a.cast<T>(),
                                          bearing_b.cast<T>(), baseline_in_rig);
    return true;
  }
  Eigen::Quaterniond qa, qb;
  Eigen::Vector3d bearing_a, bearing_b, baseline_in_rig;
};

}  // namespace

// `model` with every camera turned by the rig-frame rotation that best explains all the pairs'
// matches (Cauchy at `scale_rad`): the relative rotations and the angle scale stay.
RingModel FitCommonRotation(const std::vector<OverlapPair>& pairs, const Rig& rig, RingModel model, double scale_rad) {
  Eigen::Quaterniond turn = Eigen::Quaterniond::Identity();
  ceres::Problem problem;
  problem.AddParameterBlock(turn.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  int residuals = 0;
  for (const OverlapPair& p : pairs) {
    const Eigen::Vector3d baseline = PairBaselineInRig(p, rig);
    for (size_t i = 0; i < p.bearings_a.size(); ++i) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<CommonRotationError, 1, 4>(new CommonRotationError(
              model.rotations[p.a], model.rotations[p.b], ScaledBearing(p.bearings_a[i], model.kappa),
              ScaledBearing(p.bearings_b[i], model.kappa), baseline)),
          new ceres::CauchyLoss(scale_rad), turn.coeffs().data());
      ++residuals;
    }
  }
  if (residuals < 3) return model;
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (auto& q : model.rotations) q = (q * turn).normalized();
  return model;
}

// Per pair, the indices of the matches that the joint model explains: epipolar residual
// (RingEpipolarError) below `threshold_rad` and the rays meeting in front of both cameras.
std::vector<std::vector<int>> ReselectInliers(const std::vector<OverlapPair>& pairs, const Rig& rig,
                                              const RingModel& model, double threshold_rad) {
  std::vector<std::vector<int>> out(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    const OverlapPair& p = pairs[k];
    const Eigen::Quaterniond& qa = model.rotations[p.a];
    const Eigen::Quaterniond a_from_b = qa * model.rotations[p.b].conjugate();
    const Eigen::Vector3d baseline_in_rig = PairBaselineInRig(p, rig);
    const Eigen::Vector3d baseline_in_a = (qa * baseline_in_rig).normalized();
    for (size_t i = 0; i < p.bearings_a.size(); ++i) {
      const Eigen::Vector3d b_a = ScaledBearing(p.bearings_a[i], model.kappa);
      const Eigen::Vector3d b_b = ScaledBearing(p.bearings_b[i], model.kappa);
      if (RingResidual(p, b_a, b_b, baseline_in_rig, model) < threshold_rad &&
          InFrontOfBoth(b_a, a_from_b * b_b, baseline_in_a)) {
        out[k].push_back(static_cast<int>(i));
      }
    }
  }
  return out;
}

// Median |RingEpipolarError| over `indices` of pair `p` under `model`, degrees.
double MedianResidualDeg(const OverlapPair& p, const std::vector<int>& indices, const Rig& rig,
                         const RingModel& model) {
  if (indices.empty()) return -1.0;
  const Eigen::Vector3d baseline_in_rig = PairBaselineInRig(p, rig);
  std::vector<double> residuals;
  residuals.reserve(indices.size());
  for (int i : indices) residuals.push_back(RingResidual(p, i, baseline_in_rig, model));
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  return std::asin(std::min(1.0, residuals[residuals.size() / 2])) / kDeg;
}

// Angle between the joint rotation of a pair and the pair's own rotation refined on its inliers alone
// with the joint baseline direction and angle scale: how far the pair's matches pull away from the
// ring solution.
double PairDisagreementDeg(const OverlapPair& p, const std::vector<int>& inliers, const Rig& rig,
                           const RingModel& model, double scale_rad) {
  const Eigen::Quaterniond& qa = model.rotations[p.a];
  const Eigen::Quaterniond joint_a_from_b = qa * model.rotations[p.b].conjugate();
  const Eigen::Vector3d baseline_in_a = (qa * PairBaselineInRig(p, rig)).normalized();
  opengv::bearingVectors_t scaled_a(p.bearings_a.size()), scaled_b(p.bearings_b.size());
  for (int i : inliers) {
    scaled_a[i] = ScaledBearing(p.bearings_a[i], model.kappa);
    scaled_b[i] = ScaledBearing(p.bearings_b[i], model.kappa);
  }
  const Eigen::Quaterniond own =
      RefineWithBaseline(scaled_a, scaled_b, inliers, baseline_in_a, joint_a_from_b, scale_rad);
  return RotationDistanceDeg(own, joint_a_from_b);
}

// cam_j_from_cam0 rotations by chaining usable pairs outward from camera 0 (breadth first); false
// when some camera is not reached.
bool ChainFromCameraZero(const std::vector<RingPairEstimate>& pairs, int num_cams,
                         std::vector<Eigen::Quaterniond>* rotations) {
  std::vector<bool> known(num_cams, false);
  rotations->assign(num_cams, Eigen::Quaterniond::Identity());
  known[0] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (const RingPairEstimate& p : pairs) {
      if (!p.usable || known[p.camera_a] == known[p.camera_b]) continue;
      if (known[p.camera_a]) {
        (*rotations)[p.camera_b] = p.camb_from_cama * (*rotations)[p.camera_a];
        known[p.camera_b] = true;
      } else {
        (*rotations)[p.camera_a] = p.camb_from_cama.inverse() * (*rotations)[p.camera_b];
        known[p.camera_a] = true;
      }
      grew = true;
    }
  }
  return std::all_of(known.begin(), known.end(), [](bool k) { return k; });
}

// Angle of the product of the pair rotations around the ring (every pair usable, N >= 3); -1 otherwise.
double LoopClosureErrorDeg(const std::vector<RingPairEstimate>& pairs, int num_cams) {
  if (num_cams < 3 || static_cast<int>(pairs.size()) != num_cams) return -1.0;
  std::vector<Eigen::Quaterniond> chained;
  if (!ChainFromCameraZero(pairs, num_cams, &chained)) return -1.0;
  double worst = 0.0;
  for (const RingPairEstimate& p : pairs) {
    if (!p.usable) return -1.0;
    // The pair not used by the chain closes the loop; checking every pair's consistency with the
    // chained rotations gives the loop's error (the others are exactly 0).
    worst = std::max(worst, RotationDistanceDeg(p.camb_from_cama * chained[p.camera_a], chained[p.camera_b]));
  }
  return worst;
}

}  // namespace rovo::ring
