// Tests of the Camera struct (camera.h): model names, FOV limit, projection with Jacobian against
// numeric differentiation, unprojection validity, the valid-pixel mask and Check().
#include "datasets/camera.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/camera_models.h"
#include "datasets/ocam.h"

namespace rovo {
namespace {

constexpr double kDeg = M_PI / 180.0;

Camera Equidistant220() {
  const double f = 1600.0 / 2.0 / (110.0 * kDeg) * 0.95;
  return Camera{CameraModelId::kEquidistant, 1600, 1532, {f, f, 799.5, 765.5, 0.01, -0.003, 0, 0}, 220.0};
}

Camera DoubleSphere220() {
  return Camera{CameraModelId::kDoubleSphere, 1600, 1532, {350.0, 351.0, 799.5, 765.5, -0.2, 0.6}, 220.0};
}

Camera Ocam220() {
  return MakeOcamCamera(1600, 1532, 811.661, 756.215, 0.999876, -2.91382e-4, -1.66556e-4,
                        {-392.2, 0.0, 0.00127, -1.746e-6, 2.258e-9}, 220.0);
}

Camera ExtendedUnified220() {
  return Camera{CameraModelId::kExtendedUnified, 1600, 1532, {420.0, 421.0, 799.5, 765.5, 0.62, 1.1}, 220.0};
}

std::vector<Camera> AllCameras() { return {Equidistant220(), DoubleSphere220(), Ocam220(), ExtendedUnified220()}; }

Eigen::Vector3d Direction(double angle_deg, double azimuth_deg) {
  return Eigen::Vector3d(std::sin(angle_deg * kDeg) * std::cos(azimuth_deg * kDeg),
                         std::sin(angle_deg * kDeg) * std::sin(azimuth_deg * kDeg), std::cos(angle_deg * kDeg));
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(Camera, ModelNamesRoundTrip) {
  for (CameraModelId id : {CameraModelId::kEquidistant, CameraModelId::kDoubleSphere, CameraModelId::kOcam,
                           CameraModelId::kExtendedUnified}) {
    EXPECT_EQ(CameraModelFromName(CameraModelName(id)), id);
  }
  EXPECT_EQ(CameraModelName(CameraModelId::kOcam), "ocam");
  EXPECT_EQ(CameraModelName(CameraModelId::kDoubleSphere), "double_sphere");
  EXPECT_EQ(CameraModelName(CameraModelId::kEquidistant), "equidistant");
  EXPECT_EQ(CameraModelName(CameraModelId::kExtendedUnified), "extended_unified");
  EXPECT_THROW(CameraModelFromName("fisheye"), std::invalid_argument);
  EXPECT_THROW(CameraModelName(static_cast<CameraModelId>(7)), std::invalid_argument);
}

TEST(Camera, InFovUsesTheHalfAngleAroundTheAxis) {
  Camera camera = Equidistant220();
  EXPECT_TRUE(camera.InFov(Direction(0, 0)));
  EXPECT_TRUE(camera.InFov(Direction(109.9, 45)));
  EXPECT_TRUE(camera.InFov(Direction(110.0, 200) * 5.0));
  EXPECT_FALSE(camera.InFov(Direction(110.1, 45)));
  EXPECT_FALSE(camera.InFov(Eigen::Vector3d(0, 0, -1)));
  EXPECT_FALSE(camera.InFov(Eigen::Vector3d::Zero()));
  camera.max_fov_deg = 180;
  EXPECT_TRUE(camera.InFov(Direction(89.9, 10)));
  EXPECT_FALSE(camera.InFov(Direction(90.1, 10)));
}

// InFov decides as the angle test atan2(|xy|, z) <= fov / 2 + 1e-9 rad does, also for directions within
// rounding of the limit, for lengths from 1e-170 (subnormal squares) to 1e150, for six limits (220 twice:
// it caches the limit's cosine per thread).
TEST(Camera, InFovIsTheAngleTestEverywhere) {
  Camera camera = Equidistant220();
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> azimuth(0.0, 360.0), unit(-1.0, 1.0), scale_exp(-170.0, 150.0);
  int near_limit = 0;
  for (const double fov : {60.0, 180.0, 195.5, 220.0, 359.0, 360.0, 220.0}) {
    camera.max_fov_deg = fov;
    const double limit = 0.5 * fov * kDegToRad + 1e-9;  // as Camera::InFov writes it
    for (int k = 0; k < 20000; ++k) {
      Eigen::Vector3d p;
      if (k % 2 == 0) {
        // Within 1e-8 rad of the limit, down to the last bits.
        const double angle = std::min(M_PI, limit + unit(rng) * std::pow(10.0, -8.0 - 8.0 * std::abs(unit(rng))));
        p = Direction(angle * 180.0 / M_PI, azimuth(rng)) * std::pow(10.0, scale_exp(rng));
        ++near_limit;
      } else {
        p = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * std::pow(10.0, scale_exp(rng));
      }
      const bool expected = std::atan2(std::hypot(p.x(), p.y()), p.z()) <= limit;
      ASSERT_EQ(camera.InFov(p), expected) << "fov " << fov << " p " << p.transpose();
    }
  }
  EXPECT_GT(near_limit, 60000);
  // Subnormal squares: the cosine would say 44.6 deg, the angle is 45.001 deg.
  camera.max_fov_deg = 90.0;
  EXPECT_FALSE(camera.InFov(Eigen::Vector3d(1.00004e-161, 0.0, 1e-161)));
  EXPECT_TRUE(camera.InFov(Eigen::Vector3d(0.99996e-161, 0.0, 1e-161)));
}

// Project and Unproject apply the FOV limit; inside it they invert each other.
TEST(Camera, ProjectUnprojectWithFovLimit) {
  for (const Camera& camera : AllCameras()) {
    SCOPED_TRACE(CameraModelName(camera.model));
    for (double angle : {0.0, 5.0, 30.0, 60.0, 89.0, 90.0, 91.0, 100.0, 105.0, 109.99}) {
      for (double azimuth = 0; azimuth < 360; azimuth += 40) {
        const Eigen::Vector3d point = 3.0 * Direction(angle, azimuth);
        const auto uv = camera.Project(point);
        ASSERT_TRUE(uv.has_value()) << angle << " " << azimuth;
        EXPECT_TRUE(camera.InImage(*uv));
        const auto bearing = camera.Unproject(*uv);
        ASSERT_TRUE(bearing.has_value()) << angle << " " << azimuth;
        EXPECT_LT(AngleBetween(*bearing, point), 5e-5);
      }
    }
    EXPECT_FALSE(camera.Project(Direction(111, 30)).has_value());
    EXPECT_FALSE(camera.Project(Eigen::Vector3d(0, 0, -2)).has_value());
    EXPECT_FALSE(camera.Project(Eigen::Vector3d::Zero()).has_value());
    // Image corners lie beyond 110 degrees for these lenses.
    EXPECT_FALSE(camera.Unproject(Eigen::Vector2d(0, 0)).has_value());
    EXPECT_FALSE(camera.Unproject(Eigen::Vector2d(1599, 1531)).has_value());
    // A narrower limit on the same lens rejects more.
    Camera narrow = camera;
    narrow.max_fov_deg = 180;
    const auto uv_100 = camera.Project(Direction(100, 0));
    ASSERT_TRUE(uv_100.has_value());
    EXPECT_FALSE(narrow.Project(Direction(100, 0)).has_value());
    EXPECT_FALSE(narrow.Unproject(*uv_100).has_value());
  }
}

// A wrong parameter count makes Project/Unproject fail instead of reading out of bounds.
TEST(Camera, WrongParameterCountIsInvalid) {
  Camera camera = Equidistant220();
  camera.params.pop_back();
  EXPECT_FALSE(camera.Project(Eigen::Vector3d(0.1, 0.2, 1)).has_value());
  EXPECT_FALSE(camera.Unproject(Eigen::Vector2d(800, 700)).has_value());
  Camera ocam = Ocam220();
  ocam.params.resize(10);  // no inverse polynomial
  EXPECT_FALSE(ocam.Project(Eigen::Vector3d(0.1, 0.2, 1)).has_value());
}

// d(uv)/d(point) from Project against central differences, over the FOV (also behind the plane).
TEST(Camera, JacobianMatchesNumericDifferentiation) {
  for (const Camera& camera : AllCameras()) {
    SCOPED_TRACE(CameraModelName(camera.model));
    double worst = 0;
    int checked = 0;
    for (double angle = 2.5; angle <= 109; angle += 6.5) {
      for (double azimuth = 10; azimuth < 360; azimuth += 35) {
        for (double depth : {0.5, 4.0, 50.0}) {
          const Eigen::Vector3d point = depth * Direction(angle, azimuth);
          Eigen::Matrix<double, 2, 3> J;
          const auto uv = camera.Project(point, &J);
          ASSERT_TRUE(uv.has_value());
          const auto uv_plain = camera.Project(point);
          ASSERT_TRUE(uv_plain.has_value());
          EXPECT_EQ(*uv, *uv_plain);
          Eigen::Matrix<double, 2, 3> numeric;
          for (int axis = 0; axis < 3; ++axis) {
            const double h = 1e-6 * depth;
            Eigen::Vector3d plus = point, minus = point;
            plus[axis] += h;
            minus[axis] -= h;
            const auto uv_plus = camera.Project(plus), uv_minus = camera.Project(minus);
            ASSERT_TRUE(uv_plus && uv_minus);
            numeric.col(axis) = (*uv_plus - *uv_minus) / (2 * h);
          }
          const double error = (J - numeric).norm() / numeric.norm();
          worst = std::max(worst, error);
          ++checked;
        }
      }
    }
    EXPECT_LT(worst, 1e-6);
    EXPECT_GT(checked, 500);
    // On the optical axis (a coordinate singularity of the radial models) the Jacobian is the
    // limit of its neighbours' and matches central differences.
    const Eigen::Vector3d on_axis(0, 0, 2);
    Eigen::Matrix<double, 2, 3> J_axis, J_near;
    ASSERT_TRUE(camera.Project(on_axis, &J_axis));
    ASSERT_TRUE(camera.Project(2.0 * Direction(1e-3, 30), &J_near));
    EXPECT_LT((J_axis - J_near).norm() / J_near.norm(), 1e-4) << J_axis << "\n" << J_near;
    Eigen::Matrix<double, 2, 3> numeric_axis;
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3d plus = on_axis, minus = on_axis;
      plus[axis] += 1e-6;
      minus[axis] -= 1e-6;
      numeric_axis.col(axis) = (*camera.Project(plus) - *camera.Project(minus)) / 2e-6;
    }
    EXPECT_LT((J_axis - numeric_axis).norm() / numeric_axis.norm(), 1e-6) << J_axis << "\n" << numeric_axis;
    // The Jacobian is orthogonal to the viewing ray: moving along it does not move the pixel.
    const Eigen::Vector3d point = 2.0 * Direction(100, 70);
    Eigen::Matrix<double, 2, 3> J;
    ASSERT_TRUE(camera.Project(point, &J));
    EXPECT_LT((J * point).norm(), 1e-8 * J.norm());
  }
}

TEST(Camera, ValidPixelMaskMatchesUnproject) {
  for (Camera camera : AllCameras()) {
    SCOPED_TRACE(CameraModelName(camera.model));
    // A small version of the same lens keeps the test fast: scale the image by 1/16.
    const double s = 1.0 / 16;
    camera.width = 100;
    camera.height = 96;
    if (camera.model == CameraModelId::kOcam) {
      // Sensor scaled by s: centre moves with pixel centres, a_i scale by s^(1-i), b_i by s.
      camera.params[0] = (camera.params[0] + 0.5) * s - 0.5;
      camera.params[1] = (camera.params[1] + 0.5) * s - 0.5;
      for (int i = 0; i < 5; ++i) camera.params[5 + i] *= std::pow(s, 1 - i);
      for (size_t i = 10; i < camera.params.size(); ++i) camera.params[i] *= s;
    } else {
      for (int i = 0; i < 2; ++i) camera.params[i] *= s;
      for (int i = 2; i < 4; ++i) camera.params[i] = (camera.params[i] + 0.5) * s - 0.5;
    }
    ASSERT_NO_THROW(camera.Check("scaled"));
    const std::vector<unsigned char> mask = camera.ValidPixelMask();
    ASSERT_EQ(mask.size(), 100u * 96u);
    int valid = 0;
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const bool expected = camera.Unproject(Eigen::Vector2d(u, v)).has_value();
        EXPECT_EQ(mask[v * camera.width + u], expected ? 255 : 0);
        valid += expected;
      }
    }
    // The 220-degree image circle (radius ~47 of 50 px) covers most of the image but not the corners.
    EXPECT_GT(valid, 0.6 * mask.size());
    EXPECT_LT(valid, 0.85 * mask.size());
    EXPECT_EQ(mask[0], 0);
    EXPECT_EQ(mask[48 * 100 + 50], 255);
  }
}

void ExpectCheckFails(const Camera& camera, const std::string& field) {
  try {
    camera.Check("rig.json: cameras[2]");
    ADD_FAILURE() << "Check accepted a bad camera (expected a complaint about " << field << ")";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("rig.json: cameras[2]"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr(field));
  }
}

TEST(Camera, CheckAcceptsGoodCameras) {
  for (const Camera& camera : AllCameras()) EXPECT_NO_THROW(camera.Check("good"));
}

TEST(Camera, CheckNamesTheBadField) {
  Camera camera = Equidistant220();
  camera.width = 0;
  ExpectCheckFails(camera, "width");
  camera = Equidistant220();
  camera.height = -3;
  ExpectCheckFails(camera, "height");
  camera = Equidistant220();
  camera.max_fov_deg = 0;
  ExpectCheckFails(camera, "max_fov_deg");
  camera = Equidistant220();
  camera.params.push_back(0.0);
  ExpectCheckFails(camera, "params");
  camera = Equidistant220();
  camera.params[3] = std::nan("");
  ExpectCheckFails(camera, "params[3]");
  camera = Equidistant220();
  camera.params[0] = -10;
  ExpectCheckFails(camera, "fx");
  // r(theta) turns back before 110 degrees.
  camera = Equidistant220();
  camera.params[4] = -0.2;
  ExpectCheckFails(camera, "k1..k4");

  camera = DoubleSphere220();
  camera.params[5] = 1.5;
  ExpectCheckFails(camera, "alpha");
  camera = DoubleSphere220();
  camera.params[4] = -0.6;  // valid set shrinks below 110 degrees
  ExpectCheckFails(camera, "max_fov_deg");

  camera = ExtendedUnified220();
  camera.params[5] = 0.0;
  ExpectCheckFails(camera, "beta");
  camera = ExtendedUnified220();
  camera.params[4] = 0.2;  // w = 0.25: valid set below 110 degrees
  ExpectCheckFails(camera, "max_fov_deg");

  camera = Ocam220();
  camera.params.resize(10);
  ExpectCheckFails(camera, "params");
  camera = Ocam220();
  camera.params[5] = 392.2;
  ExpectCheckFails(camera, "a0");
  camera = Ocam220();
  camera.params[10] += 2.0;  // inverse polynomial off by 2 px
  ExpectCheckFails(camera, "inverse polynomial");
  camera = Ocam220();
  camera.params[9] = -2e-9;  // elevation turns back inside the FOV
  ExpectCheckFails(camera, "a0..a4");
}

}  // namespace
}  // namespace rovo
