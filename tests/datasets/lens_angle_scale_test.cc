// Tests of lens_angle_scale.h: every pixel's bearing turns away from the axis by the scale, keeps its
// azimuth, and projects back to the same pixel, for the rigs' ocam and equidistant lenses.
#include "datasets/lens_angle_scale.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace rovo {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

double AngleFromAxisDeg(const Eigen::Vector3d& b) { return std::atan2(b.head<2>().norm(), b.z()) * kRadToDeg; }

// Largest errors over a pixel grid of the lens scaled by `scale` against `camera`: angle from the axis
// against scale times the given one (deg), azimuth (deg), and projection of the new bearing (px).
struct ScaleErrors {
  double angle_deg = 0.0, azimuth_deg = 0.0, reprojection_px = 0.0;
  int pixels = 0;
};

ScaleErrors Measure(const Camera& camera, const Camera& scaled, double scale) {
  ScaleErrors e;
  for (int v = 4; v < camera.height; v += 13) {
    for (int u = 4; u < camera.width; u += 13) {
      const Eigen::Vector2d uv(u, v);
      const auto given = camera.Unproject(uv);
      if (!given || AngleFromAxisDeg(*given) < 1.0) continue;
      const auto turned = scaled.Unproject(uv);
      if (!turned) {
        ADD_FAILURE() << "pixel " << u << "," << v << " lost by the scaled lens";
        continue;
      }
      e.angle_deg = std::max(e.angle_deg, std::abs(AngleFromAxisDeg(*turned) - scale * AngleFromAxisDeg(*given)));
      const double azimuth = std::atan2(given->y(), given->x()) - std::atan2(turned->y(), turned->x());
      e.azimuth_deg = std::max(e.azimuth_deg, std::abs(std::remainder(azimuth, 2.0 * M_PI)) * kRadToDeg);
      const auto back = scaled.Project(*turned);
      e.reprojection_px = std::max(e.reprojection_px, back ? (*back - uv).norm() : 1e9);
      ++e.pixels;
    }
  }
  return e;
}

class LensAngleScale : public ::testing::TestWithParam<std::string> {};

TEST_P(LensAngleScale, EveryPixelTurnsAwayFromTheAxisByTheScale) {
  const Rig rig = MakeRigPreset(GetParam());
  for (double scale : {0.985, 1.0156}) {
    for (const RigCamera& c : rig.cameras) {
      const AngleScaledLens lens = ScaleLensAngles(c.camera, scale);
      const ScaleErrors e = Measure(c.camera, lens.camera, scale);
      SCOPED_TRACE(GetParam() + " " + c.name + " scale " + std::to_string(scale));
      EXPECT_GT(e.pixels, 1000);
      EXPECT_LT(e.angle_deg, 0.035);  // the refit (0.03 deg) and the inverse polynomial (0.01 px)
      EXPECT_LE(lens.max_error_deg, 0.03);
      EXPECT_LT(e.azimuth_deg, 1e-6);
      EXPECT_LT(e.reprojection_px, 0.02);
      EXPECT_NEAR(lens.camera.max_fov_deg, scale * c.camera.max_fov_deg, 0.061);
      EXPECT_NO_THROW(lens.camera.Check("scaled " + c.name));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(RigPresets, LensAngleScale, ::testing::Values("rovo4", "rovo4_real", "omnimvs4"));

// The presets' equidistant lenses have k = 0; a lens with every k_i set checks their scaling.
TEST(LensAngleScale, EquidistantDistortionTermsScaleExactly) {
  Camera lens;
  lens.model = CameraModelId::kEquidistant;
  lens.width = 800;
  lens.height = 800;
  lens.params = {255.0, 256.0, 401.0, 398.5, 0.02, -0.005, 0.001, -0.0001};
  lens.max_fov_deg = 220.0;
  for (double scale : {0.985, 1.0156}) {
    const AngleScaledLens scaled = ScaleLensAngles(lens, scale);
    const ScaleErrors e = Measure(lens, scaled.camera, scale);
    SCOPED_TRACE("scale " + std::to_string(scale));
    EXPECT_GT(e.pixels, 2000);
    EXPECT_LT(e.angle_deg, 1e-6);
    EXPECT_LT(e.reprojection_px, 1e-6);
    EXPECT_EQ(scaled.max_error_deg, 0.0);
    EXPECT_NEAR(scaled.camera.params[7], lens.params[7] / std::pow(scale, 8), 1e-15);
  }
}

// An ocam lens refitted at scale 1 keeps its angles (the refit alone, without a scale).
TEST(LensAngleScale, OcamRefitAtScaleOneKeepsTheAngles) {
  const Rig rig = MakeRigPreset("rovo4_real");
  ASSERT_EQ(rig.cameras[0].camera.model, CameraModelId::kOcam);
  const AngleScaledLens same = ScaleLensAngles(rig.cameras[0].camera, 1.0);
  const ScaleErrors e = Measure(rig.cameras[0].camera, same.camera, 1.0);
  EXPECT_GT(e.pixels, 1000);
  EXPECT_LT(e.angle_deg, 0.01);
  EXPECT_LT(e.reprojection_px, 0.02);
}

TEST(LensAngleScale, ScaleOfOneLeavesTheRigAlone) {
  const Rig rig = MakeRigPreset("rovo4");
  double error = -1.0;
  const Rig same = WithLensAngleScale(rig, 1.0, &error);
  EXPECT_EQ(error, 0.0);
  EXPECT_EQ(same.cameras[2].camera.params, rig.cameras[2].camera.params);
}

TEST(LensAngleScale, RefusesModelsWithoutAScaledFormAndWildScales) {
  Camera ds;
  ds.model = CameraModelId::kDoubleSphere;
  ds.width = 800;
  ds.height = 800;
  ds.params = {300, 300, 400, 400, -0.2, 0.6};
  EXPECT_THROW(ScaleLensAngles(ds, 1.01), std::invalid_argument);
  const Rig rig = MakeRigPreset("omnimvs4");
  EXPECT_THROW(ScaleLensAngles(rig.cameras[0].camera, 1.2), std::invalid_argument);
  Rig mixed = rig;
  mixed.cameras[1].camera = ds;
  try {
    WithLensAngleScale(mixed, 1.01);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(rig.cameras[1].name), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rovo
