// Exchange formats: lens fits, Kalibr / Basalt / EuRoC files written and read back, other systems'
// trajectory formats.
#include "datasets/exchange/exchange.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>

#include "datasets/exchange/lens_fit.h"
#include "datasets/io.h"
#include "datasets/trajectory.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

std::string TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rovo_exchange_unit_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir.string();
}

TEST(LensFit, SameKindExportsExactly) {
  const Camera ds{CameraModelId::kDoubleSphere, 1600, 1532, {350.0, 351.0, 799.5, 765.5, -0.2, 0.6}, 220.0};
  const LensFit fit = FitExchangeLens(ds, ExchangeLensModel::kDoubleSphere);
  EXPECT_TRUE(fit.exact);
  EXPECT_EQ(fit.params, ds.params);
  EXPECT_EQ(fit.max_error_px, 0.0);
  EXPECT_GT(fit.num_samples, 1000);
}

// A double-sphere lens fitted with eucm/kb4 from a poor start: the fit recovers a close lens, and
// the reported error is the true disagreement (checked on bearings off the fit grid).
TEST(LensFit, FitsAnotherModelAndReportsItsError) {
  const Camera ds{CameraModelId::kDoubleSphere, 800, 766, {175.0, 175.5, 399.5, 382.5, -0.2, 0.6}, 200.0};
  for (ExchangeLensModel model : {ExchangeLensModel::kExtendedUnified, ExchangeLensModel::kKannalaBrandt4}) {
    const LensFit fit = FitExchangeLens(ds, model);
    EXPECT_FALSE(fit.exact);
    EXPECT_LT(fit.max_error_px, 1.0) << ExchangeLensModelName(model);
    EXPECT_LE(fit.rms_error_px, fit.max_error_px);
    double worst = 0.0;
    for (double angle = 0.25; angle < 100.0; angle += 3.3) {
      for (double azimuth = 2.5; azimuth < 360; azimuth += 10) {
        const double t = angle * M_PI / 180, p = azimuth * M_PI / 180;
        const Eigen::Vector3d bearing(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
        const auto uv = ds.Project(bearing);
        if (!uv || !ds.InImage(*uv)) continue;
        Eigen::Vector2d fitted;
        ASSERT_TRUE(ProjectExchangeLens(model, fit.params, bearing, &fitted));
        worst = std::max(worst, (fitted - *uv).norm());
      }
    }
    EXPECT_LE(worst, fit.max_error_px * 1.1 + 1e-6) << ExchangeLensModelName(model);
    EXPECT_GT(worst, 0.5 * fit.max_error_px) << ExchangeLensModelName(model);
  }
}

// The rovo4 ocam lens (quarter size): a 220-degree fit in each model the formats carry.
TEST(LensFit, Rovo4OcamLens) {
  const Camera ocam = MakeRigPreset("rovo4").Scaled(0.25).cameras[0].camera;
  const LensFit kb4 = FitExchangeLens(ocam, ExchangeLensModel::kKannalaBrandt4);
  EXPECT_LT(kb4.max_error_px, 0.5);  // ~1.05 px at full size
  EXPECT_NEAR(kb4.max_angle_deg, 110.0, 1e-9);
  const LensFit ds = FitExchangeLens(ocam, ExchangeLensModel::kDoubleSphere);
  EXPECT_LT(ds.max_error_px, 2.0);
  EXPECT_GT(ds.max_error_px, kb4.max_error_px);
  EXPECT_THROW(CameraFromExchangeLens(ExchangeLensModel::kOmniRadtan, std::vector<double>(9, 1.0), 10, 10, 200, "x"),
               std::invalid_argument);
}

std::vector<ExchangeCamera> TwoCameras() {
  std::vector<ExchangeCamera> cameras(2);
  cameras[0] = {"cam0",
                ExchangeLensModel::kDoubleSphere,
                {350.0, 351.0, 799.5, 765.5, -0.2, 0.6},
                1600,
                1532,
                220.0,
                CamFromRigFromMount(45, 0, Eigen::Vector3d(0.5, 0.45, 0))};
  cameras[1] = {"cam1",
                ExchangeLensModel::kExtendedUnified,
                {420.0, 421.0, 799.5, 765.5, 0.62, 1.1},
                1600,
                1532,
                220.0,
                CamFromRigFromMount(-45, 2, Eigen::Vector3d(0.5, -0.45, 0.01))};
  return cameras;
}

void ExpectSameCameras(const std::vector<ExchangeCamera>& a, const std::vector<ExchangeCamera>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].model, b[i].model);
    ASSERT_EQ(a[i].params.size(), b[i].params.size());
    for (size_t k = 0; k < a[i].params.size(); ++k) EXPECT_DOUBLE_EQ(a[i].params[k], b[i].params[k]);
    EXPECT_EQ(a[i].width, b[i].width);
    EXPECT_EQ(a[i].height, b[i].height);
    EXPECT_LT((a[i].cam_from_rig.translation - b[i].cam_from_rig.translation).norm(), 1e-12);
    EXPECT_LT(a[i].cam_from_rig.rotation.angularDistance(b[i].cam_from_rig.rotation), 1e-12);
  }
}

TEST(Exchange, KalibrCamchainRoundTrip) {
  const std::string dir = TempDir("kalibr");
  const std::vector<ExchangeCamera> cameras = TwoCameras();
  const std::string text = KalibrCamchainYaml(cameras, "test");
  EXPECT_NE(text.find("T_cn_cnm1"), std::string::npos);
  EXPECT_NE(text.find("cam_overlaps: [1]"), std::string::npos);  // 90 deg apart, 220-degree lenses
  EXPECT_NE(text.find("intrinsics: [-0.20000000000000001, 0.59999999999999998, 350, 351"), std::string::npos);
  WriteFileAtomic(dir + "/camchain.yaml", text);
  ExpectSameCameras(cameras, ReadKalibrCamchain(dir + "/camchain.yaml"));
  // Without T_cam_imu the rig is camera 0, chained by T_cn_cnm1.
  std::string chain_only;
  bool skip = false;
  for (size_t start = 0; start < text.size();) {
    const size_t end = text.find('\n', start);
    const std::string line = text.substr(start, end - start);
    if (line.find("T_cam_imu") != std::string::npos) {
      skip = true;
    } else if (skip && line.rfind("  - ", 0) == 0) {
    } else {
      skip = false;
      chain_only += line + "\n";
    }
    start = end + 1;
  }
  WriteFileAtomic(dir + "/chain.yaml", chain_only);
  const std::vector<ExchangeCamera> chained = ReadKalibrCamchain(dir + "/chain.yaml");
  const Rigid3 expected = cameras[1].cam_from_rig * cameras[0].cam_from_rig.Inverse();
  EXPECT_LT(chained[0].cam_from_rig.rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-12);
  EXPECT_LT(chained[1].cam_from_rig.rotation.angularDistance(expected.rotation), 1e-12);
  EXPECT_LT((chained[1].cam_from_rig.translation - expected.translation).norm(), 1e-12);
  WriteFileAtomic(dir + "/bad.yaml", "cam0:\n  camera_model: fov\n  intrinsics: [1, 2, 3, 4]\n");
  try {
    ReadKalibrCamchain(dir + "/bad.yaml");
    ADD_FAILURE() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("camera_model"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(Exchange, BasaltCalibrationRoundTripAndRequiredFields) {
  const std::string dir = TempDir("basalt");
  std::vector<ExchangeCamera> cameras = TwoCameras();
  cameras[1].model = ExchangeLensModel::kKannalaBrandt4;
  cameras[1].params = {370.0, 371.0, 801.2, 764.9, 0.02, -0.003, 0.0005, -0.00003};
  const nlohmann::json json = BasaltCalibrationJson(cameras);
  const nlohmann::json& v = json["value0"];
  EXPECT_EQ(v["calib_accel_bias"].size(), 9u);
  EXPECT_EQ(v["calib_gyro_bias"].size(), 12u);
  EXPECT_TRUE(v["cam_time_offset_ns"].is_number_integer());
  EXPECT_TRUE(v["resolution"][0][0].is_number_integer());
  EXPECT_TRUE(v["vignette"].is_array());
  EXPECT_EQ(v["intrinsics"][1]["camera_type"], "kb4");
  for (const char* key : {"accel_noise_std", "gyro_noise_std", "accel_bias_std", "gyro_bias_std"}) {
    EXPECT_EQ(v[key].size(), 3u) << key;
  }
  WriteJsonFileAtomic(dir + "/calibration.json", json);
  ExpectSameCameras(cameras, ReadBasaltCalibration(dir + "/calibration.json"));
  cameras[0].model = ExchangeLensModel::kOmniRadtan;
  cameras[0].params.assign(9, 1.0);
  EXPECT_THROW(BasaltCalibrationJson(cameras), std::invalid_argument);
  fs::remove_all(dir);
}

TEST(Exchange, EurocSensorYamlAndGroundTruthRoundTrip) {
  const std::string dir = TempDir("euroc");
  ExchangeCamera camera = TwoCameras()[1];
  camera.model = ExchangeLensModel::kOmniRadtan;
  camera.params = {800.0, 801.0, 799.5, 765.5, 1.4, -0.1, 0.01, 0.001, -0.002};
  WriteFileAtomic(dir + "/sensor.yaml", EurocSensorYaml(camera, 10.0, "test"));
  const ExchangeCamera back = ReadEurocSensorYaml(dir + "/sensor.yaml", "cam1");
  ExpectSameCameras({camera}, {back});
  EXPECT_EQ(back.max_fov_deg, 220.0);

  Trajectory trajectory;
  for (int i = 0; i < 5; ++i) {
    trajectory.push_back({0.1 * i, Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ())),
                                          Eigen::Vector3d(1.0 * i, 0.5 * i * i, 0.0))});
  }
  const std::string csv = EurocGroundTruthCsv(trajectory);
  WriteFileAtomic(dir + "/data.csv", csv);
  const Trajectory read = ReadEurocCsv(dir + "/data.csv");
  ASSERT_EQ(read.size(), trajectory.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_NEAR(read[i].timestamp, trajectory[i].timestamp, 1e-12);
    EXPECT_LT((read[i].world_from_rig.translation - trajectory[i].world_from_rig.translation).norm(), 1e-12);
    EXPECT_LT(read[i].world_from_rig.rotation.angularDistance(trajectory[i].world_from_rig.rotation), 1e-12);
  }
  // Row 2: velocity (x, y) = ((3 - 1) / 0.2, (4.5 - 0.5) / 0.2) = (10, 20) by central difference.
  const size_t row = csv.find("\n200000000,2,2,0,");
  ASSERT_NE(row, std::string::npos) << csv;
  std::vector<double> fields;
  std::stringstream line(csv.substr(row + 1, csv.find('\n', row + 1) - row - 1));
  for (std::string field; std::getline(line, field, ',');) fields.push_back(std::stod(field));
  ASSERT_EQ(fields.size(), 17u);
  EXPECT_NEAR(fields[8], 10.0, 1e-9);
  EXPECT_NEAR(fields[9], 20.0, 1e-9);
  for (int i = 11; i < 17; ++i) EXPECT_EQ(fields[static_cast<size_t>(i)], 0.0);
  fs::remove_all(dir);
}

TEST(Exchange, OtherSystemsTrajectoryFormats) {
  const std::string dir = TempDir("trajectories");
  WriteFileAtomic(dir + "/ns.txt", "1403636579763555584 1 2 3 0 0 0 1\n1403636579813555456 1.5 2 3 0 0 0 1\n");
  bool ns = false;
  const Trajectory t = ReadTumAnyUnit(dir + "/ns.txt", &ns);
  EXPECT_TRUE(ns);
  EXPECT_NEAR(t[1].timestamp - t[0].timestamp, 0.05, 1e-6);
  WriteFileAtomic(dir + "/s.txt", "0.0 1 2 3 0 0 0 1\n0.1 1.5 2 3 0 0 0 1\n");
  EXPECT_NEAR(ReadTumAnyUnit(dir + "/s.txt", &ns)[1].timestamp, 0.1, 1e-15);
  EXPECT_FALSE(ns);
  WriteFileAtomic(dir + "/kitti.txt", "1 0 0 1 0 1 0 2 0 0 1 3\n0 -1 0 4 1 0 0 5 0 0 1 6\n");
  const Trajectory k = ReadKittiPoses(dir + "/kitti.txt", {0.0, 0.1});
  ASSERT_EQ(k.size(), 2u);
  EXPECT_EQ(k[1].timestamp, 0.1);
  EXPECT_LT((k[1].world_from_rig.translation - Eigen::Vector3d(4, 5, 6)).norm(), 1e-15);
  EXPECT_NEAR((k[1].world_from_rig.rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0, 1e-12);
  EXPECT_THROW(ReadKittiPoses(dir + "/kitti.txt", {0.0}), std::runtime_error);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rovo
