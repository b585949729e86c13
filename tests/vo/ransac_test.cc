#include "vo/ransac.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "synthetic_rig.h"

namespace rovo {
namespace {

using Correspondences = std::vector<std::vector<BearingPointCorrespondence>>;

// Correspondences of a random rig pose: `per_view[j]` per camera, a fraction `outlier_ratio` of
// them with random bearings.
Correspondences MakeProblem(std::mt19937_64& rng, const std::vector<Rigid3>& cam_from_rig, const Rigid3& rig_from_world,
                            const std::vector<int>& per_view, double outlier_ratio, double noise_rad = 0.0) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Correspondences out(cam_from_rig.size());
  const Rigid3 world_from_rig = rig_from_world.Inverse();
  for (size_t j = 0; j < cam_from_rig.size(); ++j) {
    const Rigid3 cam_from_world = cam_from_rig[j] * rig_from_world;
    while (static_cast<int>(out[j].size()) < per_view[j]) {
      const Eigen::Vector3d point_in_world = world_from_rig * test::RandomPoint(rng);
      const Eigen::Vector3d in_cam = cam_from_world * point_in_world;
      if (!test::InFov220(in_cam)) continue;
      BearingPointCorrespondence c{test::NoisyBearing(rng, in_cam.normalized(), noise_rad), point_in_world};
      if (u(rng) < outlier_ratio) {
        c.bearing_in_cam = Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.2).normalized();
      }
      out[j].push_back(c);
    }
  }
  return out;
}

TEST(UniformHelpers, IndexAndUnitRanges) {
  std::mt19937_64 rng(3);
  std::vector<int> counts(7, 0);
  for (int i = 0; i < 70000; ++i) {
    const uint64_t k = UniformIndex(rng, 7);
    ASSERT_LT(k, 7u);
    ++counts[k];
    const double x = UniformUnit(rng);
    ASSERT_GE(x, 0.0);
    ASSERT_LT(x, 1.0);
  }
  for (int c : counts) EXPECT_NEAR(c, 10000, 400);  // ~4 sigma
}

TEST(MultiViewRansac, FindsPoseWithHalfOutliers) {
  std::mt19937_64 rng(5);
  const auto cam_from_rig = test::SquareRigExtrinsics();
  for (int trial = 0; trial < 10; ++trial) {
    const Rigid3 rig_from_world(test::RandomRotation(rng, 40.0), Eigen::Vector3d(1.0, -2.0, 0.5) * trial * 0.3);
    const auto corrs = MakeProblem(rng, cam_from_rig, rig_from_world, {80, 40, 20, 60}, 0.5);
    MultiViewRansacOptions options;
    options.tau_rad = 0.01;  // the threshold these tests were written for
    options.seed = trial;
    const MultiViewRansacReport report = MultiViewP3PRansac(corrs, cam_from_rig, options);
    ASSERT_TRUE(report.success) << "trial " << trial;
    EXPECT_LT(RotationDistanceDeg(report.rig_from_world.rotation, rig_from_world.rotation) * M_PI / 180.0, 1e-3);
    EXPECT_LT((report.rig_from_world.translation - rig_from_world.translation).norm(), 1e-3);
    EXPECT_NEAR(report.inlier_ratio, 0.5, 0.12);
    EXPECT_EQ(report.num_correspondences, 200);
    EXPECT_LT(report.num_iterations, options.max_iterations);  // adaptive bound stopped early
  }
}

TEST(MultiViewRansac, SameSeedSameResult) {
  std::mt19937_64 rng(9);
  const auto cam_from_rig = test::SquareRigExtrinsics();
  const Rigid3 rig_from_world(test::RandomRotation(rng, 20.0), Eigen::Vector3d(0.3, 0.1, 0.0));
  const auto corrs = MakeProblem(rng, cam_from_rig, rig_from_world, {50, 50, 50, 50}, 0.6, 0.002);
  MultiViewRansacOptions options;
  options.tau_rad = 0.01;  // the threshold these tests were written for
  options.seed = 42;
  const auto a = MultiViewP3PRansac(corrs, cam_from_rig, options);
  const auto b = MultiViewP3PRansac(corrs, cam_from_rig, options);
  EXPECT_EQ(a.num_iterations, b.num_iterations);
  EXPECT_EQ(a.num_inliers, b.num_inliers);
  EXPECT_EQ(a.rig_from_world.Matrix3x4(), b.rig_from_world.Matrix3x4());
}

// PPS: each view is drawn with probability n_j / sum n. With the bound disabled (min = max
// iterations), draw frequencies must match within 5 standard deviations of the binomial.
TEST(MultiViewRansac, PpsDrawsViewsInProportionToSize) {
  std::mt19937_64 rng(13);
  const auto cam_from_rig = test::SquareRigExtrinsics();
  const std::vector<int> sizes = {100, 50, 10, 40};
  const auto corrs = MakeProblem(rng, cam_from_rig, Rigid3(), sizes, 0.9);
  MultiViewRansacOptions options;
  options.tau_rad = 0.01;  // the threshold these tests were written for
  options.min_iterations = options.max_iterations = 4000;
  const auto report = MultiViewP3PRansac(corrs, cam_from_rig, options);
  ASSERT_EQ(report.num_iterations, 4000);
  for (int j = 0; j < 4; ++j) {
    const double p = sizes[j] / 200.0;
    const double expected = 4000 * p;
    const double sigma = std::sqrt(4000 * p * (1 - p));
    EXPECT_NEAR(report.view_draws[j], expected, 5 * sigma) << "view " << j;
  }
  options.sampling = ViewSampling::kUniform;
  const auto uniform = MultiViewP3PRansac(corrs, cam_from_rig, options);
  for (int j = 0; j < 4; ++j) EXPECT_NEAR(uniform.view_draws[j], 1000, 5 * std::sqrt(4000 * 0.25 * 0.75));
}

TEST(MultiViewRansac, SingleViewScoresOneView) {
  std::mt19937_64 rng(17);
  const auto cam_from_rig = test::SquareRigExtrinsics();
  const Rigid3 rig_from_world(test::RandomRotation(rng, 10.0), Eigen::Vector3d(0.5, 0.0, 0.0));
  const auto corrs = MakeProblem(rng, cam_from_rig, rig_from_world, {30, 90, 30, 30}, 0.3);
  MultiViewRansacOptions options;
  options.tau_rad = 0.01;  // the threshold these tests were written for
  options.views = RansacViews::kSingleView;
  const auto report = MultiViewP3PRansac(corrs, cam_from_rig, options);
  ASSERT_TRUE(report.success);
  EXPECT_EQ(report.single_view, 1);
  EXPECT_EQ(report.num_correspondences, 90);
  EXPECT_EQ(report.view_draws[0] + report.view_draws[2] + report.view_draws[3], 0);
  for (int j : {0, 2, 3}) {
    for (char c : report.inliers[j]) EXPECT_EQ(c, 0);
  }
  EXPECT_LT(RotationDistanceDeg(report.rig_from_world.rotation, rig_from_world.rotation), 0.05);
}

TEST(MultiViewRansac, NoConsensusOnPureNoise) {
  std::mt19937_64 rng(19);
  const auto cam_from_rig = test::SquareRigExtrinsics();
  const auto corrs = MakeProblem(rng, cam_from_rig, Rigid3(), {30, 30, 30, 30}, 1.0);
  MultiViewRansacOptions options;
  options.tau_rad = 0.01;  // the threshold these tests were written for
  options.min_inliers = 30;
  EXPECT_FALSE(MultiViewP3PRansac(corrs, cam_from_rig, options).success);
  // Too few correspondences: no draws at all.
  const Correspondences few(4, std::vector<BearingPointCorrespondence>(2, corrs[0][0]));
  const auto report = MultiViewP3PRansac(few, cam_from_rig, options);
  EXPECT_FALSE(report.success);
  EXPECT_EQ(report.num_iterations, 0);
}

TEST(MultiViewRansac, OptionsCheckRejectsBadValues) {
  MultiViewRansacOptions options;
  options.tau_rad = 0.01;  // the threshold these tests were written for
  options.tau_rad = 0.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  EXPECT_THROW(ViewSamplingFromName("ppss"), std::invalid_argument);
  EXPECT_EQ(RansacViewsFromName("single-view"), RansacViews::kSingleView);
}

}  // namespace
}  // namespace rovo
