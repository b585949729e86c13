// Tests of ocam.h: the inverse-polynomial fit and its error measure, MakeOcamCamera, and the
// OCamCalib calib_results.txt reader against an independent implementation of OCamCalib's own
// cam2world (its row/column axes and backward z).
#include "datasets/ocam.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/camera_models.h"
#include "datasets/exchange/ocamcalib.h"

namespace rovo {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The real-rig-like lens of the issue: identity affine, centre (811.7, 756.2), 1600x1532, 220 deg.
std::vector<double> RealRigForward() {
  return {811.7, 756.2, 1.0, 0.0, 0.0, -392.2, 0.0, 0.00127, -1.746e-6, 2.258e-9};
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

std::string FixturePath() { return std::string(ROVO_TEST_DATA_DIR) + "/ocamcalib/calib_results.txt"; }

std::string WriteTemp(const std::string& name, const std::string& content) {
  const std::string path = ::testing::TempDir() + "rovo_ocam_test_" + name;
  std::ofstream(path) << content;
  return path;
}

// OCamCalib's cam2world (its C reference semantics): pixel (row, col) -> unit ray in its frame
// (x along rows, y along columns, z backwards: a0 < 0 for forward rays).
Eigen::Vector3d OcamCalibCam2World(double row, double col, const std::vector<double>& poly, double xc, double yc,
                                   double c, double d, double e) {
  const double inv_det = 1.0 / (c - d * e);
  const double xp = inv_det * ((row - xc) - d * (col - yc));
  const double yp = inv_det * (-e * (row - xc) + c * (col - yc));
  const double r = std::sqrt(xp * xp + yp * yp);
  double zp = poly[0], r_i = 1;
  for (size_t i = 1; i < poly.size(); ++i) {
    r_i *= r;
    zp += r_i * poly[i];
  }
  return Eigen::Vector3d(xp, yp, zp).normalized();
}

// The same direction in rovo's camera frame (x right = columns, y down = rows, z forward).
Eigen::Vector3d RovoFromOcamCalib(const Eigen::Vector3d& ocam) {
  return Eigen::Vector3d(ocam.y(), ocam.x(), -ocam.z());
}

// Local dtheta/drho of the forward model, to turn an elevation error into pixels independently of
// the library's own error measure.
double Elevation(const std::vector<double>& p, double rho) {
  return std::atan2(OcamModel::ForwardPoly(p.data(), rho), rho);
}

TEST(OcamFit, RealRigPolynomialReachesTheTolerance) {
  const std::vector<double> params = RealRigForward();
  const OcamInverseFit fit = FitOcamInversePolynomial(params, 220.0);
  std::printf("real-rig fit: %zu coefficients, max %.5f px, rms %.5f px\n", fit.inverse_poly.size(), fit.max_error_px,
              fit.rms_error_px);
  EXPECT_LT(fit.max_error_px, 0.01);
  EXPECT_LE(fit.rms_error_px, fit.max_error_px);
  EXPECT_LE(fit.inverse_poly.size(), 21u);
  std::vector<double> with_inverse = params;
  with_inverse.insert(with_inverse.end(), fit.inverse_poly.begin(), fit.inverse_poly.end());
  EXPECT_NEAR(OcamInverseMaxErrorPx(with_inverse, 220.0), fit.max_error_px, 1e-12);

  // Independent check on off-grid angles: the fitted radius, pushed through the forward model,
  // returns the elevation it came from, to within 0.01 px along the radius.
  double worst_px = 0;
  for (double angle = 0.013; angle <= 110.0; angle += 0.0971) {
    const double theta = (angle - 90.0) * kDeg;
    const double rho = OcamModel::InversePoly(with_inverse.data(), static_cast<int>(with_inverse.size()), theta);
    const double h = 1e-3;
    const double drho_dtheta = 2 * h / (Elevation(params, rho + h) - Elevation(params, rho - h));
    worst_px = std::max(worst_px, std::abs(Elevation(params, rho) - theta) * drho_dtheta);
  }
  EXPECT_LT(worst_px, 0.0101);
  EXPECT_GT(worst_px, 0.0);
  // The optical axis maps to the centre: rho(-pi/2) = 0 up to rounding.
  EXPECT_LT(std::abs(OcamModel::InversePoly(with_inverse.data(), static_cast<int>(with_inverse.size()), -M_PI / 2)),
            1e-9);
}

// A low degree cap cannot reach 0.01 px: the best fit is returned with its (larger) error.
TEST(OcamFit, DegreeCapReturnsTheBestFit) {
  const OcamInverseFit fit = FitOcamInversePolynomial(RealRigForward(), 220.0, 0.01, 4);
  EXPECT_EQ(fit.inverse_poly.size(), 5u);
  EXPECT_GT(fit.max_error_px, 0.01);
  EXPECT_LT(fit.max_error_px, 20.0);
  EXPECT_THROW(
      MakeOcamCamera(1600, 1532, 811.7, 756.2, 1, 0, 0, {-392.2, 0.0, 0.00127, -1.746e-6, 2.258e-9}, 220.0, 1e-9),
      std::invalid_argument);
}

// The inverse polynomials published with the real rig (OmniMVS config.yaml, numbers copied here)
// are far off over 220 degrees; the fit repairs them.
TEST(OcamFit, PublishedInverseOfTheRealRigIsOffAndRefitRepairsIt) {
  struct PublishedCamera {
    std::vector<double> params;  // cx(col), cy(row), c, d, e, a0..a4, then the published b
  };
  const std::vector<PublishedCamera> cameras = {
      {{811.661,
        756.215,
        0.999876,
        -2.91382E-4,
        -1.66556E-4,
        -392.21983020642324,
        0.0,
        0.0012707685299884767,
        -1.7456026867522776E-6,
        2.257655719602505E-9,
        611.433,
        386.965,
        -15.0504,
        -65.1466,
        -119.568,
        27.7131,
        355.781,
        206.82,
        -667.654,
        -1290.67,
        -985.814,
        -361.63,
        -52.6566}},
      {{817.845,
        793.1,
        1.00028,
        -0.032979,
        0.0327437,
        -393.2636335626606,
        0.0,
        0.0013030161088532755,
        -1.8689651365463267E-6,
        2.3792432009042225E-9,
        611.562,
        383.54,
        -22.3448,
        -47.6112,
        -41.6246,
        10.0601,
        -37.4865,
        -278.722,
        -487.074,
        -433.682,
        -222.271,
        -63.4335,
        -7.90549}},
  };
  for (const PublishedCamera& camera : cameras) {
    const double published_error = OcamInverseMaxErrorPx(camera.params, 220.0);
    std::printf("published inverse: max error %.3f px over 220 deg\n", published_error);
    EXPECT_GT(published_error, 1.0);
    const OcamInverseFit fit = FitOcamInversePolynomial(camera.params, 220.0);
    EXPECT_LT(fit.max_error_px, 0.01);
  }
}

TEST(OcamFit, RejectsInvalidForwardModels) {
  std::vector<double> params = RealRigForward();
  params[5] = 392.2;  // a0 > 0: z backwards
  EXPECT_THROW(FitOcamInversePolynomial(params, 220.0), std::invalid_argument);
  params = RealRigForward();
  params[2] = params[3] = 0.0;  // singular affine (c - d e = 0)
  EXPECT_THROW(FitOcamInversePolynomial(params, 220.0), std::invalid_argument);
  params = RealRigForward();
  EXPECT_THROW(FitOcamInversePolynomial(params, 400.0), std::invalid_argument);
  // a4 < 0 bends the elevation back before 110 degrees.
  params[9] = -2e-9;
  std::string problem;
  EXPECT_FALSE(OcamForwardMonotonic(params, 220.0, nullptr, &problem));
  EXPECT_THAT(problem, ::testing::HasSubstr("stops increasing"));
  try {
    FitOcamInversePolynomial(params, 220.0);
    ADD_FAILURE() << "fit accepted a folding lens";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("a0..a4"));
  }
  // The same lens is fine over a narrower field of view.
  EXPECT_TRUE(OcamForwardMonotonic(params, 90.0));  // it folds at about 50 deg from the axis
  double rho_edge = 0;
  EXPECT_TRUE(OcamForwardMonotonic(RealRigForward(), 220.0, &rho_edge));
  EXPECT_NEAR(Elevation(RealRigForward(), rho_edge), 20.0 * kDeg, 1e-9);
}

TEST(OcamCamera, MakeOcamCameraBuildsACheckedCamera) {
  const Camera camera =
      MakeOcamCamera(1600, 1532, 811.7, 756.2, 1.0, 0.0, 0.0, {-392.2, 0.0, 0.00127, -1.746e-6, 2.258e-9});
  EXPECT_EQ(camera.model, CameraModelId::kOcam);
  EXPECT_EQ(camera.width, 1600);
  EXPECT_EQ(camera.height, 1532);
  EXPECT_EQ(camera.max_fov_deg, 220.0);
  EXPECT_GE(camera.params.size(), 14u);
  EXPECT_NO_THROW(camera.Check("made"));
  EXPECT_LT(OcamInverseMaxErrorPx(camera.params, 220.0), 0.01);
  // Short forward polynomials are zero-padded; coefficients beyond a4 must be zero.
  const Camera quadratic = MakeOcamCamera(800, 800, 400, 400, 1, 0, 0, {-200.0, 0.0, 0.001}, 190.0);
  EXPECT_EQ(quadratic.params[8], 0.0);
  EXPECT_EQ(quadratic.params[9], 0.0);
  EXPECT_THROW(MakeOcamCamera(800, 800, 400, 400, 1, 0, 0, {-200.0, 0.0, 0.001, 0, 0, 1e-12}, 190.0),
               std::invalid_argument);
}

// The fixture (camera 1 of the real rig in OCamCalib's format) reads, maps to rovo's frame, and
// its published inverse is replaced by a refit.
TEST(OcamCalibReader, FixtureMatchesOcamCalibCam2World) {
  double file_error = 0;
  const Camera camera = ReadOcamCalibTxt(FixturePath(), 220.0, &file_error);
  EXPECT_EQ(camera.model, CameraModelId::kOcam);
  EXPECT_EQ(camera.width, 1600);
  EXPECT_EQ(camera.height, 1532);
  EXPECT_DOUBLE_EQ(camera.params[0], 811.661);  // column of the centre
  EXPECT_DOUBLE_EQ(camera.params[1], 756.215);  // row of the centre
  EXPECT_GT(file_error, 1.0);
  EXPECT_LT(OcamInverseMaxErrorPx(camera.params, 220.0), 0.01);
  EXPECT_NO_THROW(camera.Check("fixture"));

  const std::vector<double> poly = {-3.9221983020642324e+02, 0.0, 1.2707685299884767e-03, -1.7456026867522776e-06,
                                    2.257655719602505e-09};
  int checked = 0;
  for (double row = 0; row < 1532; row += 37) {
    for (double col = 0; col < 1600; col += 41) {
      const Eigen::Vector3d expected =
          RovoFromOcamCalib(OcamCalibCam2World(row, col, poly, 756.215, 811.661, 0.999876, -2.91382e-04, -1.66556e-04));
      const auto bearing = camera.Unproject(Eigen::Vector2d(col, row));
      if (!bearing) {
        // Only pixels outside the 220-degree cone are invalid.
        EXPECT_GT(std::acos(expected.z()), 110 * kDeg - 1e-6);
        continue;
      }
      EXPECT_LT(AngleBetween(*bearing, expected), 1e-9) << row << " " << col;
      // And back: the pixel is recovered to within the fit tolerance.
      const auto uv = camera.Project(*bearing);
      ASSERT_TRUE(uv.has_value());
      EXPECT_LT((*uv - Eigen::Vector2d(col, row)).norm(), 0.01);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

// A strongly non-identity affine exercises the axis swap and the normalisation by c.
TEST(OcamCalibReader, AffineMappingMatchesOcamCalib) {
  const double c = 1.05, d = 0.02, e = -0.03, xc = 500.25, yc = 640.75;
  const std::vector<double> poly = {-300.0, 0.0, 0.0012, -1.0e-6, 1.5e-9};
  char text[512];
  std::snprintf(text, sizeof(text),
                "# cam2world\n5 %.17g %.17g %.17g %.17g %.17g\n\n# world2cam\n0\n# center\n%.17g %.17g\n"
                "# affine\n%.17g %.17g %.17g\n# size\n1000 1280\n",
                poly[0], poly[1], poly[2], poly[3], poly[4], xc, yc, c, d, e);
  double file_error = 0;
  const Camera camera = ReadOcamCalibTxt(WriteTemp("affine.txt", text), 200.0, &file_error);
  EXPECT_TRUE(std::isinf(file_error));  // no inverse in the file
  EXPECT_EQ(camera.width, 1280);
  EXPECT_EQ(camera.height, 1000);
  int checked = 0;
  for (double row = 3; row < 1000; row += 29) {
    for (double col = 5; col < 1280; col += 31) {
      const Eigen::Vector3d expected = RovoFromOcamCalib(OcamCalibCam2World(row, col, poly, xc, yc, c, d, e));
      const auto bearing = camera.Unproject(Eigen::Vector2d(col, row));
      if (!bearing) continue;
      EXPECT_LT(AngleBetween(*bearing, expected), 1e-9) << row << " " << col;
      const auto uv = camera.Project(expected);
      ASSERT_TRUE(uv.has_value());
      EXPECT_LT((*uv - Eigen::Vector2d(col, row)).norm(), 0.01) << row << " " << col;
      ++checked;
    }
  }
  EXPECT_GT(checked, 800);
}

// OCamCalib's world2cam (its C reference semantics): ray in its frame -> pixel (row, col).
Eigen::Vector2d OcamCalibWorld2Cam(const Eigen::Vector3d& ray, const std::vector<double>& invpol, double xc, double yc,
                                   double c, double d, double e) {
  const double norm = std::sqrt(ray.x() * ray.x() + ray.y() * ray.y());
  const double theta = std::atan(ray.z() / norm);
  double rho = invpol[0], t_i = 1;
  for (size_t i = 1; i < invpol.size(); ++i) {
    t_i *= theta;
    rho += t_i * invpol[i];
  }
  const double x = ray.x() / norm * rho, y = ray.y() / norm * rho;
  return Eigen::Vector2d(x * c + y * d + xc, x * e + y + yc);
}

// With a non-identity affine and an accurate inverse in the file, the camera's Project equals
// OCamCalib's world2cam with the file's own coefficients (checks the inverse's mapping b' = c b).
TEST(OcamCalibReader, ProjectMatchesOcamCalibWorld2Cam) {
  const double c = 1.05, d = 0.02, e = -0.03, xc = 500.25, yc = 640.75;
  const std::vector<double> poly = {-300.0, 0.0, 0.0012, -1.0e-6, 1.5e-9};
  // The documented mapping, written out here, to fit an inverse and express it in OCamCalib's units.
  std::vector<double> rovo_params = {yc, xc, 1 / c, e / c, d / c};
  for (int i = 0; i < 5; ++i) rovo_params.push_back(poly[i] * std::pow(c, 1 - i));
  const OcamInverseFit fit = FitOcamInversePolynomial(rovo_params, 200.0, 0.001);
  ASSERT_LT(fit.max_error_px, 0.001);
  std::vector<double> invpol;
  for (double b : fit.inverse_poly) invpol.push_back(b / c);
  std::string text = "5";
  char number[128];
  for (double a : poly) {
    std::snprintf(number, sizeof(number), " %.17g", a);
    text += number;
  }
  text += "\n" + std::to_string(invpol.size());
  for (double b : invpol) {
    std::snprintf(number, sizeof(number), " %.17g", b);
    text += number;
  }
  std::snprintf(number, sizeof(number), "\n%.17g %.17g\n", xc, yc);
  text += number;
  std::snprintf(number, sizeof(number), "%.17g %.17g %.17g\n1000 1280\n", c, d, e);
  text += number;
  double file_error = 1;
  const Camera camera = ReadOcamCalibTxt(WriteTemp("world2cam.txt", text), 200.0, &file_error);
  EXPECT_LT(file_error, 0.001);  // kept, not refitted
  int checked = 0;
  for (double angle = 0.5; angle <= 100; angle += 4.5) {
    for (double azimuth = 3; azimuth < 360; azimuth += 17) {
      const Eigen::Vector3d rovo_ray(std::sin(angle * kDeg) * std::cos(azimuth * kDeg),
                                     std::sin(angle * kDeg) * std::sin(azimuth * kDeg), std::cos(angle * kDeg));
      const Eigen::Vector3d ocam_ray(rovo_ray.y(), rovo_ray.x(), -rovo_ray.z());
      const Eigen::Vector2d row_col = OcamCalibWorld2Cam(ocam_ray, invpol, xc, yc, c, d, e);
      const auto uv = camera.Project(rovo_ray);
      ASSERT_TRUE(uv.has_value());
      EXPECT_LT((*uv - Eigen::Vector2d(row_col.y(), row_col.x())).norm(), 1e-8) << angle << " " << azimuth;
      ++checked;
    }
  }
  EXPECT_GT(checked, 400);
}

// An accurate inverse polynomial in the file is kept (scaled by c, the sensor normalisation).
TEST(OcamCalibReader, AccurateInverseInTheFileIsKept) {
  // Fit an inverse in OCamCalib's own units: with c = 1, d = e = 0 the mapping is a relabelling.
  const std::vector<double> params = RealRigForward();
  const OcamInverseFit fit = FitOcamInversePolynomial(params, 220.0, 0.001);
  ASSERT_LT(fit.max_error_px, 0.001);
  std::string text =
      "# cam2world\n5 -392.2 0 0.00127 -1.746e-6 2.258e-9\n# world2cam\n" + std::to_string(fit.inverse_poly.size());
  char number[64];
  for (double b : fit.inverse_poly) {
    std::snprintf(number, sizeof(number), " %.17g", b);
    text += number;
  }
  text += "\n756.2 811.7\n1 0 0\n1532 1600\n";
  double file_error = 1;
  const Camera camera = ReadOcamCalibTxt(WriteTemp("accurate.txt", text), 220.0, &file_error);
  EXPECT_LT(file_error, 0.001);
  ASSERT_EQ(camera.params.size(), 10 + fit.inverse_poly.size());
  for (size_t i = 0; i < fit.inverse_poly.size(); ++i) EXPECT_EQ(camera.params[10 + i], fit.inverse_poly[i]);
}

void ExpectReadFails(const std::string& name, const std::string& content, const std::string& line_and_field) {
  const std::string path = WriteTemp(name, content);
  try {
    ReadOcamCalibTxt(path);
    ADD_FAILURE() << name << " was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr(path));
    EXPECT_THAT(e.what(), ::testing::HasSubstr(line_and_field));
  }
}

TEST(OcamCalibReader, ErrorsNameFileLineAndField) {
  EXPECT_THROW(ReadOcamCalibTxt("/nonexistent/calib_results.txt"), std::runtime_error);
  const std::string good_tail = "756.2 811.7\n1 0 0\n1532 1600\n";
  ExpectReadFails("short.txt", "# only a comment\n5 -392.2 0 0.00127 -1.746e-6 2.258e-9\n", "expected 5 data lines");
  ExpectReadFails("count.txt", "#\n5 -392.2 0 0.00127 -1.746e-6\n0\n" + good_tail, ":2: poly");
  ExpectReadFails("number.txt", "#\n5 -392.2 0 0.00127 -1.746e-6 2.258e-9\n2 1 x\n" + good_tail, ":3: inverse poly");
  ExpectReadFails("center.txt", "5 -392.2 0 0.00127 -1.746e-6 2.258e-9\n0\n756.2\n1 0 0\n1532 1600\n", ":3: center");
  ExpectReadFails("affine.txt", "5 -392.2 0 0.00127 -1.746e-6 2.258e-9\n0\n756.2 811.7\n-1 0 0\n1532 1600\n",
                  ":4: affine");
  ExpectReadFails("size.txt", "5 -392.2 0 0.00127 -1.746e-6 2.258e-9\n0\n756.2 811.7\n1 0 0\n1532 0\n",
                  ":5: image size");
  ExpectReadFails("a0.txt", "5 392.2 0 0.00127 -1.746e-6 2.258e-9\n0\n" + good_tail, ":1: poly");
  ExpectReadFails("fold.txt", "5 -392.2 0 0.00127 -1.746e-6 -2e-9\n0\n" + good_tail, ":1: poly");
}

}  // namespace
}  // namespace rovo
