#include "datasets/exchange/omnimvs.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "datasets/io.h"
#include "datasets/ocam.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kConfig = std::string(ROVO_SHARED_DIR) + "/data/omnimvs_itbt_config.yaml";

TEST(OmniMvs, ImportRefitsAndReportsTheFilesInverseError) {
  std::string report;
  const Rig rig = ReadOmniMvsConfig(kConfig, &report);
  ASSERT_EQ(rig.NumCameras(), 4);
  std::istringstream lines(report);
  std::string line;
  double worst_file_error = 0.0;
  int reported = 0;
  while (std::getline(lines, line)) {
    SCOPED_TRACE(line);
    const size_t at = line.find("off by up to ");
    ASSERT_NE(at, std::string::npos);
    const double file_error = std::atof(line.c_str() + at + std::strlen("off by up to "));
    EXPECT_GT(file_error, 0.1);  // every camera's own inverse is visibly off
    worst_file_error = std::max(worst_file_error, file_error);
    EXPECT_THAT(line, HasSubstr("cam" + std::to_string(reported) + ":"));
    ++reported;
  }
  EXPECT_EQ(reported, 4);
  EXPECT_GT(worst_file_error, 1.0);
  for (const RigCamera& rc : rig.cameras) {
    EXPECT_LT(OcamInverseMaxErrorPx(rc.camera.params, rc.camera.max_fov_deg), 0.01) << rc.name;
    EXPECT_EQ(rc.camera.width, 1600);
    EXPECT_EQ(rc.camera.height, 1532);
  }
  // center is [row, col]: cx (column) = 811.661, cy (row) = 756.215.
  EXPECT_DOUBLE_EQ(rig.cameras[0].camera.params[0], 811.661);
  EXPECT_DOUBLE_EQ(rig.cameras[0].camera.params[1], 756.215);
  // Affine [c, d, e] of OCamCalib (x along rows) -> ours (x along columns): 1/c, e/c, d/c.
  EXPECT_DOUBLE_EQ(rig.cameras[1].camera.params[2], 1.0 / 1.00028);
  EXPECT_DOUBLE_EQ(rig.cameras[1].camera.params[3], 0.0327437 / 1.00028);
  EXPECT_DOUBLE_EQ(rig.cameras[1].camera.params[4], -0.032979 / 1.00028);
}

// Bearing of pixel (col, row) computed directly in the file's conventions (the yaml header):
// (row - center_row, col - center_col) = [c d; e 1] (x_o, y_o), ray = (y_o, x_o, -poly(rho)).
Eigen::Vector3d FileBearing(double col, double row, const double center[2], const double affine[3],
                            const double poly[5]) {
  const double dr = row - center[0], dc = col - center[1];
  const double det = affine[0] - affine[1] * affine[2];
  const double x_o = (dr - affine[1] * dc) / det;
  const double y_o = (affine[0] * dc - affine[2] * dr) / det;
  const double rho = std::hypot(x_o, y_o);
  double z = 0.0;
  for (int i = 4; i >= 0; --i) z = z * rho + poly[i];
  return Eigen::Vector3d(y_o, x_o, -z).normalized();
}

TEST(OmniMvs, PixelBearingsMatchTheFileConvention) {
  const Rig rig = ReadOmniMvsConfig(kConfig, nullptr);
  // Camera 2 of the file (cam1 here) has the largest skew (d = -0.033, e = 0.033).
  const double center[2] = {793.1, 817.845};
  const double affine[3] = {1.00028, -0.032979, 0.0327437};
  const double poly[5] = {-393.2636335626606, 0.0, 0.0013030161088532755, -1.8689651365463267E-6,
                          2.3792432009042225E-9};
  const Camera& camera = rig.cameras[1].camera;
  for (double col : {100.0, 500.0, 817.845, 1000.0, 1500.0}) {
    for (double row : {80.0, 400.0, 793.1, 1100.0, 1450.0}) {
      const Eigen::Vector3d expected = FileBearing(col, row, center, affine, poly);
      if (AngleBetween(expected, Eigen::Vector3d::UnitZ()) > 109.0 * M_PI / 180.0) continue;
      const auto bearing = camera.Unproject(Eigen::Vector2d(col, row));
      ASSERT_TRUE(bearing.has_value()) << col << " " << row;
      EXPECT_LT(AngleBetween(*bearing, expected), 1e-9) << col << " " << row;
      const auto uv = camera.Project(expected);
      ASSERT_TRUE(uv.has_value());
      EXPECT_LT((*uv - Eigen::Vector2d(col, row)).norm(), 0.01) << col << " " << row;
    }
  }
}

TEST(OmniMvs, EmbeddedPresetEqualsImport) {
  const Rig imported = ReadOmniMvsConfig(kConfig, nullptr);
  const Rig preset = MakeRigPreset("rovo4_real");
  ASSERT_EQ(preset.NumCameras(), imported.NumCameras());
  for (int i = 0; i < imported.NumCameras(); ++i) {
    const RigCamera& a = imported.cameras[i];
    const RigCamera& b = preset.cameras[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.camera.width, b.camera.width);
    EXPECT_EQ(a.camera.height, b.camera.height);
    EXPECT_EQ(a.camera.max_fov_deg, b.camera.max_fov_deg);
    EXPECT_EQ(a.camera.params, b.camera.params) << i;
    EXPECT_EQ(a.cam_from_rig.rotation.coeffs(), b.cam_from_rig.rotation.coeffs()) << i;
    EXPECT_EQ(a.cam_from_rig.translation, b.cam_from_rig.translation) << i;
  }
}

TEST(OmniMvs, FrameChangeMapsFileAxesToRep103) {
  const Eigen::Matrix3d m = RigFromOmniMvsRigRotation();
  EXPECT_NEAR(m.determinant(), 1.0, 1e-15);
  EXPECT_TRUE((m * Eigen::Vector3d(0, 1, 0)).isApprox(Eigen::Vector3d(0, 0, -1)));  // file y (down) -> -z
  // File camera 1: cam2rig rotation vector and translation from the yaml.
  const Rigid3 file_rig_from_cam =
      Rigid3::FromAxisAngle(Eigen::Vector3d(0.05287133304667693, 0.7411561834637101, 0.02981358273057615),
                            Eigen::Vector3d(0.1485451015397448, -6.40692965168468E-5, 0.14722476953097846));
  const Rig rig = ReadOmniMvsConfig(kConfig, nullptr);
  const Rigid3& cam_from_rig = rig.cameras[0].cam_from_rig;
  EXPECT_TRUE(CameraPositionInRig(cam_from_rig).isApprox(m * file_rig_from_cam.translation, 1e-12));
  EXPECT_TRUE(
      CameraAxisInRig(cam_from_rig).isApprox(m * (file_rig_from_cam.rotation * Eigen::Vector3d::UnitZ()), 1e-12));
  // A point seen by the camera maps consistently through both frames.
  const Eigen::Vector3d point_in_file_rig(3.0, -0.5, 2.0);
  const Eigen::Vector3d in_cam_direct = file_rig_from_cam.Inverse() * point_in_file_rig;
  EXPECT_TRUE((cam_from_rig * (m * point_in_file_rig)).isApprox(in_cam_direct, 1e-12));
}

std::string WriteModifiedConfig(const std::string& from, const std::string& to) {
  std::string text = ReadFile(kConfig);
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  const std::string path =
      (fs::temp_directory_path() / ("rovo_omnimvs_test_" + std::to_string(::getpid()) + ".yaml")).string();
  WriteFileAtomic(path, text);
  return path;
}

void ExpectImportError(const std::string& from, const std::string& to, const std::string& field) {
  const std::string path = WriteModifiedConfig(from, to);
  try {
    ReadOmniMvsConfig(path, nullptr);
    ADD_FAILURE() << "no error for " << field;
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ": " + field)) << e.what();
  }
  fs::remove(path);
}

TEST(OmniMvs, MalformedFilesNameTheField) {
  ExpectImportError("center: [793.1, 817.845]", "center: [793.1]", "cameras[1].center");
  ExpectImportError("image_size: [1532, 1600]", "image_size: [1532, x]", "cameras[0].image_size");
  ExpectImportError("poly: [5, -397.8543380457763,", "poly: [6, -397.8543380457763,", "cameras[2].poly");
  ExpectImportError("max_fov: 220.0\n  - cam_id: 2", "max_fov: 400\n  - cam_id: 2", "cameras[0].max_fov");
  ExpectImportError("model: ocam\n    poly: [5, -392.9083750477403", "model: pinhole\n    poly: [5, -392.9083750477403",
                    "cameras[3].model");
  ExpectImportError("cameras:", "kameras:", "cameras");
  try {
    ReadOmniMvsConfig("/nonexistent/config.yaml", nullptr);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/config.yaml"));
  }
}

}  // namespace
}  // namespace rovo
