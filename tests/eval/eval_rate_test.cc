// rovo eval on trajectories at other rates than the frames (time association) and --align sim3.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/metrics.h"

namespace rovo {
namespace {

// Ground truth at 30 Hz along a curved, climbing path.
Trajectory GroundTruth30Hz(int frames) {
  Trajectory gt;
  for (int i = 0; i < frames; ++i) {
    const double t = 100.0 + i / 30.0;
    const Eigen::Vector3d rotation(0.1 * std::sin(t), 0.05 * std::cos(2.0 * t), 0.4 * t);
    const Eigen::Vector3d position(8.0 * std::cos(0.5 * t), 8.0 * std::sin(0.5 * t), 0.3 * t);
    gt.push_back({t, Rigid3::FromAxisAngle(rotation, position)});
  }
  return gt;
}

RunData AsRun(const Trajectory& trajectory) {
  RunData run;
  run.trajectory = trajectory;
  run.info = {{"mode", "external"}};
  return run;
}

const Rigid3 kWorld = Rigid3::FromAxisAngle(Eigen::Vector3d(0.1, 0.3, -0.8), Eigen::Vector3d(5, 2, -1));

// A 200 Hz estimate: the interpolated ground truth at its times, in another world frame, starting
// before and ending after the ground truth (those poses have no ground truth to compare with).
Trajectory Estimate200Hz(const Trajectory& gt) {
  Trajectory est;
  for (double t = gt.front().timestamp - 0.05; t <= gt.back().timestamp + 0.05; t += 1.0 / 200.0) {
    est.push_back({t, kWorld * InterpolatePose(gt, t)});
  }
  return est;
}

TEST(EvalRate, EstimateAt200HzEqualToTheInterpolatedGroundTruthScoresZero) {
  const Trajectory gt = GroundTruth30Hz(90);
  const Trajectory est = Estimate200Hz(gt);
  const RunMetrics m = EvaluateRun(gt, {}, AsRun(est), "imu_rate").metrics;
  EXPECT_EQ(m.association, "interpolate");
  // Every estimate inside the ground truth's time range is scored: ~ 200 Hz x 2.97 s.
  EXPECT_GT(m.associated_frames, 590);
  EXPECT_LT(m.associated_frames, static_cast<int>(est.size()) - 15);
  EXPECT_EQ(m.missing_frames, 0);
  ASSERT_TRUE(m.rmse_se3_m.has_value());
  EXPECT_LT(*m.rmse_se3_m, 1e-9);
  EXPECT_LT(*m.rmse_origin_m, 1e-9);
  EXPECT_LT(m.drift.translation_pct, 1e-7);
  EXPECT_GT(m.rpe.num_pairs, 100);
  EXPECT_LT(m.rpe.translation_rmse_m, 1e-9);
}

TEST(EvalRate, NearestAssociationAt200HzCountsTheInterpolationOffsetAsError) {
  // The same estimate, associated by nearest time instead: each frame pairs with an estimate up to
  // 2.5 ms away, so the error is the motion within that time, not zero.
  const Trajectory gt = GroundTruth30Hz(90);
  EvalOptions options;
  options.association = "nearest";
  const RunMetrics m = EvaluateRun(gt, {}, AsRun(Estimate200Hz(gt)), "nearest", options).metrics;
  EXPECT_EQ(m.association, "nearest");
  EXPECT_EQ(m.associated_frames, 90);
  EXPECT_GT(*m.rmse_se3_m, 1e-4);
}

TEST(EvalRate, LowerRateEstimateIsInterpolatedAndScoresZero) {
  // 10 Hz, at times between the frames.
  const Trajectory gt = GroundTruth30Hz(90);
  Trajectory est;
  for (double t = gt.front().timestamp + 0.013; t < gt.back().timestamp; t += 0.1) {
    est.push_back({t, kWorld * InterpolatePose(gt, t)});
  }
  const RunMetrics m = EvaluateRun(gt, {}, AsRun(est), "slow").metrics;
  EXPECT_EQ(m.association, "interpolate");
  EXPECT_EQ(m.associated_frames, static_cast<int>(est.size()));
  EXPECT_EQ(m.missing_frames, 0);
  EXPECT_LT(*m.rmse_se3_m, 1e-9);
}

TEST(EvalAlign, Sim3ScaledTrajectoryScoresZeroWithSim3AndBadlyWithSe3) {
  const Trajectory gt = GroundTruth30Hz(120);
  const double scale = 0.37;  // a monocular system's arbitrary unit
  Trajectory est = gt;
  for (StampedPose& p : est) {
    p.world_from_rig = kWorld * p.world_from_rig;
    p.world_from_rig.translation *= scale;
  }
  EvalOptions sim3;
  sim3.align = "sim3";
  const RunMetrics with_sim3 = EvaluateRun(gt, {}, AsRun(est), "sim3", sim3).metrics;
  EXPECT_EQ(with_sim3.align, "sim3");
  EXPECT_NEAR(with_sim3.scale, 1.0 / scale, 1e-9);
  EXPECT_LT(*with_sim3.rmse_se3_m, 1e-9);
  EXPECT_LT(with_sim3.drift.translation_pct, 1e-7);
  EXPECT_LT(with_sim3.rpe.translation_rmse_m, 1e-9);

  const RunMetrics with_se3 = EvaluateRun(gt, {}, AsRun(est), "se3").metrics;
  EXPECT_EQ(with_se3.scale, 1.0);
  EXPECT_GT(*with_se3.rmse_se3_m, 1.0);
  EXPECT_GT(with_se3.drift.translation_pct, 50.0);
}

TEST(EvalOptionsCheck, UnknownValuesNameTheField) {
  const Trajectory gt = GroundTruth30Hz(10);
  EvalOptions bad;
  bad.align = "sim2";
  try {
    EvaluateRun(gt, {}, AsRun(gt), "x", bad);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("align `sim2`"), std::string::npos) << e.what();
  }
  bad = EvalOptions();
  bad.association = "closest";
  EXPECT_THROW(EvaluateRun(gt, {}, AsRun(gt), "x", bad), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
