#include "vo/triangulation.h"

#include <gtest/gtest.h>

#include <random>

#include "synthetic_rig.h"

namespace rovo {
namespace {

TEST(Triangulation, ExactBearingsRecoverPoint) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int tested = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Vector3d point = test::RandomPoint(rng, 2.0, 40.0);
    const int n = 2 + trial % 4;
    std::vector<Ray> rays;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d origin(u(rng), u(rng), u(rng) * 0.3);
      rays.push_back({origin, (point - origin).normalized()});
    }
    TriangulationOptions options;
    options.min_parallax_deg = 0.5;
    const auto result = TriangulateRays(rays, options);
    double parallax = 0.0;
    for (const Ray& a : rays) {
      for (const Ray& b : rays) parallax = std::max(parallax, AngleBetween(a.direction_in_world, b.direction_in_world));
    }
    if (parallax * 180.0 / M_PI < 0.5) {
      EXPECT_FALSE(result.has_value());
      continue;
    }
    ASSERT_TRUE(result.has_value()) << "trial " << trial;
    EXPECT_LT((result->point_in_world - point).norm(), 1e-6 * point.norm()) << "trial " << trial;
    EXPECT_LT(result->max_error_deg, 1e-6);
    ++tested;
  }
  EXPECT_GT(tested, 400);
}

TEST(Triangulation, RaysBehindCameraAndFromOppositeSides) {
  // Two cameras 1 m apart, point behind both optical axes is irrelevant: only directions matter.
  const Eigen::Vector3d point(-3.0, 5.0, 1.0);
  const Ray a{Eigen::Vector3d(0, 0, 0), (point - Eigen::Vector3d(0, 0, 0)).normalized()};
  const Ray b{Eigen::Vector3d(1, 0, 0), (point - Eigen::Vector3d(1, 0, 0)).normalized()};
  const auto result = TriangulateTwoRays(a, b);
  ASSERT_TRUE(result.has_value());
  EXPECT_LT((result->point_in_world - point).norm(), 1e-9);
}

TEST(Triangulation, RejectsCheiralityParallaxAndError) {
  const Eigen::Vector3d point(10.0, 0.0, 0.0);
  const Ray a{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitX()};
  const Ray b{Eigen::Vector3d(0, 1, 0), (point - Eigen::Vector3d(0, 1, 0)).normalized()};
  EXPECT_TRUE(TriangulateTwoRays(a, b).has_value());
  // Both rays flipped: the lines meet at the same point but behind both origins.
  const Ray a_back{a.origin_in_world, -a.direction_in_world};
  const Ray b_back{b.origin_in_world, -b.direction_in_world};
  EXPECT_FALSE(TriangulateTwoRays(a_back, b_back).has_value());
  // Nearly parallel rays: 1 m baseline at 1 km.
  const Ray far_b{Eigen::Vector3d(0, 1, 0), (Eigen::Vector3d(1000, 0, 0) - Eigen::Vector3d(0, 1, 0)).normalized()};
  EXPECT_FALSE(TriangulateTwoRays(a, far_b).has_value());
  // Skew rays that miss each other by a lot: angular error too large.
  const Ray skew{Eigen::Vector3d(0, 1, 2), (point - Eigen::Vector3d(0, 1, 0)).normalized()};
  EXPECT_FALSE(TriangulateTwoRays(a, skew).has_value());
}

TEST(Triangulation, NoisyMultiViewBeatsTwoView) {
  std::mt19937_64 rng(31);
  double err2 = 0.0, err6 = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d point = test::RandomPoint(rng, 5.0, 15.0);
    std::vector<Ray> rays;
    for (int k = 0; k < 6; ++k) {
      const Eigen::Vector3d origin(0.3 * k, 0.2 * (k % 2), 0.0);
      rays.push_back({origin, test::NoisyBearing(rng, (point - origin).normalized(), 0.001)});
    }
    const auto two = TriangulateTwoRays(rays[0], rays[5]);
    const auto six = TriangulateRays(rays);
    if (!two || !six) continue;
    err2 += (two->point_in_world - point).norm();
    err6 += (six->point_in_world - point).norm();
  }
  EXPECT_LT(err6, err2);
}

}  // namespace
}  // namespace rovo
