#include "eval/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rovo {
namespace {

std::vector<Eigen::Vector3d> RandomPoints(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  return points;
}

Trajectory FromPositions(const std::vector<Eigen::Vector3d>& positions, double dt = 0.1) {
  Trajectory trajectory;
  for (size_t i = 0; i < positions.size(); ++i) {
    trajectory.push_back({static_cast<double>(i) * dt, Rigid3(Eigen::Quaterniond::Identity(), positions[i])});
  }
  return trajectory;
}

Association Identity(size_t n) {
  Association a;
  for (size_t i = 0; i < n; ++i) a.pairs.emplace_back(static_cast<int>(i), static_cast<int>(i));
  return a;
}

TEST(Umeyama, RecoversRigidTransform) {
  const std::vector<Eigen::Vector3d> src = RandomPoints(20, 1);
  const Rigid3 dst_from_src = Rigid3::FromAxisAngle(Eigen::Vector3d(0.3, -1.2, 0.7), Eigen::Vector3d(4, -2, 9));
  std::vector<Eigen::Vector3d> dst;
  for (const auto& p : src) dst.push_back(dst_from_src * p);
  const UmeyamaResult r = AlignUmeyama(src, dst, false);
  EXPECT_NEAR(r.scale, 1.0, 0.0);
  EXPECT_LT((r.rotation - dst_from_src.RotationMatrix()).norm(), 1e-12);
  EXPECT_LT((r.translation - dst_from_src.translation).norm(), 1e-10);
}

TEST(Umeyama, RecoversSimilarity) {
  const std::vector<Eigen::Vector3d> src = RandomPoints(15, 2);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d translation(-1, 0.5, 3);
  const double scale = 2.5;
  std::vector<Eigen::Vector3d> dst;
  for (const auto& p : src) dst.push_back(scale * rotation * p + translation);
  const UmeyamaResult r = AlignUmeyama(src, dst, true);
  EXPECT_NEAR(r.scale, scale, 1e-12);
  EXPECT_LT((r.rotation - rotation).norm(), 1e-12);
  EXPECT_LT((r.translation - translation).norm(), 1e-10);
  // Without scale the rotation is still right (the optimal rotation does not depend on scale).
  const UmeyamaResult rigid = AlignUmeyama(src, dst, false);
  EXPECT_LT((rigid.rotation - rotation).norm(), 1e-12);
}

TEST(Umeyama, ReflectionGivesNearestRotation) {
  // dst is the mirror image of src (z -> -z). The best orthogonal map is the reflection; the sign
  // correction must return a proper rotation. With spread 100 > 10 > 1 along x, y, z the best
  // rotation keeps x and y and leaves z (the least spread) wrong: the identity.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Eigen::Vector3d> src, dst;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(10.0 * n(rng), 3.0 * n(rng), 1.0 * n(rng));
    src.push_back(p);
    dst.push_back(Eigen::Vector3d(p.x(), p.y(), -p.z()));
  }
  // Make the sample covariance exactly diagonal-dominant in x, y, z order is not guaranteed; check
  // the properties that must hold for any input.
  const UmeyamaResult r = AlignUmeyama(src, dst, false);
  EXPECT_NEAR(r.rotation.determinant(), 1.0, 1e-12);
  EXPECT_LT((r.rotation.transpose() * r.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT((r.rotation - Eigen::Matrix3d::Identity()).norm(), 0.05);
}

TEST(Umeyama, ReflectionExactCase) {
  // Symmetric points: sample cross-covariance is exactly diag(100, 10, -1) * const.
  std::vector<Eigen::Vector3d> src, dst;
  for (double s : {-1.0, 1.0}) {
    src.emplace_back(10.0 * s, 0, 0);
    src.emplace_back(0, std::sqrt(10.0) * s, 0);
    src.emplace_back(0, 0, 1.0 * s);
  }
  for (const auto& p : src) dst.emplace_back(p.x(), p.y(), -p.z());
  const UmeyamaResult r = AlignUmeyama(src, dst, false);
  EXPECT_LT((r.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(Umeyama, RejectsCollinearInput) {
  std::vector<Eigen::Vector3d> src, dst;
  for (int i = 0; i < 10; ++i) {
    src.emplace_back(i * 1.0, i * 2.0, -i * 0.5);
    dst.emplace_back(i * 1.0 + 1, 0, 0);
  }
  try {
    AlignUmeyama(src, dst, false);
    FAIL() << "collinear input accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("collinear"), std::string::npos) << e.what();
  }
  // All points at one position, too few points, size mismatch.
  std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_THROW(AlignUmeyama(same, same, false), std::invalid_argument);
  EXPECT_THROW(AlignUmeyama({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 0)},
                            {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 0)}, false),
               std::invalid_argument);
  EXPECT_THROW(AlignUmeyama(RandomPoints(4, 5), RandomPoints(5, 6), false), std::invalid_argument);
}

TEST(Rmse, OriginAlignmentByHand) {
  // gt along x; the estimate leaves the line by 1 m at the middle frame. Origin alignment is the
  // identity (same first pose), errors 0, 1, 0 -> RMSE sqrt(1/3).
  const Trajectory gt = FromPositions({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}});
  const Trajectory est = FromPositions({{0, 0, 0}, {1, 1, 0}, {2, 0, 0}});
  const Association a = Identity(3);
  const Rigid3 origin = AlignOrigin(gt, est, a);
  EXPECT_LT((origin.translation).norm(), 1e-15);
  EXPECT_NEAR(TranslationRmse(gt, est, a, origin), std::sqrt(1.0 / 3.0), 1e-15);
}

TEST(Rmse, OriginAlignmentUsesFirstPoseRotation) {
  // The estimate is the gt seen from a world rotated by 90 deg about z and shifted: origin
  // alignment through the first pose (including its rotation) maps it back exactly.
  Trajectory gt = FromPositions({{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 3, 1}});
  const Rigid3 est_from_gt = Rigid3::FromAxisAngle(Eigen::Vector3d(0, 0, M_PI / 2), Eigen::Vector3d(5, 6, 7));
  Trajectory est = gt;
  for (auto& p : est) p.world_from_rig = est_from_gt * p.world_from_rig;
  const Association a = Identity(gt.size());
  EXPECT_NEAR(TranslationRmse(gt, est, a, AlignOrigin(gt, est, a)), 0.0, 1e-12);
  EXPECT_NEAR(TranslationRmse(gt, est, a, AlignSe3(gt, est, a)), 0.0, 1e-12);
}

TEST(Rmse, Se3AlignmentByHand) {
  // Unit square in the plane z = 0; the estimate is the square rotated 30 deg about z, shifted, with
  // out-of-plane errors +0.1, -0.1, +0.1, -0.1 (a saddle, orthogonal to every tilt and shift), so
  // the optimal alignment is the exact inverse transform and the RMSE is 0.1.
  const Trajectory gt = FromPositions({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  const Rigid3 est_from_gt = Rigid3::FromAxisAngle(Eigen::Vector3d(0, 0, M_PI / 6), Eigen::Vector3d(3, -2, 1));
  Trajectory est = gt;
  const double offsets[] = {0.1, -0.1, 0.1, -0.1};
  for (size_t i = 0; i < est.size(); ++i) {
    est[i].world_from_rig.translation =
        est_from_gt * gt[i].world_from_rig.translation + Eigen::Vector3d(0, 0, offsets[i]);
  }
  const Association a = Identity(4);
  const Rigid3 gt_from_est = AlignSe3(gt, est, a);
  EXPECT_LT(RotationDistanceDeg(gt_from_est.rotation, est_from_gt.Inverse().rotation), 1e-9);
  EXPECT_NEAR(TranslationRmse(gt, est, a, gt_from_est), 0.1, 1e-12);
}

TEST(Drift, ScaleDriftOfOnePercent) {
  // Straight 100 m at 1 m per frame; the estimate overestimates every motion by 1%.
  std::vector<Eigen::Vector3d> gt_positions, est_positions;
  for (int i = 0; i <= 100; ++i) {
    gt_positions.emplace_back(i, 0, 0);
    est_positions.emplace_back(1.01 * i, 0, 0);
  }
  const Trajectory gt = FromPositions(gt_positions), est = FromPositions(est_positions);
  const DriftResult d = RelativeDrift(gt, est, Identity(gt.size()));
  ASSERT_EQ(d.segment_lengths_m.size(), 8u);
  EXPECT_NEAR(d.segment_lengths_m.front(), 10.0, 1e-12);
  EXPECT_NEAR(d.segment_lengths_m.back(), 80.0, 1e-12);
  EXPECT_GT(d.num_segments, 100);
  EXPECT_NEAR(d.translation_pct, 1.0, 1e-9);
  EXPECT_NEAR(d.rotation_deg_per_100m, 0.0, 1e-9);
}

TEST(Drift, HeadingDriftPerMetre) {
  // Positions exact, heading error growing 0.01 deg per metre -> 1 deg / 100 m.
  std::vector<Eigen::Vector3d> positions;
  for (int i = 0; i <= 100; ++i) positions.emplace_back(i, 0, 0);
  const Trajectory gt = FromPositions(positions);
  Trajectory est = gt;
  for (size_t i = 0; i < est.size(); ++i) {
    est[i].world_from_rig.rotation = QuaternionFromRollPitchYawDeg(0, 0, 0.01 * static_cast<double>(i));
  }
  const DriftResult d = RelativeDrift(gt, est, Identity(gt.size()));
  EXPECT_NEAR(d.rotation_deg_per_100m, 1.0, 1e-9);
  // A perfect estimate has no drift.
  EXPECT_NEAR(RelativeDrift(gt, gt, Identity(gt.size())).translation_pct, 0.0, 1e-12);
}

TEST(Association, ReportsMissingFramesAndStrayEstimates) {
  std::vector<Eigen::Vector3d> positions;
  for (int i = 0; i < 10; ++i) positions.emplace_back(i, 0, 0);
  const Trajectory gt = FromPositions(positions, 0.1);
  Trajectory est;
  for (int i = 0; i < 10; ++i) {
    if (i == 3 || i == 7) continue;  // lost frames
    const double jitter = (i == 5) ? 0.01 : 0.0;
    est.push_back({i * 0.1 + jitter, gt[static_cast<size_t>(i)].world_from_rig});
  }
  est.push_back({5.0, Rigid3()});  // far outside the gt time range
  const Association a = AssociateByTimestamp(gt, est, 0.025);
  ASSERT_EQ(a.pairs.size(), 8u);
  EXPECT_EQ(a.gt_without_estimate, (std::vector<int>{3, 7}));
  EXPECT_EQ(a.estimate_without_gt, (std::vector<int>{8}));
  EXPECT_EQ(a.pairs[3], std::make_pair(4, 3));
  EXPECT_EQ(a.pairs[4], std::make_pair(5, 4));
  // A tighter tolerance drops the jittered frame as well.
  const Association tight = AssociateByTimestamp(gt, est, 0.005);
  EXPECT_EQ(tight.gt_without_estimate, (std::vector<int>{3, 5, 7}));
}

TEST(Association, EachGtFrameTakesItsNearestEstimate) {
  const Trajectory gt = FromPositions({{0, 0, 0}, {1, 0, 0}}, 1.0);
  Trajectory est = {{0.02, Rigid3()}, {0.01, Rigid3()}, {1.0, Rigid3()}};
  const Association a = AssociateByTimestamp(gt, est, 0.1);
  ASSERT_EQ(a.pairs.size(), 2u);
  EXPECT_EQ(a.pairs[0], std::make_pair(0, 1));
  EXPECT_EQ(a.estimate_without_gt, (std::vector<int>{0}));
}

TEST(Extrinsics, ErrorRelativeToCameraZeroIgnoresCommonRigMotion) {
  std::vector<Rigid3> gt;
  for (int i = 0; i < 4; ++i) {
    gt.push_back(Rigid3(QuaternionFromRollPitchYawDeg(-90, 0, -90 + 90 * i), Eigen::Vector3d(0.1 * i, -0.2, 0.3)));
  }
  // The estimate expresses the rig in a different body frame (common change of every camera) and
  // has camera 2 off by 1 deg about its own x axis and 5 cm along its z.
  const Rigid3 rig_from_rig2 = Rigid3::FromAxisAngle(Eigen::Vector3d(0.1, 0.2, -0.3), Eigen::Vector3d(1, 2, 3));
  std::vector<ExtrinsicsRecord> records;
  for (int frame = 0; frame < 3; ++frame) {
    for (int c = 0; c < 4; ++c) {
      ExtrinsicsRecord r;
      r.frame = frame;
      r.timestamp = frame * 0.1;
      r.camera = c;
      Rigid3 cam_from_rig = gt[static_cast<size_t>(c)];
      if (c == 2 && frame < 2) {
        cam_from_rig = Rigid3(QuaternionFromRollPitchYawDeg(1, 0, 0), Eigen::Vector3d(0, 0, 0.05)) * cam_from_rig;
      }
      r.cam_from_rig = cam_from_rig * rig_from_rig2;
      records.push_back(r);
    }
  }
  const std::vector<ExtrinsicError> errors = ExtrinsicErrors(records, gt);
  ASSERT_EQ(errors.size(), 9u);
  // cam2_from_cam0 estimated = offset * gt: the translation moves by R_offset t_gt + 0.05 z - t_gt.
  const Rigid3 gt_cam2_from_cam0 = gt[2] * gt[0].Inverse();
  const double expected_translation = (QuaternionFromRollPitchYawDeg(1, 0, 0) * gt_cam2_from_cam0.translation +
                                       Eigen::Vector3d(0, 0, 0.05) - gt_cam2_from_cam0.translation)
                                          .norm();
  EXPECT_GT(expected_translation, 0.04);
  for (const ExtrinsicError& e : errors) {
    const bool off = e.camera == 2 && e.frame < 2;
    EXPECT_NEAR(e.rotation_error_deg, off ? 1.0 : 0.0, 1e-9) << "frame " << e.frame << " camera " << e.camera;
    EXPECT_NEAR(e.translation_error_m, off ? expected_translation : 0.0, 1e-9);
  }
  records.erase(records.begin());  // frame 0 loses camera 0
  EXPECT_THROW(ExtrinsicErrors(records, gt), std::invalid_argument);
}

TEST(EvaluateRun, SummarisesFramesAndExtrinsics) {
  std::vector<Eigen::Vector3d> positions;
  for (int i = 0; i < 20; ++i) positions.emplace_back(i, 0.1 * i * i / 20.0, 0.01 * i);
  const Trajectory gt = FromPositions(positions);
  RunData run;
  run.info = {{"mode", "online"}, {"dataset", "x"}, {"seed", 1}, {"noise_set", 2}};
  for (int i = 0; i < 20; ++i) {
    if (i == 4) continue;
    run.trajectory.push_back(gt[static_cast<size_t>(i)]);
    run.trajectory.back().world_from_rig.translation.y() += (i % 2 ? 0.2 : -0.2);
  }
  for (int i = 0; i < 20; ++i) {
    FrameRecord f;
    f.frame = i;
    f.timestamp = i * 0.1;
    f.num_correspondences = 100;
    f.num_inliers = i == 4 ? 0 : 50 + (i % 2) * 10;
    f.inlier_ratio = f.num_inliers / 100.0;
    f.mean_reproj_error_deg = i == 4 ? 0.0 : 0.2;
    f.status = i == 4 ? FrameStatus::kLost : (i == 0 ? FrameStatus::kInit : FrameStatus::kOk);
    f.time_ms = 10.0;
    run.frames.push_back(f);
  }
  const std::vector<Rigid3> gt_ext = {Rigid3(),
                                      Rigid3(QuaternionFromRollPitchYawDeg(0, 0, 90), Eigen::Vector3d(1, 0, 0))};
  for (int i = 0; i < 20; ++i) {
    run.extrinsics.push_back({i, i * 0.1, 0, gt_ext[0]});
    run.extrinsics.push_back(
        {i, i * 0.1, 1, Rigid3(QuaternionFromRollPitchYawDeg(0, 0, 90.0 + (19 - i) * 0.1), Eigen::Vector3d(1, 0, 0))});
  }
  const RunEvaluation e = EvaluateRun(gt, gt_ext, run, "r");
  const RunMetrics& m = e.metrics;
  EXPECT_EQ(m.mode, "online");
  EXPECT_EQ(m.noise_set, 2);
  EXPECT_EQ(m.associated_frames, 19);
  EXPECT_EQ(m.missing_frames, 1);
  EXPECT_EQ(m.lost_frames, 1);
  ASSERT_TRUE(m.rmse_se3_m.has_value());
  EXPECT_LE(*m.rmse_se3_m, 0.2 + 1e-9);
  EXPECT_GT(*m.rmse_se3_m, 0.15);
  EXPECT_NEAR(*m.relative_rmse_pct, 100.0 * *m.rmse_se3_m / m.path_length_m, 1e-12);
  // ok frames: 1..19 without 4 = 18 frames; 10 odd ones at 60%, 8 even ones at 50%.
  EXPECT_NEAR(m.mean_inlier_ratio, (10 * 0.6 + 8 * 0.5) / 18.0, 1e-12);
  EXPECT_NEAR(m.mean_reproj_error_deg, 0.2, 1e-12);
  EXPECT_NEAR(m.mean_time_ms, 10.0, 1e-12);
  ASSERT_EQ(m.final_ext_rotation_deg.size(), 1u);
  EXPECT_NEAR(m.final_ext_rotation_deg[0], 0.0, 1e-9);
  EXPECT_NEAR(m.mean_ext_rotation_deg[0], 0.95, 1e-9);  // mean of 1.9 .. 0
  EXPECT_EQ(e.frame_errors.size(), 19u);
}

TEST(EvaluateRun, PartialRunIsScoredOnItsFrameSpan) {
  // Ground truth of 30 frames, 1 m apart; a run over frames 10..19 (run.json "frames": [10, 20]).
  std::vector<Eigen::Vector3d> positions;
  for (int i = 0; i < 30; ++i) positions.emplace_back(i, 0.0, 0.0);
  const Trajectory gt = FromPositions(positions);
  RunData run;
  run.info = {{"mode", "gt"}, {"dataset", "x"}, {"seed", 0}, {"frames", {10, 20}}};
  for (int i = 10; i < 20; ++i) {
    run.trajectory.push_back(gt[static_cast<size_t>(i)]);
    run.trajectory.back().world_from_rig.translation.y() += (i % 2 ? 0.1 : -0.1);
  }
  const RunEvaluation e = EvaluateRun(gt, {Rigid3()}, run, "partial");
  EXPECT_EQ(e.metrics.gt_frames, 10);
  EXPECT_EQ(e.metrics.missing_frames, 0);
  EXPECT_NEAR(e.metrics.path_length_m, 9.0, 1e-12);  // not the whole 29 m
  ASSERT_TRUE(e.metrics.relative_rmse_pct.has_value());
  EXPECT_NEAR(*e.metrics.relative_rmse_pct, 100.0 * *e.metrics.rmse_se3_m / 9.0, 1e-12);
  ASSERT_EQ(e.frame_errors.size(), 10u);
  EXPECT_EQ(e.frame_errors.front().gt_index, 10);  // indices into the full ground truth
  // Without "frames" the whole ground truth counts.
  run.info.erase("frames");
  EXPECT_EQ(EvaluateRun(gt, {Rigid3()}, run, "whole").metrics.missing_frames, 20);
}

}  // namespace
}  // namespace rovo
