// Exposure timing (render/timing.h, datasets/FORMAT.md "Timing"): trigger offsets, motion blur and
// rolling shutter against their analytic expectations on a wall with one vertical edge.
#include "render/timing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "datasets/dataset.h"
#include "render/render.h"
#include "render/sensor.h"
#include "render/tracer.h"
#include "tests/render/edge_scene.h"

namespace rovo {
namespace {

using namespace rovo::testing;  // NOLINT(google-build-using-namespace): the edge scene's names

// Red channel of row y, normalised so that the bright side is 1 and the dark side 0.
std::vector<double> Profile(const CameraImage& image, int y) {
  std::vector<double> p(image.width);
  const double lo = 0.1, hi = 0.9;
  for (int x = 0; x < image.width; ++x)
    p[x] =
        (image.linear[(static_cast<size_t>(y) * image.width + x) * 3] / image.linear[(y * image.width) * 3] * hi - lo) /
        (hi - lo);
  return p;
}

// Mean and variance (px, px^2) of the edge's gradient |dp/du| over rows [y0, y1].
void EdgeMoments(const CameraImage& image, int y0, int y1, double* mean, double* var) {
  std::vector<double> g(image.width - 1, 0.0);
  for (int y = y0; y <= y1; ++y) {
    const std::vector<double> p = Profile(image, y);
    for (int x = 0; x + 1 < image.width; ++x) g[x] += std::abs(p[x + 1] - p[x]);
  }
  double s0 = 0, s1 = 0, s2 = 0;
  for (int x = 0; x + 1 < image.width; ++x) {
    s0 += g[x];
    s1 += g[x] * (x + 0.5);
  }
  *mean = s1 / s0;
  for (int x = 0; x + 1 < image.width; ++x) s2 += g[x] * (x + 0.5 - *mean) * (x + 0.5 - *mean);
  *var = s2 / s0;
}

// Expected image position (u) of the edge for the rig at y = rig_y, in the image row through the
// optical axis: the edge is at bearing angle atan(rig_y / D) to the right.
double EdgeU(double rig_y) { return (kSize - 1) / 2.0 + kF * std::atan(rig_y / kWallX); }

TEST(PoseAtTime, InterpolatesAndExtrapolates) {
  const Scene scene = MakeEdgeScene();
  const Trajectory& traj = scene.rig_trajectory;
  EXPECT_NEAR(PoseAtTime(traj, nullptr, 0.125).translation.y(), 1.25, 1e-12);
  EXPECT_NEAR(PoseAtTime(traj, nullptr, -0.01).translation.y(), -0.1, 1e-12);  // before the first sample
  EXPECT_NEAR(PoseAtTime(traj, nullptr, 0.21).translation.y(), 2.1, 1e-12);    // after the last
  EXPECT_EQ(PoseAtTime(traj, nullptr, 0.1).translation, traj[1].world_from_rig.translation);
  Trajectory turning = traj;
  turning[1].world_from_rig.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()));
  const Rigid3 mid = PoseAtTime(turning, nullptr, 0.075);
  EXPECT_NEAR(Eigen::AngleAxisd(mid.rotation).angle(), 0.15, 1e-9);
}

TEST(TriggerOffsets, SeededDrawAndExplicitValues) {
  TimingSettings t;
  t.trigger_offset_std_ms = 2.0;
  const std::vector<double> a = TriggerOffsetsMs(t, 4, 7), b = TriggerOffsetsMs(t, 4, 7), c = TriggerOffsetsMs(t, 4, 8);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  for (double o : a) EXPECT_LT(std::abs(o), 10.0);
  t.trigger_offset_std_ms = 0.0;
  t.trigger_offset_ms = {0.0, 1.0, -2.0, 3.5};
  EXPECT_EQ(TriggerOffsetsMs(t, 4, 7), t.trigger_offset_ms);
  EXPECT_NO_THROW(t.Check(4, false));
  EXPECT_THROW(t.Check(3, false), std::invalid_argument);
  TimingSettings blur;
  blur.shutter_from_sensor = true;
  EXPECT_THROW(blur.Check(4, false), std::invalid_argument);
}

// Blur samples only where there is blur: a fixed shutter always, the sensor's exposure only when some
// exposure of the schedule is long enough to move an edge by most of a pixel.
TEST(Timing, DefaultSppFollowsTheBlur) {
  TimingSettings none, fixed, sensor;
  fixed.shutter_ms = 0.2;
  sensor.shutter_from_sensor = true;
  std::vector<std::vector<CameraExposure>> day(10, std::vector<CameraExposure>(4, CameraExposure{0.2, 1.0}));
  EXPECT_EQ(DefaultSpp(none, day), kDefaultSpp);
  EXPECT_EQ(DefaultSpp(fixed, day), kDefaultBlurSpp);
  EXPECT_EQ(DefaultSpp(sensor, day), kDefaultSpp);
  EXPECT_EQ(DefaultSpp(sensor, {}), kDefaultSpp);
  day[9][3].exposure_ms = kBlurSppMinExposureMs;  // one long exposure anywhere in the range
  EXPECT_EQ(DefaultSpp(sensor, day), kDefaultBlurSpp);
}

// A camera triggered o ms late sees exactly what a camera at the rig's pose at t + o sees.
TEST(Timing, TriggerOffsetEqualsRenderAtShiftedPose) {
  EdgeRender r(16);
  const CameraImage offset = r.Render(7.0, 0.0, 0.0);
  CameraImage shifted;
  r.tracer.SetFrame(1);
  // The rig between frames is the continuous-time ground truth (here a straight line at constant speed).
  const ContinuousTrajectory rig_motion(r.scene.rig_trajectory);
  const Rigid3 world_from_cam = rig_motion.Pose(0.107) * CamFromRig().Inverse();
  EXPECT_NEAR(rig_motion.Pose(0.107).translation.y(), 1.07, 1e-12);
  r.tracer.Render(r.rays, world_from_cam, r.settings, &shifted);
  EXPECT_EQ(offset.linear, shifted.linear);
  // And the edge moved right by f * atan(speed * o / D) from the frame's time.
  double m0, v0, m1, v1;
  EdgeMoments(r.Render(0.0, 0.0, 0.0), 120, 135, &m0, &v0);
  EdgeMoments(offset, 120, 135, &m1, &v1);
  EXPECT_NEAR(m0, EdgeU(1.0), 0.1);
  EXPECT_NEAR(m1 - m0, EdgeU(1.07) - EdgeU(1.0), 0.1);
}

// Motion blur over [t - T/2, t + T/2]: the edge stays centred at its mid-exposure position and its
// gradient widens to a box of the distance the edge moves, W = f * speed * T / D:
// var = var_static + W^2 / 12.
TEST(Timing, MotionBlurWidthIsTheDistanceTravelled) {
  EdgeRender r(16);
  double m0, v0, m1, v1;
  EdgeMoments(r.Render(0.0, 0.0, 0.0), 110, 145, &m0, &v0);
  const double shutter_ms = 20.0;
  EdgeMoments(r.Render(0.0, shutter_ms, 0.0), 110, 145, &m1, &v1);
  const double expected_width = EdgeU(1.0 + kSpeed * shutter_ms / 2000.0) - EdgeU(1.0 - kSpeed * shutter_ms / 2000.0);
  EXPECT_NEAR(m1, m0, 0.15);
  EXPECT_NEAR(std::sqrt(12.0 * (v1 - v0)), expected_width, 0.05 * expected_width);
  std::printf("blur: centre %.3f -> %.3f px, width %.3f px (expected %.3f)\n", m0, m1, std::sqrt(12.0 * (v1 - v0)),
              expected_width);
}

// Rolling shutter, top row first: row v is exposed at t + (v / (H - 1) - 1/2) R, so with the rig
// moving left the edge shifts right going down; each row equals the global-shutter image at the
// row's time.
TEST(Timing, RollingShutterShearsTopRowsEarlier) {
  EdgeRender r(4);
  const double readout_ms = 30.0;
  const CameraImage rs = r.Render(0.0, 0.0, readout_ms);
  for (int y : {40, 90, 128, 170, 215}) {
    const double dt_ms = (y / (kSize - 1.0) - 0.5) * readout_ms;
    double m_rs, v_rs, m_gs, v_gs;
    EdgeMoments(rs, y, y, &m_rs, &v_rs);
    EdgeMoments(r.Render(dt_ms, 0.0, 0.0), y, y, &m_gs, &v_gs);
    EXPECT_NEAR(m_rs, m_gs, 0.05) << "row " << y;
  }
  double top, bottom, v;
  EdgeMoments(rs, 118, 118, &top, &v);
  EdgeMoments(rs, 138, 138, &bottom, &v);
  // Near the axis the edge moves f * speed * dt / D pixels in the time between the rows.
  const double expected = kF * kSpeed * (20.0 / (kSize - 1.0)) * readout_ms / 1000.0 / kWallX;
  EXPECT_GT(bottom - top, 0.0);
  std::printf("rolling shutter: rows 118 -> 138 shift %.3f px (expected %.3f)\n", bottom - top, expected);
  EXPECT_NEAR(bottom - top, expected, 0.15 * expected + 0.05);
}

// A CameraMotion at one time without shutter or readout renders the same bytes as without one.
TEST(Timing, NoEffectIsByteIdentical) {
  const Scene scene = testing::MakeBoxScene(3, true);
  Tracer tracer(scene);
  const Rig rig = MakeRigPreset("omnimvs4").Scaled(0.2);
  const CameraRays rays = CameraRays::Make(rig.cameras[0].camera, 0, 2);
  ShadeSettings settings;
  settings.spp = 2;
  settings.want_depth = true;
  settings.want_mask = true;
  tracer.SetFrame(1);
  const Rigid3 world_from_cam = scene.rig_trajectory[1].world_from_rig * rig.cameras[0].cam_from_rig.Inverse();
  CameraImage plain, timed;
  tracer.Render(rays, world_from_cam, settings, &plain);
  CameraMotion still;
  tracer.Render(rays, world_from_cam, settings, &timed, &still);
  EXPECT_EQ(plain.rgb, timed.rgb);
  EXPECT_EQ(plain.depth, timed.depth);
  EXPECT_EQ(plain.mask, timed.mask);
  // The dynamic cube over a window, seen at the window's middle (its frame time): same image.
  tracer.SetFrameWindow(1, 0.01);
  tracer.Render(rays, world_from_cam, settings, &timed, &still);
  int differ = 0;
  for (size_t i = 0; i < plain.rgb.size(); ++i) differ += std::abs(plain.rgb[i] - timed.rgb[i]) > 1;
  EXPECT_LE(differ, 3);
  EXPECT_EQ(plain.mask, timed.mask);
}

// A moving object blurs: the box scene's cube moves 0.25 m per frame along -y; over a shutter of
// the whole frame period its mask (pixel centres at mid-exposure) stays, its image smears.
TEST(Timing, DynamicObjectBlursAlongItsMotion) {
  const Scene scene = testing::MakeBoxScene(3, true);
  Tracer tracer(scene);
  const Rig rig = MakeRigPreset("omnimvs4").Scaled(0.2);
  const CameraRays rays = CameraRays::Make(rig.cameras[0].camera, 0, 1);
  ShadeSettings settings;
  settings.spp = 16;
  settings.want_mask = true;
  Rigid3 world_from_cam;
  const double h = 0.05;
  tracer.SetFrameWindow(1, h);
  const ContinuousTrajectory rig_motion(scene.rig_trajectory);
  CameraMotion still =
      MakeCameraMotion(rig_motion, 1, rig.cameras[0].cam_from_rig, h, 0, 0, 0, rays.height, &world_from_cam);
  CameraMotion blur =
      MakeCameraMotion(rig_motion, 1, rig.cameras[0].cam_from_rig, h, 0, 100.0, 0, rays.height, &world_from_cam);
  CameraImage sharp, blurred;
  tracer.Render(rays, world_from_cam, settings, &sharp, &still);
  tracer.Render(rays, world_from_cam, settings, &blurred, &blur);
  EXPECT_EQ(sharp.mask, blurred.mask);
  int changed = 0;
  for (size_t i = 0; i < sharp.rgb.size(); ++i) changed += std::abs(sharp.rgb[i] - blurred.rgb[i]) > 8;
  EXPECT_GT(changed, 20);
}

TEST(TimingRecord, RoundTripAndValidation) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "rovo_timing_record_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  DatasetInfo info;
  info.generator = "test";
  info.frame_count = 1;
  info.rig = MakeRigPreset("omnimvs4");
  TimingSettings t;
  t.shutter_ms = 5.0;
  t.rolling_shutter_ms = 20.0;
  t.trigger_offset_std_ms = 1.0;
  info.timing = MakeTimingRecord(t, TriggerOffsetsMs(t, 4, 3));
  info.timing->spp = 8;  // adaptive sampling from 2 samples (`sampling`)
  info.timing->min_spp = 2;
  info.timing->threshold_codes = 8.0;
  WriteDatasetInfo(dir.string(), info);
  const DatasetInfo back = ReadDatasetInfo(dir.string());
  ASSERT_TRUE(back.timing.has_value());
  EXPECT_EQ(*back.timing, *info.timing);
  EXPECT_EQ(back.timing->exposure, "fixed");
  EXPECT_EQ(back.timing->min_spp, 2);
  EXPECT_DOUBLE_EQ(back.timing->threshold_codes, 8.0);
  // dataset.json as `info`, read back: the error names `pointer`.
  const auto expect_error = [&](const std::string& pointer) {
    WriteDatasetInfo(dir.string(), info);
    try {
      ReadDatasetInfo(dir.string());
      ADD_FAILURE() << "expected an error at " << pointer;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(pointer), std::string::npos) << e.what();
    }
  };
  // Resume and the suite's reuse compare the exposure times, not the sampling.
  TimingRecord fixed = *info.timing;
  fixed.spp = fixed.min_spp = 0;
  fixed.threshold_codes = 0.0;
  EXPECT_TRUE(fixed.SameExposure(*info.timing));
  EXPECT_NE(fixed, *info.timing);
  fixed.shutter_ms = 4.0;
  EXPECT_FALSE(fixed.SameExposure(*info.timing));
  info.timing->min_spp = 16;
  expect_error("/timing/sampling/min_spp");
  info.timing->min_spp = 2;
  info.timing->trigger_offset_ms.pop_back();
  expect_error("/timing/trigger_offset_ms");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rovo
