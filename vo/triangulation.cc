#include "vo/triangulation.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>

#include "datasets/rigid3.h"

namespace rovo {

void TriangulationOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("TriangulationOptions.") + what);
  };
  require(min_parallax_deg >= 0.0, "min_parallax_deg must be >= 0");
  require(max_error_deg > 0.0, "max_error_deg must be > 0");
  require(max_distance > 0.0, "max_distance must be > 0");
  require(gauss_newton_iterations >= 0, "gauss_newton_iterations must be >= 0");
}

std::optional<TriangulatedPoint> TriangulateRays(const std::vector<Ray>& rays, const TriangulationOptions& options) {
  options.Check();
  if (rays.size() < 2) return std::nullopt;
  TriangulatedPoint out;
  double max_parallax = 0.0;
  for (size_t a = 0; a < rays.size(); ++a) {
    for (size_t b = a + 1; b < rays.size(); ++b) {
      max_parallax = std::max(max_parallax, AngleBetween(rays[a].direction_in_world, rays[b].direction_in_world));
    }
  }
  out.parallax_deg = max_parallax * 180.0 / M_PI;
  if (out.parallax_deg < options.min_parallax_deg) return std::nullopt;

  Eigen::Matrix3d lhs = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (const Ray& ray : rays) {
    const Eigen::Matrix3d proj =
        Eigen::Matrix3d::Identity() - ray.direction_in_world * ray.direction_in_world.transpose();
    lhs += proj;
    rhs += proj * ray.origin_in_world;
  }
  Eigen::LDLT<Eigen::Matrix3d> ldlt(lhs);
  if (ldlt.info() != Eigen::Success) return std::nullopt;
  Eigen::Vector3d x = ldlt.solve(rhs);
  if (!x.allFinite()) return std::nullopt;

  // Gauss-Newton on r_k = d_k - (X - o_k)/|X - o_k|, dr/dX = -(I - u u^T)/|X - o_k|.
  auto cost = [&](const Eigen::Vector3d& p) {
    double c = 0.0;
    for (const Ray& ray : rays) c += (ray.direction_in_world - (p - ray.origin_in_world).normalized()).squaredNorm();
    return c;
  };
  double current = cost(x);
  for (int it = 0; it < options.gauss_newton_iterations; ++it) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (const Ray& ray : rays) {
      const Eigen::Vector3d v = x - ray.origin_in_world;
      const double n = v.norm();
      if (n <= 0.0) return std::nullopt;
      const Eigen::Vector3d u = v / n;
      const Eigen::Matrix3d jac = -(Eigen::Matrix3d::Identity() - u * u.transpose()) / n;
      const Eigen::Vector3d r = ray.direction_in_world - u;
      jtj += jac.transpose() * jac;
      jtr += jac.transpose() * r;
    }
    const Eigen::Vector3d step = jtj.ldlt().solve(-jtr);
    if (!step.allFinite()) break;
    const Eigen::Vector3d next = x + step;
    const double next_cost = cost(next);
    if (!(next_cost < current)) break;
    x = next;
    current = next_cost;
    if (step.norm() < 1e-12 * (1.0 + x.norm())) break;
  }

  double max_error = 0.0;
  for (const Ray& ray : rays) {
    const Eigen::Vector3d v = x - ray.origin_in_world;
    if (ray.direction_in_world.dot(v) <= 0.0) return std::nullopt;  // cheirality
    if (v.norm() > options.max_distance) return std::nullopt;
    max_error = std::max(max_error, AngleBetween(ray.direction_in_world, v));
  }
  out.max_error_deg = max_error * 180.0 / M_PI;
  if (out.max_error_deg > options.max_error_deg) return std::nullopt;
  out.point_in_world = x;
  return out;
}

}  // namespace rovo
