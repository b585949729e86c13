#include "datasets/rig.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "datasets/ocam.h"

namespace rovo {
namespace {

double WrapDeg(double a) {
  while (a > 180.0) a -= 360.0;
  while (a <= -180.0) a += 360.0;
  return a;
}

TEST(RigPresets, NamesAndUnknown) {
  EXPECT_THAT(RigPresetNames(),
              ::testing::ElementsAre("rovo4", "omnimvs4", "rovo4_real", "rovo4_stereo", "rovo4_mono"));
  try {
    MakeRigPreset("nope");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("rovo4"));
  }
  for (const std::string& name : RigPresetNames()) {
    const Rig rig = MakeRigPreset(name);
    EXPECT_NO_THROW(rig.Check(name));
    const int expected = name == "rovo4_stereo" ? 6 : name == "rovo4_mono" ? 5 : 4;
    ASSERT_EQ(rig.NumCameras(), expected) << name;
    for (int i = 0; i < expected; ++i) EXPECT_EQ(rig.cameras[i].name, "cam" + std::to_string(i)) << name;
  }
}

TEST(RigPresets, ForwardStereoAndMonoBesideTheRing) {
  const Rig ring = MakeRigPreset("rovo4");
  for (const std::string name : {"rovo4_stereo", "rovo4_mono"}) {
    const Rig rig = MakeRigPreset(name);
    // The ring is rovo4's, unchanged, as cameras 0-3.
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(rig.cameras[i].camera.params, ring.cameras[i].camera.params) << name;
      EXPECT_TRUE(rig.cameras[i].cam_from_rig.translation.isApprox(ring.cameras[i].cam_from_rig.translation)) << name;
    }
    for (int i = 4; i < rig.NumCameras(); ++i) {
      const RigCamera& rc = rig.cameras[i];
      EXPECT_EQ(rc.camera.model, CameraModelId::kEquidistant) << name;
      EXPECT_NEAR(CameraYawDeg(rc.cam_from_rig), 0.0, 1e-9) << name;  // looks forward (+x)
      EXPECT_NEAR(CameraPitchDeg(rc.cam_from_rig), 0.0, 1e-9) << name;
      // 100 degrees across the width: the image edge's bearing is 50 degrees off the axis.
      const double f = rc.camera.params[0];
      EXPECT_NEAR(0.5 * rc.camera.width / f * 180.0 / M_PI, 50.0, 1e-9);
      EXPECT_GT(rc.camera.max_fov_deg,
                2.0 * std::hypot(0.5 * rc.camera.width, 0.5 * rc.camera.height) / f * 180.0 / M_PI);
      EXPECT_LT(rc.camera.max_fov_deg, 180.0);
    }
  }
  const Rig stereo = MakeRigPreset("rovo4_stereo");
  const Eigen::Vector3d left = CameraPositionInRig(stereo.cameras[4].cam_from_rig);
  const Eigen::Vector3d right = CameraPositionInRig(stereo.cameras[5].cam_from_rig);
  EXPECT_NEAR((left - right).norm(), 0.4, 1e-12);  // baseline
  EXPECT_GT(left.y(), right.y());                  // cam4 is the left camera (rig y = left)
  // Parallel optical axes: a rectified-ready pair.
  EXPECT_LT(RotationDistanceDeg(stereo.cameras[4].cam_from_rig.rotation, stereo.cameras[5].cam_from_rig.rotation),
            1e-9);
  EXPECT_EQ(MakeRigPreset("rovo4_mono").NumCameras(), 5);
}

TEST(RigPresets, Rovo4Geometry) {
  const Rig rig = MakeRigPreset("rovo4");
  const double yaws[4] = {45.0, -45.0, -135.0, 135.0};
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < 4; ++i) {
    const RigCamera& rc = rig.cameras[i];
    EXPECT_NEAR(WrapDeg(CameraYawDeg(rc.cam_from_rig) - yaws[i]), 0.0, 1e-9) << i;
    EXPECT_NEAR(CameraPitchDeg(rc.cam_from_rig), 0.0, 1e-9);
    const Eigen::Vector3d position = CameraPositionInRig(rc.cam_from_rig);
    EXPECT_NEAR(position.z(), 0.0, 1e-12);
    // Each camera sits in the corner its optical axis points to.
    EXPECT_NEAR(WrapDeg(std::atan2(position.y(), position.x()) * 180.0 / M_PI - yaws[i]), 0.0, 10.0);
    centroid += position / 4.0;
    // Neighbours (i, i+1 mod 4) are about 1 m apart; diagonals are farther.
    const double baseline = (position - CameraPositionInRig(rig.cameras[(i + 1) % 4].cam_from_rig)).norm();
    EXPECT_GE(baseline, 0.8);
    EXPECT_LE(baseline, 1.05);
    const double diagonal = (position - CameraPositionInRig(rig.cameras[(i + 2) % 4].cam_from_rig)).norm();
    EXPECT_GT(diagonal, baseline);
    // Image "down" is rig -z (camera upright), image right is horizontal.
    const Eigen::Vector3d down_in_rig = rc.cam_from_rig.rotation.conjugate() * Eigen::Vector3d::UnitY();
    EXPECT_TRUE(down_in_rig.isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
    // The lens: 1600x1532 ocam of 220 degrees, inverse fitted to < 0.01 px.
    EXPECT_EQ(rc.camera.model, CameraModelId::kOcam);
    EXPECT_EQ(rc.camera.width, 1600);
    EXPECT_EQ(rc.camera.height, 1532);
    EXPECT_DOUBLE_EQ(rc.camera.max_fov_deg, 220.0);
    EXPECT_DOUBLE_EQ(rc.camera.params[5], -392.2);
    EXPECT_LT(OcamInverseMaxErrorPx(rc.camera.params, 220.0), 0.01);
    const auto centre = rc.camera.Project(Eigen::Vector3d(0, 0, 1));
    ASSERT_TRUE(centre.has_value());
    EXPECT_NEAR(centre->x(), 811.7, 1e-9);
    EXPECT_NEAR(centre->y(), 756.2, 1e-9);
  }
  EXPECT_LT(centroid.norm(), 1e-12);
}

TEST(RigPresets, Rovo4SeesBehindAndEdgeInsideImage) {
  const Rig rig = MakeRigPreset("rovo4");
  const Camera& camera = rig.cameras[0].camera;
  // 109 degrees from the axis (behind the image plane) still projects inside the image.
  const double a = 109.0 * M_PI / 180.0;
  const auto uv = camera.Project(Eigen::Vector3d(std::sin(a), 0.0, std::cos(a)));
  ASSERT_TRUE(uv.has_value());
  EXPECT_TRUE(camera.InImage(*uv)) << uv->transpose();
  EXPECT_FALSE(camera.Project(Eigen::Vector3d(std::sin(2.0), 0.0, std::cos(2.0))).has_value());  // 114.6 deg
}

TEST(RigPresets, OmniMvs4Geometry) {
  const Rig rig = MakeRigPreset("omnimvs4");
  const double yaws[4] = {0.0, 90.0, 180.0, -90.0};
  for (int i = 0; i < 4; ++i) {
    const RigCamera& rc = rig.cameras[i];
    EXPECT_NEAR(WrapDeg(CameraYawDeg(rc.cam_from_rig) - yaws[i]), 0.0, 1e-9);
    const Eigen::Vector3d position = CameraPositionInRig(rc.cam_from_rig);
    EXPECT_NEAR(position.norm(), 0.6, 1e-12);
    // Facing outwards from the rig centre.
    EXPECT_GT(position.normalized().dot(CameraAxisInRig(rc.cam_from_rig)), 0.999999);
    EXPECT_EQ(rc.camera.model, CameraModelId::kEquidistant);
    EXPECT_EQ(rc.camera.width, 800);
    EXPECT_EQ(rc.camera.height, 768);
  }
  // The 110-degree rim lies inside the image, close to the top and bottom edges.
  const Camera& camera = rig.cameras[0].camera;
  const double a = 110.0 * M_PI / 180.0 * (1 - 1e-9);
  const auto top = camera.Project(Eigen::Vector3d(0.0, -std::sin(a), std::cos(a)));
  ASSERT_TRUE(top.has_value());
  EXPECT_NEAR(top->y(), 383.0 - 191.5 * 110.0 * M_PI / 180.0, 1e-6);
  EXPECT_TRUE(camera.InImage(*top));
  EXPECT_LT(top->y(), 20.0);
}

TEST(RigPresets, Rovo4RealMatchesTheRooftopLayout) {
  const Rig rig = MakeRigPreset("rovo4_real");
  const double yaws[4] = {45.0, -45.0, -135.0, 135.0};
  for (int i = 0; i < 4; ++i) {
    const RigCamera& rc = rig.cameras[i];
    EXPECT_NEAR(WrapDeg(CameraYawDeg(rc.cam_from_rig) - yaws[i]), 0.0, 6.0) << i;
    EXPECT_NEAR(CameraPitchDeg(rc.cam_from_rig), 0.0, 4.0) << i;
    const Eigen::Vector3d position = CameraPositionInRig(rc.cam_from_rig);
    EXPECT_NEAR(position.z(), 0.0, 1e-3);
    const double baseline = (position - CameraPositionInRig(rig.cameras[(i + 1) % 4].cam_from_rig)).norm();
    EXPECT_NEAR(baseline, 0.295, 0.01);  // the real rig is small: ~0.3 m between neighbours
    EXPECT_LT(OcamInverseMaxErrorPx(rc.camera.params, 220.0), 0.01);
  }
}

TEST(RigPresets, MountHelperFramesAreRightHanded) {
  const Rigid3 cam_from_rig = CamFromRigFromMount(30.0, 10.0, Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(CameraYawDeg(cam_from_rig), 30.0, 1e-9);
  EXPECT_NEAR(CameraPitchDeg(cam_from_rig), 10.0, 1e-9);
  EXPECT_TRUE(CameraPositionInRig(cam_from_rig).isApprox(Eigen::Vector3d(1, 2, 3), 1e-12));
  EXPECT_NEAR(cam_from_rig.RotationMatrix().determinant(), 1.0, 1e-12);
  // Image right is horizontal.
  EXPECT_NEAR((cam_from_rig.rotation.conjugate() * Eigen::Vector3d::UnitX()).z(), 0.0, 1e-12);
}

TEST(Rig, ScaledProjectsToScaledPixels) {
  for (const char* name : {"rovo4", "omnimvs4"}) {
    const Rig rig = MakeRigPreset(name);
    const double scale = 0.25;
    const Rig small = rig.Scaled(scale);
    EXPECT_EQ(small.cameras[0].camera.width, static_cast<int>(std::lround(rig.cameras[0].camera.width * scale)));
    for (double deg : {0.0, 30.0, 89.0, 91.0, 108.0}) {
      const double a = deg * M_PI / 180.0;
      const Eigen::Vector3d bearing(std::sin(a) * 0.6, std::sin(a) * 0.8, std::cos(a));
      const auto uv = rig.cameras[1].camera.Project(bearing);
      const auto uv_small = small.cameras[1].camera.Project(bearing);
      ASSERT_TRUE(uv && uv_small) << name << " " << deg;
      EXPECT_NEAR(uv_small->x(), (uv->x() + 0.5) * scale - 0.5, 1e-9) << name << " " << deg;
      EXPECT_NEAR(uv_small->y(), (uv->y() + 0.5) * scale - 0.5, 1e-9) << name << " " << deg;
      const auto back = small.cameras[1].camera.Unproject(*uv_small);
      ASSERT_TRUE(back.has_value());
      EXPECT_LT(AngleBetween(*back, bearing.normalized()), 1e-4) << name << " " << deg;
    }
  }
  // Double sphere (Usenko et al. example parameters), same rule.
  Rig ds = MakeRigPreset("omnimvs4");
  ds.cameras[0].camera.model = CameraModelId::kDoubleSphere;
  ds.cameras[0].camera.params = {160.0, 160.0, 399.5, 383.5, -0.2, 0.6};
  ds.cameras[0].camera.max_fov_deg = 200.0;
  const Rig ds_small = ds.Scaled(0.5);
  const Eigen::Vector3d bearing(0.5, -0.3, 0.2);
  const auto uv = ds.cameras[0].camera.Project(bearing);
  const auto uv_small = ds_small.cameras[0].camera.Project(bearing);
  ASSERT_TRUE(uv && uv_small);
  EXPECT_NEAR(uv_small->x(), (uv->x() + 0.5) * 0.5 - 0.5, 1e-9);
  EXPECT_NEAR(uv_small->y(), (uv->y() + 0.5) * 0.5 - 0.5, 1e-9);
  EXPECT_THROW(MakeRigPreset("rovo4").Scaled(0.0), std::invalid_argument);
}

TEST(Rig, WithExtrinsicsAndCheck) {
  const Rig rig = MakeRigPreset("omnimvs4");
  std::vector<Rigid3> extrinsics = rig.Extrinsics();
  ASSERT_EQ(extrinsics.size(), 4u);
  extrinsics[2] = Rigid3::Identity();
  const Rig changed = rig.WithExtrinsics(extrinsics);
  EXPECT_LT(changed.cameras[2].cam_from_rig.translation.norm(), 1e-15);
  EXPECT_THROW(rig.WithExtrinsics({Rigid3()}), std::invalid_argument);
  Rig duplicate = rig;
  duplicate.cameras[3].name = "cam0";
  EXPECT_THROW(duplicate.Check("test"), std::invalid_argument);
  EXPECT_THROW(Rig().Check("test"), std::invalid_argument);
}

// Rotation of the perturbation in the camera frame: delta = R' R^T, as an axis-angle vector.
Eigen::Vector3d DeltaInCamera(const Rigid3& perturbed, const Rigid3& truth) {
  return Eigen::AngleAxisd(perturbed.rotation * truth.rotation.conjugate()).axis() *
         Eigen::AngleAxisd(perturbed.rotation * truth.rotation.conjugate()).angle();
}

TEST(PerturbExtrinsics, StatisticsMatchSigma) {
  const Rig rig = MakeRigPreset("rovo4");
  const double sigma_deg = 5.0, sigma_m = 0.02;
  Eigen::Vector3d sum_sq_rot = Eigen::Vector3d::Zero(), sum_rot = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_sq_pos = Eigen::Vector3d::Zero();
  int n = 0;
  for (uint64_t seed = 0; seed < 1500; ++seed) {
    const PerturbedExtrinsics set = PerturbExtrinsics(rig, sigma_deg, sigma_m, seed);
    ASSERT_EQ(set.cam_from_rig.size(), 4u);
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d d = DeltaInCamera(set.cam_from_rig[c], rig.cameras[c].cam_from_rig) * 180.0 / M_PI;
      sum_rot += d;
      sum_sq_rot += d.cwiseProduct(d);
      const Eigen::Vector3d offset =
          CameraPositionInRig(set.cam_from_rig[c]) - CameraPositionInRig(rig.cameras[c].cam_from_rig);
      sum_sq_pos += offset.cwiseProduct(offset);
      ++n;
    }
  }
  for (int k = 0; k < 3; ++k) {
    // 6000 samples: the standard deviation estimate is within ~3% at 3 sigma; small-angle
    // composition adds well under 1%.
    EXPECT_NEAR(std::sqrt(sum_sq_rot[k] / n), sigma_deg, 0.05 * sigma_deg) << k;
    EXPECT_NEAR(sum_rot[k] / n, 0.0, 0.25) << k;
    EXPECT_NEAR(std::sqrt(sum_sq_pos[k] / n), sigma_m, 0.05 * sigma_m) << k;
  }
}

TEST(PerturbExtrinsics, DeterministicAndRecorded) {
  const Rig rig = MakeRigPreset("omnimvs4");
  const PerturbedExtrinsics a = PerturbExtrinsics(rig, 5.0, 0.0, 42);
  const PerturbedExtrinsics b = PerturbExtrinsics(rig, 5.0, 0.0, 42);
  const PerturbedExtrinsics c = PerturbExtrinsics(rig, 5.0, 0.0, 43);
  EXPECT_EQ(a.seed, 42u);
  EXPECT_DOUBLE_EQ(a.sigma_rotation_deg, 5.0);
  EXPECT_DOUBLE_EQ(a.sigma_translation_m, 0.0);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(std::memcmp(a.cam_from_rig[i].rotation.coeffs().data(), b.cam_from_rig[i].rotation.coeffs().data(),
                          4 * sizeof(double)),
              0);
    EXPECT_GT(RotationDistanceDeg(a.cam_from_rig[i].rotation, c.cam_from_rig[i].rotation), 1e-6);
    // Rotation-only noise keeps the camera centre.
    EXPECT_TRUE(
        CameraPositionInRig(a.cam_from_rig[i]).isApprox(CameraPositionInRig(rig.cameras[i].cam_from_rig), 1e-12));
    EXPECT_GT(RotationDistanceDeg(a.cam_from_rig[i].rotation, rig.cameras[i].cam_from_rig.rotation), 1e-3);
  }
  // Fixed by the algorithm (mt19937_64 + Box-Muller, draw order of FORMAT.md), not by the standard
  // library: pin the values (tolerance for libm's last-bit differences in log/sin/cos).
  const PerturbedExtrinsics pinned = PerturbExtrinsics(rig, 5.0, 0.01, 42);
  const Eigen::Vector4d q0(-0.48716694171190622, 0.48656929753277556, -0.49163384396003651, -0.53311804797306195);
  const Eigen::Vector3d t0(-0.022262371072345077, -0.028004682158246141, -0.60466059411756667);
  const Eigen::Vector4d q1(0.7298109117221574, -0.058862159338247323, 0.016158807120376633, 0.68091862383236268);
  const Eigen::Vector3d t1(0.051180218227200952, 0.033809462829073267, -0.56749556337414064);
  EXPECT_LT((pinned.cam_from_rig[0].rotation.coeffs() - q0).norm(), 1e-12);
  EXPECT_LT((pinned.cam_from_rig[0].translation - t0).norm(), 1e-12);
  EXPECT_LT((pinned.cam_from_rig[1].rotation.coeffs() - q1).norm(), 1e-12);
  EXPECT_LT((pinned.cam_from_rig[1].translation - t1).norm(), 1e-12);
  const PerturbedExtrinsics zero = PerturbExtrinsics(rig, 0.0, 0.0, 1);
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT(RotationDistanceDeg(zero.cam_from_rig[i].rotation, rig.cameras[i].cam_from_rig.rotation), 1e-9);
  }
  EXPECT_THROW(PerturbExtrinsics(rig, -1.0, 0.0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
