// The IMU in `rovo dataset export --format euroc|kalibr|basalt`: the files each format defines for it
// (read here with yaml-cpp and nlohmann-json, compared with the dataset's IMU and its continuous-time
// ground truth), the camera extrinsics relative to the IMU, and the round trip export -> import.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "datasets/continuous_trajectory.h"
#include "datasets/dataset.h"
#include "datasets/io.h"
#include "tests/datasets/integration/imu_fixture.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

int RunShell(const std::string& command, const std::string& log) {
  const int status = std::system((command + " > " + log + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<std::vector<std::string>> CsvRows(const std::string& path) {
  std::istringstream in(ReadFile(path));
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> row;
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) row.push_back(f);
    rows.push_back(row);
  }
  return rows;
}

Rigid3 FromMatrix(const std::vector<double>& m) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = m[static_cast<size_t>(4 * (i / 3) + i % 3)];
  return Rigid3(r, Eigen::Vector3d(m[3], m[7], m[11]));
}

double Distance(const Rigid3& a, const Rigid3& b) {
  return (a.translation - b.translation).norm() + a.rotation.angularDistance(b.rotation);
}

class ExchangeImuTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = (fs::temp_directory_path() / ("rovo_exchange_imu_" + std::to_string(::getpid()))).string();
    fs::create_directories(root_);
    const std::string render = std::string(ROVO_BINARY) +
                               " render --preset cloudy_urban --quick --frames 0:3 --spp 1 --scale 0.5 --quiet --out " +
                               Dataset();
    ASSERT_EQ(RunShell(render, root_ + "/render.log"), 0) << ReadFile(root_ + "/render.log");
    test::AddImu(Dataset());
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static std::string Dataset() { return root_ + "/dataset"; }
  static std::string Export(const std::string& format, const std::string& extra = "") {
    const std::string out = root_ + "/" + format;
    EXPECT_EQ(RunShell(std::string(ROVO_BINARY) + " dataset export " + Dataset() + " --format " + format + " --out " +
                           out + " " + extra,
                       root_ + "/export_" + format + ".log"),
              0)
        << ReadFile(root_ + "/export_" + format + ".log");
    return out;
  }
  // Import of an export gives the dataset's rig, ground truth and IMU back.
  static void CheckRoundTrip(const std::string& exported, const std::string& format) {
    const std::string imported = exported + "_imported";
    ASSERT_EQ(RunShell(std::string(ROVO_BINARY) + " dataset import " + exported + " --format " + format + " --out " +
                           imported,
                       root_ + "/import.log"),
              0)
        << ReadFile(root_ + "/import.log");
    EXPECT_TRUE(ValidateDataset(imported).empty()) << ReadFile(root_ + "/import.log");
    const DatasetInfo a = ReadDatasetInfo(Dataset()), b = ReadDatasetInfo(imported);
    ASSERT_TRUE(b.imu.has_value()) << format;
    EXPECT_EQ(b.imu->noise, a.imu->noise);
    EXPECT_EQ(b.imu->rate_hz, a.imu->rate_hz);
    EXPECT_EQ(b.imu->time_offset_s, a.imu->time_offset_s);
    EXPECT_EQ(b.imu->seed, a.imu->seed);
    EXPECT_LT(Distance(*a.rig.imu_from_rig, *b.rig.imu_from_rig), 1e-12);
    for (size_t k = 0; k < a.rig.cameras.size(); ++k) {
      EXPECT_LT(Distance(a.rig.cameras[k].cam_from_rig, b.rig.cameras[k].cam_from_rig), 1e-12) << format << " " << k;
    }
    const Trajectory gt_a = ReadTum(GroundTruthPath(Dataset())), gt_b = ReadTum(GroundTruthPath(imported));
    ASSERT_EQ(gt_a.size(), gt_b.size());
    for (size_t i = 0; i < gt_a.size(); ++i) {
      EXPECT_NEAR(gt_a[i].timestamp, gt_b[i].timestamp, 1e-9);
      EXPECT_LT(Distance(gt_a[i].world_from_rig, gt_b[i].world_from_rig), 1e-9) << format << " frame " << i;
    }
    const ImuStreams sa = ReadImuStreams(Dataset()), sb = ReadImuStreams(imported);
    ASSERT_EQ(sa.measured.size(), sb.measured.size());
    for (size_t k = 0; k < sa.measured.size(); ++k) {
      EXPECT_NEAR(sa.measured[k].timestamp, sb.measured[k].timestamp, 0.5e-9);
      EXPECT_EQ(sa.measured[k].angular_velocity, sb.measured[k].angular_velocity);
      EXPECT_EQ(sa.measured[k].linear_acceleration, sb.measured[k].linear_acceleration);
      EXPECT_EQ(sa.exact[k].angular_velocity, sb.exact[k].angular_velocity);
      EXPECT_EQ(sa.bias[k].gyroscope_bias, sb.bias[k].gyroscope_bias);
      EXPECT_EQ(sa.bias[k].accelerometer_bias, sb.bias[k].accelerometer_bias);
    }
  }
  static std::string root_;
};
std::string ExchangeImuTest::root_;

TEST_F(ExchangeImuTest, EurocCarriesTheImuAndItsGroundTruth) {
  const std::string out = Export("euroc");
  const DatasetInfo info = ReadDatasetInfo(Dataset());
  const ImuStreams imu = ReadImuStreams(Dataset());
  const Rigid3 imu_from_rig = *info.rig.imu_from_rig;
  // data.csv: EuRoC's header and every sample.
  const std::string data = ReadFile(out + "/mav0/imu0/data.csv");
  EXPECT_EQ(data.substr(0, data.find('\n')),
            "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
            "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]");
  const auto rows = CsvRows(out + "/mav0/imu0/data.csv");
  ASSERT_EQ(rows.size(), imu.measured.size());
  EXPECT_EQ(std::stoll(rows[0][0]), std::llround(imu.measured[0].timestamp * 1e9));
  EXPECT_EQ(std::stod(rows[0][3]), imu.measured[0].angular_velocity.z());
  EXPECT_EQ(std::stod(rows[0][6]), imu.measured[0].linear_acceleration.z());
  // sensor.yaml: EuRoC's keys.
  const YAML::Node sensor = YAML::LoadFile(out + "/mav0/imu0/sensor.yaml");
  EXPECT_EQ(sensor["sensor_type"].as<std::string>(), "imu");
  EXPECT_EQ(sensor["rate_hz"].as<double>(), info.imu->rate_hz);
  EXPECT_EQ(sensor["gyroscope_noise_density"].as<double>(), info.imu->noise.gyroscope_noise_density);
  EXPECT_EQ(sensor["accelerometer_random_walk"].as<double>(), info.imu->noise.accelerometer_random_walk);
  EXPECT_LT(Distance(FromMatrix(sensor["T_BS"]["data"].as<std::vector<double>>()), Rigid3::Identity()), 1e-15);
  // Each camera's T_BS = imu_from_cam.
  const YAML::Node cam1 = YAML::LoadFile(out + "/mav0/cam1/sensor.yaml");
  EXPECT_LT(Distance(FromMatrix(cam1["T_BS"]["data"].as<std::vector<double>>()),
                     imu_from_rig * info.rig.cameras[1].cam_from_rig.Inverse()),
            1e-12);
  // Ground truth at every IMU sample: the IMU's pose, velocity and true biases at the camera-clock time.
  const auto gt = CsvRows(out + "/mav0/state_groundtruth_estimate0/data.csv");
  ASSERT_EQ(gt.size(), imu.measured.size());
  const ContinuousTrajectory trajectory(ReadTum(GroundTruthPath(Dataset())));
  for (size_t k : {size_t{0}, gt.size() / 2, gt.size() - 1}) {
    const double t = imu.measured[k].timestamp - info.imu->time_offset_s;
    EXPECT_EQ(std::stoll(gt[k][0]), std::llround(t * 1e9));
    const Rigid3 world_from_imu = trajectory.Pose(t) * imu_from_rig.Inverse();
    const Eigen::Vector3d p(std::stod(gt[k][1]), std::stod(gt[k][2]), std::stod(gt[k][3]));
    const Eigen::Quaterniond q(std::stod(gt[k][4]), std::stod(gt[k][5]), std::stod(gt[k][6]), std::stod(gt[k][7]));
    EXPECT_LT((p - world_from_imu.translation).norm(), 1e-9);
    EXPECT_LT(q.angularDistance(world_from_imu.rotation), 1e-9);
    // Velocity of the IMU by a central difference of its positions on the curve.
    const double h = 1e-4;
    const Eigen::Vector3d v_numeric = ((trajectory.Pose(t + h) * imu_from_rig.Inverse()).translation -
                                       (trajectory.Pose(t - h) * imu_from_rig.Inverse()).translation) /
                                      (2 * h);
    const Eigen::Vector3d v(std::stod(gt[k][8]), std::stod(gt[k][9]), std::stod(gt[k][10]));
    EXPECT_LT((v - v_numeric).norm(), 1e-5);
    EXPECT_EQ(std::stod(gt[k][11]), imu.bias[k].gyroscope_bias.x());
    EXPECT_EQ(std::stod(gt[k][16]), imu.bias[k].accelerometer_bias.z());
  }
  CheckRoundTrip(out, "euroc");
}

TEST_F(ExchangeImuTest, KalibrImuYamlAndCamchainFromTheTrueMount) {
  const std::string out = Export("kalibr", "--model ds");  // omni has no rovo camera model to import
  const DatasetInfo info = ReadDatasetInfo(Dataset());
  const YAML::Node imu = YAML::LoadFile(out + "/imu.yaml");
  EXPECT_EQ(imu["accelerometer_noise_density"].as<double>(), info.imu->noise.accelerometer_noise_density);
  EXPECT_EQ(imu["accelerometer_random_walk"].as<double>(), info.imu->noise.accelerometer_random_walk);
  EXPECT_EQ(imu["gyroscope_noise_density"].as<double>(), info.imu->noise.gyroscope_noise_density);
  EXPECT_EQ(imu["gyroscope_random_walk"].as<double>(), info.imu->noise.gyroscope_random_walk);
  EXPECT_EQ(imu["update_rate"].as<double>(), info.imu->rate_hz);
  EXPECT_EQ(imu["rostopic"].as<std::string>(), "/imu0");
  const YAML::Node chain = YAML::LoadFile(out + "/camchain.yaml");
  for (size_t k = 0; k < info.rig.cameras.size(); ++k) {
    const YAML::Node cam = chain["cam" + std::to_string(k)];
    std::vector<double> m;
    for (const YAML::Node& row : cam["T_cam_imu"]) {
      for (const YAML::Node& v : row) m.push_back(v.as<double>());
    }
    ASSERT_EQ(m.size(), 16u);
    EXPECT_LT(Distance(FromMatrix(m), info.rig.cameras[k].cam_from_rig * info.rig.imu_from_rig->Inverse()), 1e-12);
    EXPECT_EQ(cam["timeshift_cam_imu"].as<double>(), info.imu->time_offset_s);
  }
  CheckRoundTrip(out, "kalibr");
}

TEST_F(ExchangeImuTest, BasaltCalibrationCarriesTheImu) {
  const std::string out = Export("basalt");
  const DatasetInfo info = ReadDatasetInfo(Dataset());
  const nlohmann::json value = ReadJsonFile(out + "/calibration.json")["value0"];
  EXPECT_EQ(value["imu_update_rate"].get<double>(), info.imu->rate_hz);
  EXPECT_EQ(value["accel_noise_std"][0].get<double>(), info.imu->noise.accelerometer_noise_density);
  EXPECT_EQ(value["gyro_noise_std"][2].get<double>(), info.imu->noise.gyroscope_noise_density);
  EXPECT_EQ(value["accel_bias_std"][1].get<double>(), info.imu->noise.accelerometer_random_walk);
  EXPECT_EQ(value["gyro_bias_std"][0].get<double>(), info.imu->noise.gyroscope_random_walk);
  EXPECT_TRUE(value["cam_time_offset_ns"].is_number_integer());
  EXPECT_EQ(value["cam_time_offset_ns"].get<int64_t>(), std::llround(info.imu->time_offset_s * 1e9));
  const nlohmann::json& t = value["T_imu_cam"][2];
  const Rigid3 imu_from_cam(
      Eigen::Quaterniond(t["qw"].get<double>(), t["qx"].get<double>(), t["qy"].get<double>(), t["qz"].get<double>()),
      Eigen::Vector3d(t["px"].get<double>(), t["py"].get<double>(), t["pz"].get<double>()));
  EXPECT_LT(Distance(imu_from_cam, *info.rig.imu_from_rig * info.rig.cameras[2].cam_from_rig.Inverse()), 1e-12);
  CheckRoundTrip(out, "basalt");
}

}  // namespace
}  // namespace rovo
