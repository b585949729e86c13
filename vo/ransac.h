#pragma once
// Multi-view P3P RANSAC (ROVO paper, Sec. IV-C, Algorithm 1).
//
// Data: per camera j, correspondences (bearing_in_cam_ij, point_in_world_ij) and the camera's
// cam_from_rig_j. Each iteration
//   1. picks a view j' with probability n_j' / sum_j n_j (PPS: probability proportional to size;
//      only views with >= 3 correspondences take part),
//   2. draws 3 distinct correspondences of j', solves P3P -> candidates cam_from_world_k,
//   3. turns each into a rig pose rig_from_world_k = inverse(cam_from_rig_j') * cam_from_world_k,
//   4. scores it over EVERY correspondence of EVERY view with the truncated angular cost
//        C_k = sum_j sum_i max(0, tau - angle(bearing_ij, cam_from_rig_j * rig_from_world_k * X_ij)),
//      angle(a, b) = atan2(|a x b|, a . b) (valid for any direction, also behind the image plane),
//   5. keeps the candidate with the largest C_k and updates the iteration bound from its inlier ratio
//      w (inlier: angle < tau): N = log(1 - confidence) / log(1 - w^3).
// Ablations: sampling kUniform picks the view uniformly; kSingleView restricts hypotheses and scoring
// to one view (the one with the most correspondences), i.e. the monocular P3P RANSAC.
// Determinism: std::mt19937_64 seeded by Options::seed with our own uniform helpers, so the result is
// the same on every platform for a given seed.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "datasets/rigid3.h"

namespace rovo {

struct BearingPointCorrespondence {
  Eigen::Vector3d bearing_in_cam;  // unit
  Eigen::Vector3d point_in_world;
};

enum class ViewSampling { kPps, kUniform };
enum class RansacViews { kMultiView, kSingleView };
ViewSampling ViewSamplingFromName(const std::string& name);  // "pps" | "uniform"; throws otherwise
RansacViews RansacViewsFromName(const std::string& name);    // "multiview" | "single-view"

struct MultiViewRansacOptions {
  double tau_rad = 0.2 * M_PI / 180.0;  // inlier threshold and truncation of the cost (0.2 deg)
  int min_iterations = 20;              // at least this many hypotheses draws
  int max_iterations = 1000;            // hard bound on draws
  double confidence = 0.999;            // for the adaptive iteration bound
  int min_inliers = 10;                 // fewer: no consensus
  ViewSampling sampling = ViewSampling::kPps;
  RansacViews views = RansacViews::kMultiView;
  uint64_t seed = 0;
  void Check() const;  // throws std::invalid_argument naming the field
};

struct MultiViewRansacReport {
  bool success = false;  // a pose with >= min_inliers inliers was found
  Rigid3 rig_from_world;
  double score = 0.0;  // best sum of max(0, tau - angle)
  int num_inliers = 0;
  int num_correspondences = 0;  // scored correspondences (all views, or the single view)
  double inlier_ratio = 0.0;
  int num_iterations = 0;                  // draws
  int num_hypotheses = 0;                  // P3P solutions scored
  std::vector<std::vector<char>> inliers;  // [camera][i], 1 = inlier of the best pose
  std::vector<int> view_draws;             // how often each view was chosen
  int single_view = -1;                    // the view used in kSingleView mode
};

// correspondences[j] are camera j's; cam_from_rig.size() must equal correspondences.size().
MultiViewRansacReport MultiViewP3PRansac(const std::vector<std::vector<BearingPointCorrespondence>>& correspondences,
                                         const std::vector<Rigid3>& cam_from_rig,
                                         const MultiViewRansacOptions& options);

// ---- The generic loop (PoseLib's robust/ransac_impl.h and COLMAP's RANSAC are the models) ----
// Estimator: `static constexpr int kMinNumSamples`, `using Sample` (a minimal sample), `using Model`,
// `std::vector<Model> Estimate(const Sample&) const`, `RansacScore Score(const Model&) const` (larger
// is better) and `int NumData() const` (the inlier ratio's denominator). Sampler: `Sample
// Draw(std::mt19937_64&)`. The loop keeps the first model of the best score and stops at the adaptive
// bound N = log(1 - confidence) / log(1 - w^kMinNumSamples) (w: the best model's inlier ratio), within
// [min_iterations, max_iterations].
struct RansacScore {
  double score = 0.0;
  int inliers = 0;
};
struct RansacLoopOptions {
  int min_iterations = 20;
  int max_iterations = 1000;
  double confidence = 0.999;
  void Check() const;  // throws std::invalid_argument naming the field
};
template <typename Model>
struct RansacResult {
  bool found = false;  // some model was scored
  Model best{};        // the first model with the best score
  double best_score = -1.0;
  int num_iterations = 0;  // samples drawn
  int num_hypotheses = 0;  // models scored
};

template <typename Estimator, typename Sampler>
RansacResult<typename Estimator::Model> Ransac(const Estimator& estimator, Sampler& sampler, std::mt19937_64& rng,
                                               const RansacLoopOptions& options) {
  options.Check();
  RansacResult<typename Estimator::Model> result;
  int64_t bound = options.max_iterations;
  int iteration = 0;
  for (; iteration < std::max<int64_t>(options.min_iterations, std::min<int64_t>(bound, options.max_iterations));
       ++iteration) {
    const typename Estimator::Sample sample = sampler.Draw(rng);
    for (const typename Estimator::Model& model : estimator.Estimate(sample)) {
      ++result.num_hypotheses;
      const RansacScore s = estimator.Score(model);
      if (!(s.score > result.best_score)) continue;
      result.found = true;
      result.best_score = s.score;
      result.best = model;
      const double w = static_cast<double>(s.inliers) / estimator.NumData();
      double p_good = w;
      for (int k = 1; k < Estimator::kMinNumSamples; ++k) p_good *= w;
      if (p_good >= 1.0 - 1e-12) {
        bound = 0;
      } else if (p_good > 0.0) {
        const double n = std::log(1.0 - options.confidence) / std::log(1.0 - p_good);
        bound = static_cast<int64_t>(std::min<double>(std::ceil(n), options.max_iterations));
      }
    }
  }
  result.num_iterations = iteration;
  return result;
}

// Portable uniform helpers on std::mt19937_64 (the standard distributions differ between libraries).
uint64_t UniformIndex(std::mt19937_64& rng, uint64_t n);  // in [0, n), unbiased; n >= 1
double UniformUnit(std::mt19937_64& rng);                 // in [0, 1), 53 random bits
// Index j with probability weights[j] / sum(weights); weights >= 0 with a positive sum.
int SampleProportional(std::mt19937_64& rng, const std::vector<double>& weights);

}  // namespace rovo
