#include "eval/body_offset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "eval/format.h"
#include "eval/metrics.h"
#include "eval/report.h"
#include "eval/suite_summary.h"
#include "eval/suite_table.h"

namespace rovo {
namespace {

// A drone-like path that turns about all three axes (hand-eye fully observable).
Trajectory SpatialPath(int n, double dt) {
  Trajectory gt;
  for (int i = 0; i < n; ++i) {
    const double s = i * dt;
    const Eigen::Vector3d rotation(0.4 * std::sin(0.7 * s), 0.3 * std::cos(0.5 * s), 0.25 * s);
    const Eigen::Vector3d position(12.0 * std::cos(0.2 * s), 9.0 * std::sin(0.25 * s), 1.5 * std::sin(0.6 * s));
    gt.push_back({s, Rigid3::FromAxisAngle(rotation, position)});
  }
  return gt;
}

// A car-like path: rotations about the vertical only.
Trajectory PlanarPath(int n, double dt) {
  Trajectory gt;
  for (int i = 0; i < n; ++i) {
    const double s = i * dt;
    const double yaw = 0.3 * s + 0.4 * std::sin(0.5 * s);
    const Eigen::Vector3d position(15.0 * std::sin(0.2 * s), 6.0 * (1.0 - std::cos(0.3 * s)), 0.0);
    gt.push_back({s, Rigid3::FromAxisAngle(Eigen::Vector3d(0, 0, yaw), position)});
  }
  return gt;
}

// est_i = world * poses_i * rig_from_body.
Trajectory WithOffsets(const Trajectory& poses, const Rigid3& world, const Rigid3& rig_from_body) {
  Trajectory out = poses;
  for (StampedPose& p : out) p.world_from_rig = world * p.world_from_rig * rig_from_body;
  return out;
}

// Poses with a slowly accumulating error (a drifting odometry) and per-pose jitter, seeded.
Trajectory Drifting(const Trajectory& gt, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> jitter(0.0, 1.0);
  Trajectory out = gt;
  Rigid3 drift;
  for (size_t i = 1; i < gt.size(); ++i) {
    const Rigid3 step = gt[i - 1].world_from_rig.Inverse() * gt[i].world_from_rig;
    const Rigid3 noise = Rigid3::FromAxisAngle(Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)) * 2e-4,
                                               Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)) * 2e-3);
    drift = drift * step * noise;
    out[i].world_from_rig = out[0].world_from_rig * drift;
  }
  return out;
}

Association Identity(size_t n) {
  Association a;
  for (size_t i = 0; i < n; ++i) a.pairs.emplace_back(static_cast<int>(i), static_cast<int>(i));
  return a;
}

const Rigid3 kWorld = Rigid3::FromAxisAngle(Eigen::Vector3d(0.2, -0.4, 1.1), Eigen::Vector3d(30, -7, 2));
const Rigid3 kBody = Rigid3::FromAxisAngle(Eigen::Vector3d(0.05, -0.08, 0.12), Eigen::Vector3d(0.4, -0.3, 0.25));

TEST(BodyOffset, RecoversBodyAndWorldOffsetsWithoutNoise) {
  const Trajectory gt = SpatialPath(200, 0.1);
  const Trajectory est = WithOffsets(gt, kWorld, kBody);
  const BodyOffset offset = EstimateBodyOffset(gt, est, Identity(gt.size()));
  ASSERT_TRUE(offset.valid) << offset.note;
  EXPECT_EQ(offset.translation_rank, 3);
  EXPECT_LT(RotationDistanceDeg(offset.rig_from_body.rotation, kBody.rotation) * M_PI / 180.0, 1e-9);
  EXPECT_LT((offset.rig_from_body.translation - kBody.translation).norm(), 1e-9);
  // With the body offset removed, the world offset is what origin alignment finds.
  const Trajectory aligned = RemoveBodyOffset(est, offset.rig_from_body);
  const Rigid3 world = AlignOrigin(gt, aligned, Identity(gt.size())).Inverse();
  EXPECT_LT(RotationDistanceDeg(world.rotation, kWorld.rotation) * M_PI / 180.0, 1e-9);
  EXPECT_LT((world.translation - kWorld.translation).norm(), 1e-9);
}

TEST(BodyOffset, PlanarMotionLeavesTheVerticalTranslationFree) {
  const Trajectory gt = PlanarPath(300, 0.1);
  const Trajectory est = WithOffsets(gt, kWorld, kBody);
  const BodyOffset offset = EstimateBodyOffset(gt, est, Identity(gt.size()));
  ASSERT_TRUE(offset.valid) << offset.note;
  EXPECT_EQ(offset.translation_rank, 2);
  ASSERT_EQ(offset.free_axes.size(), 1u);
  EXPECT_NEAR(std::abs(offset.free_axes[0].z()), 1.0, 1e-9);
  EXPECT_NE(offset.note.find("left at 0"), std::string::npos);
  // The rotation (its yaw included, fixed by the translations) and the horizontal lever arm are exact.
  EXPECT_LT(RotationDistanceDeg(offset.rig_from_body.rotation, kBody.rotation) * M_PI / 180.0, 1e-9);
  EXPECT_LT((offset.rig_from_body.translation.head<2>() - kBody.translation.head<2>()).norm(), 1e-9);
  EXPECT_NEAR(offset.rig_from_body.translation.z(), 0.0, 1e-9);
}

TEST(BodyOffset, StraightLineCannotDetermineTheRotation) {
  Trajectory gt;
  for (int i = 0; i < 20; ++i) gt.push_back({0.1 * i, Rigid3(Eigen::Quaterniond::Identity(), {1.0 * i, 0, 0})});
  const BodyOffset offset = EstimateBodyOffset(gt, WithOffsets(gt, kWorld, kBody), Identity(gt.size()));
  EXPECT_FALSE(offset.valid);
  EXPECT_NE(offset.note.find("one direction"), std::string::npos);
}

RunData AsRun(const Trajectory& trajectory) {
  RunData run;
  run.trajectory = trajectory;
  run.info = {{"mode", "external"}};
  return run;
}

TEST(BodyOffset, BodyAlignedMetricsEqualThoseOfTheUnoffsetTrajectory) {
  const Trajectory gt = SpatialPath(300, 0.1);
  const Trajectory drifting = Drifting(gt, 7);
  const RunMetrics plain = EvaluateRun(gt, {}, AsRun(drifting), "plain").metrics;
  const RunMetrics offset = EvaluateRun(gt, {}, AsRun(WithOffsets(drifting, kWorld, kBody)), "offset").metrics;
  // The raw figures count the body offset as error ...
  EXPECT_GT(offset.drift.translation_pct, 5.0 * plain.drift.translation_pct);
  EXPECT_GT(offset.rpe.rotation_rmse_deg, 5.0 * plain.rpe.rotation_rmse_deg);
  ASSERT_TRUE(offset.body.available) << offset.body.note;
  ASSERT_TRUE(plain.body.available) << plain.body.note;
  // Up to the drift's share in it (0.011 deg per step, a random walk over the strides).
  EXPECT_NEAR(offset.body.offset_rotation_deg, RotationAngleDeg(kBody.rotation), 0.2);
  EXPECT_LT((offset.body.offset_translation_m - kBody.translation).norm(), 0.02);
  // ... the body-aligned ones equal the un-offset trajectory's (the same offset estimate on both,
  // up to the noise's share in it).
  auto near = [](double a, double b) { return std::abs(a - b) <= 0.03 * std::max(std::abs(a), std::abs(b)) + 1e-6; };
  EXPECT_TRUE(near(offset.body.drift.translation_pct, plain.body.drift.translation_pct))
      << offset.body.drift.translation_pct << " vs " << plain.body.drift.translation_pct;
  EXPECT_TRUE(near(offset.body.rpe.translation_pct, plain.body.rpe.translation_pct))
      << offset.body.rpe.translation_pct << " vs " << plain.body.rpe.translation_pct;
  EXPECT_TRUE(near(offset.body.rpe.rotation_rmse_deg, plain.body.rpe.rotation_rmse_deg))
      << offset.body.rpe.rotation_rmse_deg << " vs " << plain.body.rpe.rotation_rmse_deg;
  EXPECT_TRUE(near(*offset.body.rmse_origin_m, *plain.body.rmse_origin_m))
      << *offset.body.rmse_origin_m << " vs " << *plain.body.rmse_origin_m;
  // The un-offset trajectory's own offset estimate is near the identity, so its body-aligned
  // figures stay near its raw ones.
  EXPECT_LT(plain.body.offset_rotation_deg, 0.2);
  EXPECT_TRUE(std::abs(plain.body.drift.translation_pct - plain.drift.translation_pct) <
              0.2 * plain.drift.translation_pct);
}

TEST(BodyOffset, NoiseFreeOffsetTrajectoryScoresZeroAfterRemoval) {
  const Trajectory gt = SpatialPath(200, 0.1);
  const RunMetrics m = EvaluateRun(gt, {}, AsRun(WithOffsets(gt, kWorld, kBody)), "offset").metrics;
  EXPECT_GT(m.drift.translation_pct, 1.0);
  EXPECT_GT(*m.rmse_origin_m, 1.0);
  ASSERT_TRUE(m.body.available);
  EXPECT_LT(m.body.drift.translation_pct, 1e-7);
  EXPECT_LT(m.body.rpe.translation_rmse_m, 1e-9);
  EXPECT_LT(m.body.rpe.rotation_rmse_deg, 1e-7);
  EXPECT_LT(*m.body.rmse_origin_m, 1e-9);
}

TEST(BodyOffset, TablesAndJsonCarryRawAndBodyAlignedFigures) {
  const Trajectory gt = SpatialPath(200, 0.1);
  RunMetrics m = EvaluateRun(gt, {}, AsRun(WithOffsets(Drifting(gt, 3), kWorld, kBody)), "sys").metrics;
  m.mode = "online";
  const std::string table = RunTableMarkdown({m});
  EXPECT_NE(table.find("drift [%] raw → body-aligned"), std::string::npos) << table;
  EXPECT_NE(table.find(Fmt("%.3f", m.drift.translation_pct) + " → " + Fmt("%.3f", m.body.drift.translation_pct)),
            std::string::npos)
      << table;
  EXPECT_NE(MetricsLegendMarkdown().find("hand-eye"), std::string::npos);
  // metrics.json keeps the raw keys and adds the body-aligned ones; they read back.
  const nlohmann::json j = MetricsToJson(m);
  EXPECT_DOUBLE_EQ(j["drift_translation_pct"].get<double>(), m.drift.translation_pct);
  EXPECT_DOUBLE_EQ(j["body_aligned_drift_translation_pct"].get<double>(), m.body.drift.translation_pct);
  const RunMetrics back = MetricsFromJson(j, "test");
  EXPECT_DOUBLE_EQ(back.body.rpe.rotation_rmse_deg, m.body.rpe.rotation_rmse_deg);
  EXPECT_DOUBLE_EQ(*back.body.rmse_origin_m, *m.body.rmse_origin_m);
  EXPECT_EQ(back.body.offset_translation_rank, 3);
  // A metrics.json written before these keys existed still reads.
  nlohmann::json old = j;
  for (const char* key : {"body_aligned_drift_translation_pct", "rpe_translation_pct", "align", "association"}) {
    old.erase(key);
  }
  EXPECT_NO_THROW(MetricsFromJson(old, "old"));
  // The suite aggregates them and Table I shows raw → body-aligned drift.
  PresetSummary preset;
  preset.preset = "cloudy_urban";
  preset.modes = SummariseModes({m});
  const auto stat = preset.Find("online")->Find("body_aligned_drift_translation_pct");
  ASSERT_TRUE(stat.has_value());
  EXPECT_DOUBLE_EQ(stat->mean, m.body.drift.translation_pct);
  const std::string suite = SuiteTableMarkdown({preset}, true);
  EXPECT_NE(suite.find(Fmt("%.2f", m.drift.translation_pct) + " → " + Fmt("%.2f", m.body.drift.translation_pct)),
            std::string::npos)
      << suite;
}

}  // namespace
}  // namespace rovo
