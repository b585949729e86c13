// Micro-benchmarks of the back-end stages on synthetic rig data (no rendering):
// P3P, one multi-view RANSAC (per hypothesis time in the counters), pose refinement, triangulation
// and one local BA with online extrinsics.
#include <benchmark/benchmark.h>

#include <random>

#include "tests/vo/synthetic_rig.h"
#include "vo/local_ba.h"
#include "vo/p3p.h"
#include "vo/pose_refinement.h"
#include "vo/ransac.h"
#include "vo/triangulation.h"

namespace rovo {
namespace {

std::vector<std::vector<BearingPointCorrespondence>> Correspondences(std::mt19937_64& rng, int per_view,
                                                                     double outlier_ratio) {
  const auto cam_from_rig = test::SquareRigExtrinsics();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::vector<BearingPointCorrespondence>> out(4);
  for (int j = 0; j < 4; ++j) {
    while (static_cast<int>(out[j].size()) < per_view) {
      const Eigen::Vector3d x = test::RandomPoint(rng);
      const Eigen::Vector3d in_cam = cam_from_rig[j] * x;
      if (!test::InFov220(in_cam)) continue;
      Eigen::Vector3d b = test::NoisyBearing(rng, in_cam.normalized(), 0.001);
      if (u(rng) < outlier_ratio) b = Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng)).normalized();
      out[j].push_back({b, x});
    }
  }
  return out;
}

void BM_P3P(benchmark::State& state) {
  std::mt19937_64 rng(1);
  const auto c = Correspondences(rng, 3, 0.0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(SolveP3P({c[0][0].bearing_in_cam, c[0][1].bearing_in_cam, c[0][2].bearing_in_cam},
                                      {c[0][0].point_in_world, c[0][1].point_in_world, c[0][2].point_in_world}));
  }
}
BENCHMARK(BM_P3P);

// 4 views x state.range(0) correspondences, 50% outliers; fixed 200 draws.
void BM_MultiViewRansac(benchmark::State& state) {
  std::mt19937_64 rng(2);
  const auto c = Correspondences(rng, static_cast<int>(state.range(0)), 0.5);
  const auto cam_from_rig = test::SquareRigExtrinsics();
  MultiViewRansacOptions options;
  options.min_iterations = options.max_iterations = 200;
  int64_t hypotheses = 0;
  for (auto _ : state) {
    const auto report = MultiViewP3PRansac(c, cam_from_rig, options);
    hypotheses += report.num_hypotheses;
  }
  // Seconds per hypothesis (printed with an SI prefix, e.g. "3.1u" = 3.1 us).
  state.counters["s_per_hypothesis"] =
      benchmark::Counter(static_cast<double>(hypotheses), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_MultiViewRansac)->Arg(100)->Arg(400)->Unit(benchmark::kMillisecond);

void BM_RefineRigPose(benchmark::State& state) {
  std::mt19937_64 rng(3);
  const auto c = Correspondences(rng, 300, 0.0);
  const auto cam_from_rig = test::SquareRigExtrinsics();
  const Rigid3 start(Eigen::Quaterniond(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ())),
                     Eigen::Vector3d(0.05, 0, 0));
  for (auto _ : state) benchmark::DoNotOptimize(RefineRigPose(c, cam_from_rig, {}, start));
}
BENCHMARK(BM_RefineRigPose)->Unit(benchmark::kMillisecond);

void BM_TriangulateThreeRays(benchmark::State& state) {
  const Eigen::Vector3d x(8, 3, 1);
  std::vector<Ray> rays;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d o(0.5 * k, 0.1 * k, 0);
    rays.push_back({o, (x - o).normalized()});
  }
  for (auto _ : state) benchmark::DoNotOptimize(TriangulateRays(rays));
}
BENCHMARK(BM_TriangulateThreeRays);

// 6 poses, state.range(0) points, 10 iterations; online extrinsics if state.range(1) != 0.
void BM_LocalBa(benchmark::State& state) {
  std::mt19937_64 rng(4);
  LocalBaProblem base;
  base.cam_from_rig = test::SquareRigExtrinsics();
  for (int i = 0; i < 6; ++i)
    base.rig_from_world.push_back(Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0 * i, 0, 0)));
  for (int k = 0; k < state.range(0); ++k) {
    const Eigen::Vector3d x = test::RandomPoint(rng, 4.0, 25.0);
    int cams = 0;
    for (int j = 0; j < 4; ++j) {
      bool seen = false;
      for (int i = 0; i < 6; ++i) {
        const Eigen::Vector3d in_cam = base.cam_from_rig[j] * (base.rig_from_world[i] * x);
        if (!test::InFov220(in_cam)) continue;
        base.observations.push_back({i, j, k, test::NoisyBearing(rng, in_cam.normalized(), 0.001)});
        seen = true;
      }
      cams += seen;
    }
    base.points_in_world.push_back(x);
    base.point_num_cameras.push_back(cams);
  }
  LocalBaOptions options;
  options.optimize_extrinsics = state.range(1) != 0;
  for (auto _ : state) {
    LocalBaProblem p = base;
    benchmark::DoNotOptimize(SolveLocalBa(p, options));
  }
}
BENCHMARK(BM_LocalBa)
    ->ArgNames({"points", "online"})
    ->ArgsProduct({{800, 1500}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rovo
