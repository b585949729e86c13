// Speed of the camera models through Camera (double): Project, Project with Jacobian, Unproject,
// on directions spread over the whole 220-degree FOV (a fixed pseudo-random set, so runs compare).
// Run: build-*/datasets/rovo_datasets_benchmark
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "datasets/camera.h"
#include "datasets/ocam.h"

namespace rovo {
namespace {

constexpr double kDeg = M_PI / 180.0;

Camera MakeCamera(CameraModelId model) {
  switch (model) {
    case CameraModelId::kEquidistant: {
      const double f = 1600.0 / 2.0 / (110.0 * kDeg) * 0.95;
      return Camera{model, 1600, 1532, {f, f, 799.5, 765.5, 0.01, -0.003, 0.0, 0.0}, 220.0};
    }
    case CameraModelId::kDoubleSphere:
      return Camera{model, 1600, 1532, {350.0, 351.0, 799.5, 765.5, -0.2, 0.6}, 220.0};
    case CameraModelId::kExtendedUnified:
      return Camera{model, 1600, 1532, {420.0, 421.0, 799.5, 765.5, 0.62, 1.1}, 220.0};
    case CameraModelId::kOcam:
      return MakeOcamCamera(1600, 1532, 811.661, 756.215, 0.999876, -2.91382e-4, -1.66556e-4,
                            {-392.2, 0.0, 0.00127, -1.746e-6, 2.258e-9}, 220.0);
  }
  return Camera{};
}

// Points uniformly distributed over the solid angle of the FOV, at depths 0.5..50.
std::vector<Eigen::Vector3d> Points(int count) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  const double min_cos = std::cos(110.0 * kDeg);
  while (static_cast<int>(points.size()) < count) {
    const double z = min_cos + (1.0 - min_cos) * unit(rng);
    const double phi = 2 * M_PI * unit(rng);
    const double r = std::sqrt(1 - z * z);
    const double depth = 0.5 + 49.5 * unit(rng);
    points.push_back(depth * Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z));
  }
  return points;
}

constexpr int kNumPoints = 4096;

void BM_Project(benchmark::State& state) {
  const Camera camera = MakeCamera(static_cast<CameraModelId>(state.range(0)));
  const std::vector<Eigen::Vector3d> points = Points(kNumPoints);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.Project(points[i]));
    i = (i + 1) % points.size();
  }
  state.SetLabel(CameraModelName(camera.model));
}

void BM_ProjectWithJacobian(benchmark::State& state) {
  const Camera camera = MakeCamera(static_cast<CameraModelId>(state.range(0)));
  const std::vector<Eigen::Vector3d> points = Points(kNumPoints);
  Eigen::Matrix<double, 2, 3> J;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.Project(points[i], &J));
    benchmark::DoNotOptimize(J);
    i = (i + 1) % points.size();
  }
  state.SetLabel(CameraModelName(camera.model));
}

void BM_Unproject(benchmark::State& state) {
  const Camera camera = MakeCamera(static_cast<CameraModelId>(state.range(0)));
  std::vector<Eigen::Vector2d> pixels;
  for (const Eigen::Vector3d& point : Points(kNumPoints)) pixels.push_back(*camera.Project(point));
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.Unproject(pixels[i]));
    i = (i + 1) % pixels.size();
  }
  state.SetLabel(CameraModelName(camera.model));
}

BENCHMARK(BM_Project)->DenseRange(0, 3);
BENCHMARK(BM_ProjectWithJacobian)->DenseRange(0, 3);
BENCHMARK(BM_Unproject)->DenseRange(0, 3);

}  // namespace
}  // namespace rovo
