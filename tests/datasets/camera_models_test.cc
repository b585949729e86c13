// Model-level tests of camera_models.h: project/unproject round trips over the whole 220-degree
// FOV (including points behind the image plane) at several depths, in float and double, and the
// templates instantiated with ceres::Jet.
#include "datasets/camera_models.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <vector>

#include "datasets/ocam.h"

namespace rovo {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct ModelCase {
  std::string name;
  CameraModelId model;
  std::vector<double> params;
  double max_angle_deg;  // largest angle from the axis tested (half the FOV)
  // Tolerances of the round trips in double; float gets its own.
  double pixel_tol_double;
};

// A lens that reaches 220 degrees on a 1600x1532 sensor, for each model.
std::vector<ModelCase> Cases() {
  const double f_equidistant = 1600.0 / 2.0 / (110.0 * kDeg) * 0.95;
  const Camera ocam_identity =
      MakeOcamCamera(1600, 1532, 811.7, 756.2, 1.0, 0.0, 0.0, {-392.2, 0.0, 0.00127, -1.746e-6, 2.258e-9}, 220.0);
  const Camera ocam_affine = MakeOcamCamera(
      1600, 1532, 811.661, 756.215, 0.999876, -2.91382e-4, -1.66556e-4,
      {-392.21983020642324, 0.0, 0.0012707685299884767, -1.7456026867522776e-6, 2.257655719602505e-9}, 220.0);
  return {
      {"equidistant", CameraModelId::kEquidistant, {f_equidistant, f_equidistant, 799.5, 765.5, 0, 0, 0, 0}, 110, 1e-6},
      {"equidistant_k",
       CameraModelId::kEquidistant,
       {370.0, 371.0, 801.2, 764.9, 0.02, -0.003, 0.0005, -0.00003},
       110,
       1e-6},
      {"double_sphere", CameraModelId::kDoubleSphere, {350.0, 351.0, 799.5, 765.5, -0.2, 0.6}, 110, 1e-6},
      {"double_sphere_small_alpha", CameraModelId::kDoubleSphere, {300.0, 300.0, 640.0, 480.0, 0.3, 0.4}, 110, 1e-6},
      {"extended_unified", CameraModelId::kExtendedUnified, {420.0, 421.0, 799.5, 765.5, 0.62, 1.1}, 110, 1e-6},
      {"extended_unified_small_alpha",
       CameraModelId::kExtendedUnified,
       {300.0, 300.0, 640.0, 480.0, 0.45, 0.9},
       105,
       1e-6},
      // The inverse polynomial is a fit (< 0.01 px): the round trip is only that good.
      {"ocam", CameraModelId::kOcam, ocam_identity.params, 110, 0.01},
      {"ocam_affine", CameraModelId::kOcam, ocam_affine.params, 110, 0.01},
  };
}

template <typename T>
bool ImgFromCam(CameraModelId model, const std::vector<T>& params, const T* point, T* uv) {
  const int n = static_cast<int>(params.size());
  switch (model) {
    case CameraModelId::kEquidistant:
      return EquidistantModel::ImgFromCam(params.data(), n, point, uv);
    case CameraModelId::kDoubleSphere:
      return DoubleSphereModel::ImgFromCam(params.data(), n, point, uv);
    case CameraModelId::kOcam:
      return OcamModel::ImgFromCam(params.data(), n, point, uv);
    case CameraModelId::kExtendedUnified:
      return ExtendedUnifiedModel::ImgFromCam(params.data(), n, point, uv);
  }
  return false;
}

template <typename T>
bool CamFromImg(CameraModelId model, const std::vector<T>& params, const T* uv, T* bearing) {
  const int n = static_cast<int>(params.size());
  switch (model) {
    case CameraModelId::kEquidistant:
      return EquidistantModel::CamFromImg(params.data(), n, uv, bearing);
    case CameraModelId::kDoubleSphere:
      return DoubleSphereModel::CamFromImg(params.data(), n, uv, bearing);
    case CameraModelId::kOcam:
      return OcamModel::CamFromImg(params.data(), n, uv, bearing);
    case CameraModelId::kExtendedUnified:
      return ExtendedUnifiedModel::CamFromImg(params.data(), n, uv, bearing);
  }
  return false;
}

// Unit directions covering the FOV: angle from the axis 0..max in 2.5-degree steps (plus the exact
// edge), azimuth in 15-degree steps.
std::vector<Eigen::Vector3d> DirectionGrid(double max_angle_deg) {
  std::vector<Eigen::Vector3d> directions;
  std::vector<double> angles;
  for (double a = 0; a < max_angle_deg; a += 2.5) angles.push_back(a);
  angles.push_back(max_angle_deg);
  for (double angle : angles) {
    for (double azimuth = 0; azimuth < 360; azimuth += 15) {
      directions.emplace_back(std::sin(angle * kDeg) * std::cos(azimuth * kDeg),
                              std::sin(angle * kDeg) * std::sin(azimuth * kDeg), std::cos(angle * kDeg));
      if (angle == 0) break;
    }
  }
  return directions;
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

template <typename T>
struct Tolerances;
template <>
struct Tolerances<double> {
  static double Pixel(const ModelCase& c) { return c.pixel_tol_double; }
  static constexpr double kNorm = 1e-12;
};
template <>
struct Tolerances<float> {
  // float has 24 bits: pixel coordinates near 1500 resolve to ~1e-4 px (measured round trips:
  // 2.3e-4 px worse than double).
  static double Pixel(const ModelCase& c) { return c.pixel_tol_double + 0.002; }
  static constexpr double kNorm = 1e-5;
};

template <typename T>
class CameraModelRoundTrip : public ::testing::Test {};
using Scalars = ::testing::Types<double, float>;
TYPED_TEST_SUITE(CameraModelRoundTrip, Scalars);

// Point -> pixel -> bearing: the bearing is the point's direction, for points in front of and
// behind the image plane, at several depths.
TYPED_TEST(CameraModelRoundTrip, PointToPixelToBearing) {
  using T = TypeParam;
  for (const ModelCase& c : Cases()) {
    SCOPED_TRACE(c.name);
    const std::vector<T> params(c.params.begin(), c.params.end());
    const double focal_px = c.model == CameraModelId::kOcam ? 380.0 : std::min(c.params[0], c.params[1]);
    const double angle_tol = Tolerances<T>::Pixel(c) / focal_px * 1.5;
    int behind = 0, checked = 0;
    for (const Eigen::Vector3d& direction : DirectionGrid(c.max_angle_deg)) {
      for (double depth : {0.3, 1.0, 7.5, 120.0}) {
        const Eigen::Vector3d point = depth * direction;
        const T point_t[3] = {T(point.x()), T(point.y()), T(point.z())};
        T uv[2];
        ASSERT_TRUE(ImgFromCam(c.model, params, point_t, uv)) << point.transpose();
        T bearing_t[3];
        ASSERT_TRUE(CamFromImg(c.model, params, uv, bearing_t)) << point.transpose();
        const Eigen::Vector3d bearing(bearing_t[0], bearing_t[1], bearing_t[2]);
        EXPECT_NEAR(bearing.norm(), 1.0, Tolerances<T>::kNorm);
        EXPECT_LT(AngleBetween(bearing, direction), angle_tol)
            << "direction " << direction.transpose() << " depth " << depth;
        behind += direction.z() < 0;
        ++checked;
      }
    }
    EXPECT_GT(behind, 100);  // the grid really covers the part behind the image plane
    EXPECT_GT(checked, 1500);
  }
}

// Pixel -> bearing -> pixel over the image of the FOV.
TYPED_TEST(CameraModelRoundTrip, PixelToBearingToPixel) {
  using T = TypeParam;
  for (const ModelCase& c : Cases()) {
    SCOPED_TRACE(c.name);
    const std::vector<T> params(c.params.begin(), c.params.end());
    double max_error = 0;
    int checked = 0;
    for (const Eigen::Vector3d& direction : DirectionGrid(c.max_angle_deg)) {
      // Pixels generated in double, so that they are exact images of the grid.
      const Eigen::Vector3d point = direction;
      Eigen::Vector2d uv;
      ASSERT_TRUE(ImgFromCam(c.model, c.params, point.data(), uv.data()));
      const T uv_t[2] = {T(uv.x()), T(uv.y())};
      T bearing[3], uv_back[2];
      ASSERT_TRUE(CamFromImg(c.model, params, uv_t, bearing)) << uv.transpose();
      ASSERT_TRUE(ImgFromCam(c.model, params, bearing, uv_back)) << uv.transpose();
      const double error = std::hypot(double(uv_back[0]) - uv.x(), double(uv_back[1]) - uv.y());
      max_error = std::max(max_error, error);
      ++checked;
    }
    EXPECT_LT(max_error, Tolerances<T>::Pixel(c));
    EXPECT_GT(checked, 1000);
  }
}

// The 220-degree parameter sets do put the FOV edge inside the image (radius ~760 px of 766).
TEST(CameraModels, FovEdgeLandsInsideTheImage) {
  for (const ModelCase& c : Cases()) {
    SCOPED_TRACE(c.name);
    if (c.params[2] < 700) continue;  // the small test lens is not a 1600x1532 one
    for (double azimuth = 0; azimuth < 360; azimuth += 30) {
      const Eigen::Vector3d edge(std::sin(110 * kDeg) * std::cos(azimuth * kDeg),
                                 std::sin(110 * kDeg) * std::sin(azimuth * kDeg), std::cos(110 * kDeg));
      Eigen::Vector2d uv;
      ASSERT_TRUE(ImgFromCam(c.model, c.params, edge.data(), uv.data()));
      EXPECT_GT(uv.x(), -0.5);
      EXPECT_LT(uv.x(), 1599.5);
      EXPECT_GT(uv.y(), -0.5 - 1e-9);
      EXPECT_LT(uv.y(), 1531.5);
      const Eigen::Vector2d centre = c.model == CameraModelId::kOcam ? Eigen::Vector2d(c.params[0], c.params[1])
                                                                     : Eigen::Vector2d(c.params[2], c.params[3]);
      EXPECT_GT((uv - centre).norm(), 650.0);
    }
  }
}

TEST(CameraModels, OpticalAxisMapsToTheCentreAndBack) {
  for (const ModelCase& c : Cases()) {
    SCOPED_TRACE(c.name);
    const Eigen::Vector3d axis(0, 0, 2.0);
    Eigen::Vector2d uv;
    ASSERT_TRUE(ImgFromCam(c.model, c.params, axis.data(), uv.data()));
    Eigen::Vector3d bearing;
    ASSERT_TRUE(CamFromImg(c.model, c.params, uv.data(), bearing.data()));
    EXPECT_LT(AngleBetween(bearing, axis), 1e-6);
    // Straight behind and the origin are not projectable by any model.
    const Eigen::Vector3d behind(0, 0, -1), origin(0, 0, 0);
    EXPECT_FALSE(ImgFromCam(c.model, c.params, behind.data(), uv.data()));
    EXPECT_FALSE(ImgFromCam(c.model, c.params, origin.data(), uv.data()));
  }
}

// Double sphere rejects directions outside its valid set (xi = -0.2, alpha = 0.6: 122.05 deg).
TEST(CameraModels, DoubleSphereValidSet) {
  const std::vector<double> params = {350.0, 351.0, 799.5, 765.5, -0.2, 0.6};
  const double limit_deg = std::acos(-DoubleSphereModel::ValidW2(params.data())) / kDeg;
  EXPECT_NEAR(limit_deg, 122.05, 0.01);
  Eigen::Vector2d uv;
  const Eigen::Vector3d inside(std::sin(121.5 * kDeg), 0, std::cos(121.5 * kDeg));
  const Eigen::Vector3d outside(std::sin(122.5 * kDeg), 0, std::cos(122.5 * kDeg));
  EXPECT_TRUE(DoubleSphereModel::ImgFromCam(params.data(), 6, inside.data(), uv.data()));
  EXPECT_FALSE(DoubleSphereModel::ImgFromCam(params.data(), 6, outside.data(), uv.data()));
  // alpha > 0.5: pixels beyond the image disc r2 > 1 / (2 alpha - 1) have no bearing.
  const double r_max = 1.0 / std::sqrt(2 * 0.6 - 1);
  const Eigen::Vector2d far_pixel(799.5 + 350.0 * r_max * 1.01, 765.5);
  Eigen::Vector3d bearing;
  EXPECT_FALSE(DoubleSphereModel::CamFromImg(params.data(), 6, far_pixel.data(), bearing.data()));
}

// Extended unified rejects directions outside its valid set z > -w d (alpha = 0.62, beta = 1.1:
// w = 0.38 / 0.62, the limit angle a solves cos a = -w sqrt(beta sin^2 a + cos^2 a)).
TEST(CameraModels, ExtendedUnifiedValidSet) {
  const std::vector<double> params = {420.0, 421.0, 799.5, 765.5, 0.62, 1.1};
  const double w = ExtendedUnifiedModel::ValidW(params.data());
  EXPECT_NEAR(w, 0.38 / 0.62, 1e-12);
  double limit_deg = 90.0;  // bisection on the boundary
  for (double lo = 90.0, hi = 180.0; hi - lo > 1e-9; limit_deg = 0.5 * (lo + hi)) {
    const double a = 0.5 * (lo + hi) * kDeg;
    (std::cos(a) > -w * std::sqrt(1.1 * std::sin(a) * std::sin(a) + std::cos(a) * std::cos(a)) ? lo : hi) =
        0.5 * (lo + hi);
  }
  Eigen::Vector2d uv;
  const Eigen::Vector3d inside(std::sin((limit_deg - 0.5) * kDeg), 0, std::cos((limit_deg - 0.5) * kDeg));
  const Eigen::Vector3d outside(std::sin((limit_deg + 0.5) * kDeg), 0, std::cos((limit_deg + 0.5) * kDeg));
  EXPECT_TRUE(ExtendedUnifiedModel::ImgFromCam(params.data(), 6, inside.data(), uv.data()));
  EXPECT_FALSE(ExtendedUnifiedModel::ImgFromCam(params.data(), 6, outside.data(), uv.data()));
  // alpha > 0.5: pixels beyond the image disc r2 > 1 / (beta (2 alpha - 1)) have no bearing.
  const double r_max = 1.0 / std::sqrt(1.1 * (2 * 0.62 - 1));
  const Eigen::Vector2d far_pixel(799.5 + 420.0 * r_max * 1.01, 765.5);
  Eigen::Vector3d bearing;
  EXPECT_FALSE(ExtendedUnifiedModel::CamFromImg(params.data(), 6, far_pixel.data(), bearing.data()));
}

// Extended unified with beta = 1 is the unified model with xi = alpha / (1 - alpha) and focal
// length f (1 - alpha): u = f x / (z + xi |p|) (Khomutenko et al., eq. 3).
TEST(CameraModels, ExtendedUnifiedWithBetaOneIsTheUnifiedModel) {
  const double alpha = 0.57, f = 400.0;
  const std::vector<double> params = {f, f, 640.0, 480.0, alpha, 1.0};
  const double xi = alpha / (1 - alpha), gamma = f / (1 - alpha);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, -0.2, 1.0), Eigen::Vector3d(1.0, 0.5, -0.2)}) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(ExtendedUnifiedModel::ImgFromCam(params.data(), 6, p.data(), uv.data()));
    const double s = p.z() + xi * p.norm();
    EXPECT_NEAR(uv.x(), gamma * (1 - alpha) * p.x() / ((1 - alpha) * s) + 640.0, 1e-9);
    EXPECT_NEAR(uv.y(), gamma * (1 - alpha) * p.y() / ((1 - alpha) * s) + 480.0, 1e-9);
  }
}

// Ocam against its definition, written out independently: the bearing of a pixel is
// normalize(A^-1 (uv - c), -poly(rho)).
TEST(CameraModels, OcamUnprojectFollowsTheDefinition) {
  const std::vector<double> params = {811.661, 756.215, 0.999876,  -2.91382e-4, -1.66556e-4, -392.2,
                                      0.0,     0.00127, -1.746e-6, 2.258e-9,    1.0};
  Eigen::Matrix2d affine;
  affine << params[2], params[3], params[4], 1.0;
  for (const Eigen::Vector2d& uv : {Eigen::Vector2d(100.5, 700.0), Eigen::Vector2d(1500.0, 20.0),
                                    Eigen::Vector2d(811.661, 756.215), Eigen::Vector2d(900.0, 1400.0)}) {
    const Eigen::Vector2d xy = affine.inverse() * (uv - Eigen::Vector2d(params[0], params[1]));
    const double rho = xy.norm();
    const double poly = params[5] + params[7] * rho * rho + params[8] * std::pow(rho, 3) + params[9] * std::pow(rho, 4);
    const Eigen::Vector3d expected = Eigen::Vector3d(xy.x(), xy.y(), -poly).normalized();
    Eigen::Vector3d bearing;
    ASSERT_TRUE(OcamModel::CamFromImg(params.data(), 11, uv.data(), bearing.data()));
    EXPECT_LT(AngleBetween(bearing, expected), 1e-12) << uv.transpose();
    // x right, y down: a pixel right of and above the centre looks right (+x) and up (-y).
    if (uv.x() > 1000 && uv.y() < 100) {
      EXPECT_GT(bearing.x(), 0);
      EXPECT_LT(bearing.y(), 0);
    }
  }
}

// The templates compile and differentiate with ceres::Jet (used by the bundle adjustment):
// derivatives of ImgFromCam w.r.t. the point agree with central differences.
TEST(CameraModels, CeresJetDerivatives) {
  using Jet = ceres::Jet<double, 3>;
  for (const ModelCase& c : Cases()) {
    SCOPED_TRACE(c.name);
    const std::vector<Jet> params(c.params.begin(), c.params.end());
    // The grid starts on the optical axis (a coordinate singularity handled by its own branch).
    for (const Eigen::Vector3d& direction : DirectionGrid(c.max_angle_deg - 1)) {
      const Eigen::Vector3d point = 2.0 * direction;
      const Jet point_jet[3] = {Jet(point.x(), 0), Jet(point.y(), 1), Jet(point.z(), 2)};
      Jet uv_jet[2];
      ASSERT_TRUE(ImgFromCam(c.model, params, point_jet, uv_jet));
      for (int axis = 0; axis < 3; ++axis) {
        const double h = 1e-6;
        Eigen::Vector3d plus = point, minus = point;
        plus[axis] += h;
        minus[axis] -= h;
        Eigen::Vector2d uv_plus, uv_minus;
        ASSERT_TRUE(ImgFromCam(c.model, c.params, plus.data(), uv_plus.data()));
        ASSERT_TRUE(ImgFromCam(c.model, c.params, minus.data(), uv_minus.data()));
        const Eigen::Vector2d numeric = (uv_plus - uv_minus) / (2 * h);
        EXPECT_NEAR(uv_jet[0].v[axis], numeric.x(), 1e-4 * (1 + std::abs(numeric.x())));
        EXPECT_NEAR(uv_jet[1].v[axis], numeric.y(), 1e-4 * (1 + std::abs(numeric.y())));
      }
    }
  }
}

}  // namespace
}  // namespace rovo
