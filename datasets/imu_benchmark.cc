// Cost of the IMU of `rovo render --imu` for a whole static_urban-length sequence (3000 frames at
// 10 Hz, 300 s): the continuous-time ground truth's construction, the simulation at 200 Hz
// (60001 samples) and the three csv files.
// Run: build/datasets/rovo_datasets_benchmark --benchmark_filter=Imu
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "datasets/imu_model.h"
#include "datasets/rig.h"

namespace rovo {
namespace {

Trajectory Drive(int frames) {
  Trajectory traj;
  for (int i = 0; i < frames; ++i) {
    const double s = static_cast<double>(i) / (frames - 1);
    traj.push_back(
        {i * 0.1, Rigid3(QuaternionFromRollPitchYawDeg(2.0 * std::sin(40.0 * s), 1.0 * std::cos(30.0 * s), 720.0 * s),
                         Eigen::Vector3d(1500.0 * s, 200.0 * std::sin(6.0 * s), 0.2 * std::sin(50.0 * s)))});
  }
  return traj;
}

void BM_ImuContinuousTrajectory(benchmark::State& state) {
  const Trajectory traj = Drive(3000);
  for (auto _ : state) benchmark::DoNotOptimize(ContinuousTrajectory(traj));
}

void BM_ImuSimulate(benchmark::State& state) {
  const ContinuousTrajectory curve(Drive(3000));
  const ImuSettings settings;
  for (auto _ : state) benchmark::DoNotOptimize(SimulateImu(curve, PresetImuFromRig(), settings, 1, nullptr));
}

void BM_ImuWriteStreams(benchmark::State& state) {
  const ContinuousTrajectory curve(Drive(3000));
  const ImuStreams streams = SimulateImu(curve, PresetImuFromRig(), ImuSettings(), 1, nullptr);
  const std::string dir = (std::filesystem::temp_directory_path() / "rovo_imu_benchmark").string();
  for (auto _ : state) WriteImuStreams(dir, streams);
  std::filesystem::remove_all(dir);
}

BENCHMARK(BM_ImuContinuousTrajectory)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ImuSimulate)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ImuWriteStreams)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rovo
