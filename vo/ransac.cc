#include "vo/ransac.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "vo/p3p.h"

namespace rovo {

void RansacLoopOptions::Check() const {
  if (min_iterations < 0) throw std::invalid_argument("RansacLoopOptions.min_iterations must be >= 0");
  if (max_iterations < 0) throw std::invalid_argument("RansacLoopOptions.max_iterations must be >= 0");
  if (!(confidence > 0.0 && confidence <= 1.0)) {
    throw std::invalid_argument("RansacLoopOptions.confidence must be in (0, 1]");
  }
}

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

// The rig's multi-view P3P estimator: a sample is three correspondences of one view; each P3P
// solution becomes a rig pose scored over every scored view (truncated angular cost).
class MultiViewP3PEstimator {
 public:
  static constexpr int kMinNumSamples = 3;
  struct Sample {
    int view = 0;
    uint64_t index[3] = {0, 0, 0};
  };
  using Model = Rigid3;  // rig_from_world

  MultiViewP3PEstimator(const std::vector<std::vector<BearingPointCorrespondence>>& correspondences,
                        const std::vector<Rigid3>& cam_from_rig, const std::vector<char>& scored, int total, double tau)
      : correspondences_(correspondences),
        cam_from_rig_(cam_from_rig),
        scored_(scored),
        total_(total),
        tau_(tau),
        cos_tau_(std::cos(tau)) {
    for (const Rigid3& x : cam_from_rig) rig_from_cam_.push_back(x.Inverse());
  }
  std::vector<Model> Estimate(const Sample& s) const {
    const auto& corrs = correspondences_[s.view];
    const auto& a = corrs[s.index[0]];
    const auto& b = corrs[s.index[1]];
    const auto& c = corrs[s.index[2]];
    std::vector<Model> rig_from_world;
    for (const Rigid3& cam_from_world : SolveP3P({a.bearing_in_cam, b.bearing_in_cam, c.bearing_in_cam},
                                                 {a.point_in_world, b.point_in_world, c.point_in_world})) {
      rig_from_world.push_back(rig_from_cam_[s.view] * cam_from_world);
    }
    return rig_from_world;
  }
  // The score summed over the scored views; `inlier_masks` (optional) receives each view's inliers.
  RansacScore Score(const Model& rig_from_world, std::vector<std::vector<char>>* inlier_masks = nullptr) const {
    RansacScore total;
    for (size_t j = 0; j < correspondences_.size(); ++j) {
      if (!scored_[j]) continue;
      const ViewScore s = ScoreView(correspondences_[j], cam_from_rig_[j] * rig_from_world, tau_, cos_tau_,
                                    inlier_masks ? &(*inlier_masks)[j] : nullptr);
      total.score += s.score;
      total.inliers += s.inliers;
    }
    return total;
  }
  int NumData() const { return total_; }

 private:
  const std::vector<std::vector<BearingPointCorrespondence>>& correspondences_;
  const std::vector<Rigid3>& cam_from_rig_;
  std::vector<Rigid3> rig_from_cam_;
  const std::vector<char>& scored_;
  int total_;
  double tau_, cos_tau_;
};

// Picks a view with probability weights[j] / sum (PPS: the view's correspondence count; uniform: 1),
// then three distinct correspondences of it; counts the draws per view.
class ViewSampler {
 public:
  ViewSampler(const std::vector<std::vector<BearingPointCorrespondence>>& correspondences,
              const std::vector<double>& weights, std::vector<int>* view_draws)
      : correspondences_(correspondences), weights_(weights), view_draws_(view_draws) {}
  MultiViewP3PEstimator::Sample Draw(std::mt19937_64& rng) {
    MultiViewP3PEstimator::Sample s;
    s.view = SampleProportional(rng, weights_);
    ++(*view_draws_)[s.view];
    const uint64_t n = correspondences_[s.view].size();
    s.index[0] = UniformIndex(rng, n);
    do {
      s.index[1] = UniformIndex(rng, n);
    } while (s.index[1] == s.index[0]);
    do {
      s.index[2] = UniformIndex(rng, n);
    } while (s.index[2] == s.index[0] || s.index[2] == s.index[1]);
    return s;
  }

 private:
  const std::vector<std::vector<BearingPointCorrespondence>>& correspondences_;
  const std::vector<double>& weights_;
  std::vector<int>* view_draws_;
};

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

  const MultiViewP3PEstimator estimator(correspondences, cam_from_rig, scored, total, options.tau_rad);
  ViewSampler sampler(correspondences, weights, &report.view_draws);
  std::mt19937_64 rng(options.seed);
  const RansacResult<Rigid3> result =
      Ransac(estimator, sampler, rng, {options.min_iterations, options.max_iterations, options.confidence});
  report.num_iterations = result.num_iterations;
  report.num_hypotheses = result.num_hypotheses;
  if (!result.found) return report;
  report.rig_from_world = result.best;
  report.score = result.best_score;
  const int inliers = estimator.Score(report.rig_from_world, &report.inliers).inliers;
  report.num_inliers = inliers;
  report.inlier_ratio = static_cast<double>(inliers) / total;
  report.success = inliers >= options.min_inliers;
  return report;
}

}  // namespace rovo
