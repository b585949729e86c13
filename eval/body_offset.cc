// Hand-eye estimate of a system's fixed body offset (body_offset.h).
#include "eval/body_offset.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace rovo {
namespace {

// A direction of the offset's translation is determined when the motion turns about axes
// perpendicular to it by at least this much (RMS over the pairs): |(R_A - I) d| = 2 sin(angle / 2).
constexpr double kMinPerpendicularRotationDeg = 1.0;
constexpr int kMaxIterations = 2000;
constexpr int kReweightRounds = 10;

struct MotionPair {
  Eigen::Matrix3d gt_rotation;  // R_A
  Eigen::Vector3d gt_translation;
  Eigen::Vector3d gt_axis;  // log(R_A)
  Eigen::Vector3d est_translation;
  Eigen::Vector3d est_axis;  // log(R_B)
  Eigen::Quaterniond gt_q, est_q;
};

Eigen::Vector3d LogRotation(const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd aa(q);
  return aa.axis() * aa.angle();
}

// Relative motions over strides 1, 2, 4, ... frames of the association (at most ~500 starts each).
std::vector<MotionPair> MotionPairs(const Trajectory& gt, const Trajectory& estimate, const Association& association) {
  std::vector<MotionPair> pairs;
  const size_t n = association.pairs.size();
  const size_t start_step = std::max<size_t>(1, n / 500);
  for (size_t stride = 1; stride < n; stride *= 2) {
    for (size_t k = 0; k + stride < n; k += start_step) {
      const auto [gi, ei] = association.pairs[k];
      const auto [gj, ej] = association.pairs[k + stride];
      const Rigid3 a = gt[gi].world_from_rig.Inverse() * gt[gj].world_from_rig;
      const Rigid3 b = estimate[ei].world_from_rig.Inverse() * estimate[ej].world_from_rig;
      MotionPair p;
      p.gt_q = a.rotation;
      p.est_q = b.rotation;
      p.gt_rotation = a.RotationMatrix();
      p.gt_translation = a.translation;
      p.gt_axis = LogRotation(a.rotation);
      p.est_translation = b.translation;
      p.est_axis = LogRotation(b.rotation);
      pairs.push_back(p);
    }
  }
  return pairs;
}

// The rotation R minimising sum |u_k - R v_k|^2 (no centring): SVD of sum u v^T.
Eigen::Matrix3d Kabsch(const Eigen::Matrix3d& correlation) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s(1.0, 1.0, 1.0);
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s(2) = -1.0;
  return svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
}

// sum_k (w a_k)(w b_k)^T over the rotation vectors.
Eigen::Matrix3d AxisCorrelation(const std::vector<MotionPair>& pairs, double weight) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const MotionPair& p : pairs) m += weight * weight * p.gt_axis * p.est_axis.transpose();
  return m;
}

// The least-squares t of (R_A - I) t = R t_B - t_A within the determined directions.
struct TranslationSolver {
  Eigen::Matrix3d eigenvectors;
  Eigen::Vector3d eigenvalues;
  int rank = 0;
  double threshold = 0.0;

  explicit TranslationSolver(const std::vector<MotionPair>& pairs) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (const MotionPair& p : pairs) {
      const Eigen::Matrix3d d = p.gt_rotation - Eigen::Matrix3d::Identity();
      h += d.transpose() * d;
    }
    h /= static_cast<double>(pairs.size());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(h);
    eigenvectors = eig.eigenvectors();
    eigenvalues = eig.eigenvalues();
    const double min_chord = 2.0 * std::sin(0.5 * kMinPerpendicularRotationDeg * M_PI / 180.0);
    threshold = min_chord * min_chord;
    for (int i = 0; i < 3; ++i) rank += eigenvalues(i) >= threshold ? 1 : 0;
  }

  Eigen::Vector3d Solve(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& rotation) const {
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (const MotionPair& p : pairs) {
      rhs +=
          (p.gt_rotation - Eigen::Matrix3d::Identity()).transpose() * (rotation * p.est_translation - p.gt_translation);
    }
    rhs /= static_cast<double>(pairs.size());
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      if (eigenvalues(i) >= threshold) t += eigenvectors.col(i) * (eigenvectors.col(i).dot(rhs) / eigenvalues(i));
    }
    return t;
  }
};

// Alternates the rotation (Kabsch over rotation vectors and corrected translations) and the
// translation (linear least squares) on their common objective until neither changes.
Rigid3 SolveHandEye(const std::vector<MotionPair>& pairs, const TranslationSolver& translation_solver,
                    double axis_weight, const Eigen::Matrix3d& initial_rotation) {
  Eigen::Matrix3d rotation = initial_rotation;
  Eigen::Vector3d t = translation_solver.Solve(pairs, rotation);
  const Eigen::Matrix3d axis_part = AxisCorrelation(pairs, axis_weight);
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    Eigen::Matrix3d m = axis_part;
    for (const MotionPair& p : pairs) {
      const Eigen::Vector3d u = p.gt_translation + (p.gt_rotation - Eigen::Matrix3d::Identity()) * t;
      m += u * p.est_translation.transpose();
    }
    const Eigen::Matrix3d next_rotation = Kabsch(m);
    const Eigen::Vector3d next_t = translation_solver.Solve(pairs, next_rotation);
    const double change = (next_rotation - rotation).norm() + (next_t - t).norm();
    rotation = next_rotation;
    t = next_t;
    if (change < 1e-15) break;
  }
  return Rigid3(rotation, t);
}

// RMS of the translation residuals |t_A + (R_A - I) t - R t_B| [m] and of the rotation-vector
// residuals |log R_A - R log R_B| [rad] at a solution.
std::pair<double, double> ResidualRms(const std::vector<MotionPair>& pairs, const Rigid3& x) {
  const Eigen::Matrix3d r = x.RotationMatrix();
  double translation = 0.0, axis = 0.0;
  for (const MotionPair& p : pairs) {
    translation +=
        (p.gt_translation + (p.gt_rotation - Eigen::Matrix3d::Identity()) * x.translation - r * p.est_translation)
            .squaredNorm();
    axis += (p.gt_axis - r * p.est_axis).squaredNorm();
  }
  const double n = static_cast<double>(pairs.size());
  return {std::sqrt(translation / n), std::sqrt(axis / n)};
}

// Solves with the rotation vectors weighted by w [m/rad] against the translations, w re-estimated
// from the residuals (w = RMS translation residual / RMS rotation-vector residual, the ratio of their
// noise: the inverse-variance weighting). Without it, a nearly straight drive, whose rotation vectors
// are mostly noise, tilts the offset by their noise over their size.
Rigid3 SolveReweighted(const std::vector<MotionPair>& pairs, const TranslationSolver& translation_solver,
                       double initial_weight, const Eigen::Matrix3d& initial_rotation) {
  double weight = initial_weight;
  Rigid3 x = SolveHandEye(pairs, translation_solver, weight, initial_rotation);
  for (int round = 0; round < kReweightRounds; ++round) {
    const auto [translation_rms, axis_rms] = ResidualRms(pairs, x);
    if (!(axis_rms > 1e-12) || !(translation_rms > 1e-12)) break;  // exact data: any weight gives the same
    const double next = std::clamp(translation_rms / axis_rms, 1e-3 * initial_weight, 1e3 * initial_weight);
    if (std::abs(next - weight) <= 1e-3 * weight) break;
    weight = next;
    x = SolveHandEye(pairs, translation_solver, weight, x.RotationMatrix());
  }
  return x;
}

double RotationResidualDeg(const std::vector<MotionPair>& pairs, const Eigen::Quaterniond& rotation) {
  double sum = 0.0;
  for (const MotionPair& p : pairs) {
    const double angle = RotationDistanceDeg(p.gt_q * rotation, rotation * p.est_q);
    sum += angle * angle;
  }
  return std::sqrt(sum / static_cast<double>(pairs.size()));
}

std::string FreeAxesNote(const BodyOffset& offset) {
  if (offset.free_axes.empty()) return "";
  std::ostringstream note;
  note << "the motion turns too little about axes perpendicular to ";
  for (size_t i = 0; i < offset.free_axes.size(); ++i) {
    const Eigen::Vector3d& a = offset.free_axes[i];
    note << (i ? " and " : "") << "(" << a.x() << ", " << a.y() << ", " << a.z() << ")";
  }
  note << " (rig frame) to determine the offset's translation along it; left at 0 (no relative motion depends on it)";
  return note.str();
}

}  // namespace

BodyOffset EstimateBodyOffset(const Trajectory& gt, const Trajectory& estimate, const Association& association) {
  BodyOffset out;
  if (association.pairs.size() < 3) {
    out.note = "fewer than 3 associated poses";
    return out;
  }
  const std::vector<MotionPair> pairs = MotionPairs(gt, estimate, association);
  out.motion_pairs = static_cast<int>(pairs.size());
  // The rotation vectors weigh as much as the translations in the rotation's fit.
  double axis_sq = 0.0, translation_sq = 0.0;
  for (const MotionPair& p : pairs) {
    axis_sq += p.gt_axis.squaredNorm();
    translation_sq += p.gt_translation.squaredNorm();
  }
  if (!(axis_sq > 0.0) && !(translation_sq > 0.0)) {
    out.note = "the ground truth does not move";
    return out;
  }
  const double axis_weight = axis_sq > 0.0 && translation_sq > 0.0 ? std::sqrt(translation_sq / axis_sq) : 1.0;
  // Rotation observability: the rotation vectors and translations together must span a plane.
  Eigen::Matrix3d full = AxisCorrelation(pairs, axis_weight);
  for (const MotionPair& p : pairs) full += p.gt_translation * p.est_translation.transpose();
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(full).singularValues();
  if (!(sv(1) > 1e-9 * sv(0))) {
    out.note =
        "the motion (rotation axes and translations) spans one direction only: the rotation about it is "
        "undetermined";
    return out;
  }
  // Start from the rotation axes alone where they span a plane (exact for noise-free data).
  const Eigen::Matrix3d axes = AxisCorrelation(pairs, 1.0);
  const Eigen::Vector3d axes_sv = Eigen::JacobiSVD<Eigen::Matrix3d>(axes).singularValues();
  const Eigen::Matrix3d initial = axes_sv(1) > 1e-3 * axes_sv(0) ? Kabsch(axes) : Kabsch(full);

  const TranslationSolver translation_solver(pairs);
  out.rig_from_body = SolveReweighted(pairs, translation_solver, axis_weight, initial);
  out.translation_rank = translation_solver.rank;
  for (int i = 0; i < 3; ++i) {
    if (translation_solver.eigenvalues(i) < translation_solver.threshold) {
      out.free_axes.push_back(translation_solver.eigenvectors.col(i));
    }
  }
  out.rotation_residual_deg = RotationResidualDeg(pairs, out.rig_from_body.rotation);
  out.note = FreeAxesNote(out);
  out.valid = true;
  return out;
}

Trajectory RemoveBodyOffset(const Trajectory& estimate, const Rigid3& rig_from_body) {
  const Rigid3 body_from_rig = rig_from_body.Inverse();
  Trajectory out = estimate;
  for (StampedPose& p : out) p.world_from_rig = p.world_from_rig * body_from_rig;
  return out;
}

}  // namespace rovo
