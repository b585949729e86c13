#include "vo/ransac.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "vo/p3p.h"

namespace rovo {

ViewSampling ViewSamplingFromName(const std::string& name) {
  if (name == "pps") return ViewSampling::kPps;
  if (name == "uniform") return ViewSampling::kUniform;
  throw std::invalid_argument("sampling: expected 'pps' or 'uniform', got '" + name + "'");
}

RansacViews RansacViewsFromName(const std::string& name) {
  if (name == "multiview") return RansacViews::kMultiView;
  if (name == "single-view") return RansacViews::kSingleView;
  throw std::invalid_argument("ransac: expected 'multiview' or 'single-view', got '" + name + "'");
}

void MultiViewRansacOptions::Check() const {
  if (!(tau_rad > 0.0 && tau_rad < M_PI))
    throw std::invalid_argument("MultiViewRansacOptions.tau_rad must be in (0, pi)");
  if (min_iterations < 1) throw std::invalid_argument("MultiViewRansacOptions.min_iterations must be >= 1");
  if (max_iterations < min_iterations) {
    throw std::invalid_argument("MultiViewRansacOptions.max_iterations must be >= min_iterations");
  }
  if (!(confidence > 0.0 && confidence < 1.0))
    throw std::invalid_argument("MultiViewRansacOptions.confidence must be in (0, 1)");
  if (min_inliers < 3) throw std::invalid_argument("MultiViewRansacOptions.min_inliers must be >= 3");
}

uint64_t UniformIndex(std::mt19937_64& rng, uint64_t n) {
  // Rejection sampling: accept draws below the largest multiple of n.
  const uint64_t limit = std::numeric_limits<uint64_t>::max() - std::numeric_limits<uint64_t>::max() % n;
  uint64_t v;
  do {
    v = rng();
  } while (v >= limit);
  return v % n;
}

double UniformUnit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

int SampleProportional(std::mt19937_64& rng, const std::vector<double>& weights) {
  double total = 0.0;
  for (double w : weights) total += w;
  const double u = UniformUnit(rng) * total;
  double acc = 0.0;
  int last_positive = -1;
  for (size_t j = 0; j < weights.size(); ++j) {
    if (weights[j] <= 0.0) continue;
    last_positive = static_cast<int>(j);
    acc += weights[j];
    if (u < acc) return static_cast<int>(j);
  }
  return last_positive;  // rounding at the top end
}

namespace {

struct ViewScore {
  double score = 0.0;
  int inliers = 0;
};

// Truncated angular cost of one view under cam_from_world.
ViewScore ScoreView(const std::vector<BearingPointCorrespondence>& corrs, const Rigid3& cam_from_world, double tau,
                    double cos_tau, std::vector<char>* inlier_mask) {
  ViewScore s;
  const Eigen::Matrix3d rot = cam_from_world.RotationMatrix();
  const Eigen::Vector3d& trans = cam_from_world.translation;
  if (inlier_mask) inlier_mask->assign(corrs.size(), 0);
  for (size_t i = 0; i < corrs.size(); ++i) {
    const Eigen::Vector3d p = rot * corrs[i].point_in_world + trans;
    const double dot = corrs[i].bearing_in_cam.dot(p);
    if (dot <= cos_tau * p.norm()) continue;  // angle >= tau: zero contribution
    const double angle = std::atan2(corrs[i].bearing_in_cam.cross(p).norm(), dot);
    if (angle < tau) {
      s.score += tau - angle;
      ++s.inliers;
      if (inlier_mask) (*inlier_mask)[i] = 1;
    }
  }
  return s;
}

}  // namespace

MultiViewRansacReport MultiViewP3PRansac(const std::vector<std::vector<BearingPointCorrespondence>>& correspondences,
                                         const std::vector<Rigid3>& cam_from_rig,
                                         const MultiViewRansacOptions& options) {
  options.Check();
  if (cam_from_rig.size() != correspondences.size()) {
    throw std::invalid_argument("MultiViewP3PRansac: cam_from_rig and correspondences differ in size");
  }
  const int num_views = static_cast<int>(correspondences.size());
  MultiViewRansacReport report;
  report.view_draws.assign(num_views, 0);
  report.inliers.resize(num_views);
  for (int j = 0; j < num_views; ++j) report.inliers[j].assign(correspondences[j].size(), 0);

  // Views that take part in sampling and in scoring.
  std::vector<double> weights(num_views, 0.0);
  std::vector<char> scored(num_views, 1);
  if (options.views == RansacViews::kSingleView) {
    int best = -1;
    for (int j = 0; j < num_views; ++j) {
      if (best < 0 || correspondences[j].size() > correspondences[best].size()) best = j;
    }
    report.single_view = best;
    for (int j = 0; j < num_views; ++j) scored[j] = (j == best);
  }
  int total = 0;
  for (int j = 0; j < num_views; ++j) {
    const int n = static_cast<int>(correspondences[j].size());
    if (scored[j]) total += n;
    if (scored[j] && n >= 3) weights[j] = options.sampling == ViewSampling::kPps ? n : 1.0;
  }
  report.num_correspondences = total;
  double weight_sum = 0.0;
  for (double w : weights) weight_sum += w;
  if (weight_sum <= 0.0 || total < options.min_inliers) return report;

  std::vector<Rigid3> rig_from_cam(num_views);
  for (int j = 0; j < num_views; ++j) rig_from_cam[j] = cam_from_rig[j].Inverse();

  std::mt19937_64 rng(options.seed);
  const double cos_tau = std::cos(options.tau_rad);
  double best_score = -1.0;
  int64_t bound = options.max_iterations;
  int iteration = 0;
  for (; iteration < std::max<int64_t>(options.min_iterations, std::min<int64_t>(bound, options.max_iterations));
       ++iteration) {
    const int view = SampleProportional(rng, weights);
    ++report.view_draws[view];
    const auto& corrs = correspondences[view];
    const uint64_t n = corrs.size();
    uint64_t i0 = UniformIndex(rng, n), i1, i2;
    do {
      i1 = UniformIndex(rng, n);
    } while (i1 == i0);
    do {
      i2 = UniformIndex(rng, n);
    } while (i2 == i0 || i2 == i1);
    const std::vector<Rigid3> cam_from_world =
        SolveP3P({corrs[i0].bearing_in_cam, corrs[i1].bearing_in_cam, corrs[i2].bearing_in_cam},
                 {corrs[i0].point_in_world, corrs[i1].point_in_world, corrs[i2].point_in_world});
    for (const Rigid3& candidate : cam_from_world) {
      ++report.num_hypotheses;
      const Rigid3 rig_from_world = rig_from_cam[view] * candidate;
      double score = 0.0;
      int inliers = 0;
      for (int j = 0; j < num_views; ++j) {
        if (!scored[j]) continue;
        const ViewScore s =
            ScoreView(correspondences[j], cam_from_rig[j] * rig_from_world, options.tau_rad, cos_tau, nullptr);
        score += s.score;
        inliers += s.inliers;
      }
      if (score > best_score) {
        best_score = score;
        report.rig_from_world = rig_from_world;
        const double w = static_cast<double>(inliers) / total;
        const double p_good = w * w * w;
        if (p_good >= 1.0 - 1e-12) {
          bound = 0;
        } else if (p_good > 0.0) {
          const double k = std::log(1.0 - options.confidence) / std::log(1.0 - p_good);
          bound = static_cast<int64_t>(std::min<double>(std::ceil(k), options.max_iterations));
        }
      }
    }
  }
  report.num_iterations = iteration;
  if (best_score < 0.0) return report;
  report.score = best_score;
  int inliers = 0;
  for (int j = 0; j < num_views; ++j) {
    if (!scored[j]) continue;
    inliers += ScoreView(correspondences[j], cam_from_rig[j] * report.rig_from_world, options.tau_rad, cos_tau,
                         &report.inliers[j])
                   .inliers;
  }
  report.num_inliers = inliers;
  report.inlier_ratio = static_cast<double>(inliers) / total;
  report.success = inliers >= options.min_inliers;
  return report;
}

}  // namespace rovo
