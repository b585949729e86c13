// The IMU files of a dataset: csv round trips and errors, the dataset.json record, the rig's mount,
// and `rovo dataset validate` / ValidateDataset on a fixture dataset given an IMU.
#include "datasets/imu.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "datasets/dataset.h"
#include "datasets/imu_model.h"
#include "datasets/io.h"
#include "datasets/json_check.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rovo_imu_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string Issues(const std::vector<ValidationIssue>& issues) {
  std::string out;
  for (const ValidationIssue& i : issues) out += i.file + ": " + i.field + ": " + i.message + "\n";
  return out;
}

TEST(ImuFiles, StreamsRoundTripBitExact) {
  const std::string dir = TempDir("round_trip");
  ImuStreams s;
  for (int k = 0; k < 20; ++k) {
    ImuSample m;
    m.timestamp = 1234.5 + k / 200.0;
    m.angular_velocity = Eigen::Vector3d(0.1 / 3.0, -k * 1e-7, M_PI);
    m.linear_acceleration = Eigen::Vector3d(1.0 / 7.0, 9.81, -2e-300);
    s.measured.push_back(m);
    m.angular_velocity *= 0.5;
    s.exact.push_back(m);
    ImuBiasSample b;
    b.timestamp = m.timestamp;
    b.gyroscope_bias = Eigen::Vector3d(1e-3, 2e-3 / 3.0, -k * 1e-9);
    s.bias.push_back(b);
  }
  WriteImuStreams(dir, s);
  const ImuStreams r = ReadImuStreams(dir);
  ASSERT_EQ(r.measured.size(), 20u);
  for (size_t k = 0; k < 20; ++k) {
    EXPECT_EQ(r.measured[k].timestamp, s.measured[k].timestamp);
    EXPECT_EQ(r.measured[k].angular_velocity, s.measured[k].angular_velocity);
    EXPECT_EQ(r.exact[k].linear_acceleration, s.exact[k].linear_acceleration);
    EXPECT_EQ(r.bias[k].gyroscope_bias, s.bias[k].gyroscope_bias);
  }
  // Streams of different lengths are an error naming the file.
  s.bias.pop_back();
  WriteImuBiasCsv(ImuBiasPath(dir), s.bias);
  try {
    ReadImuStreams(dir);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(ImuBiasPath(dir)));
    EXPECT_THAT(e.what(), HasSubstr("19 samples"));
  }
}

TEST(ImuFiles, MalformedLinesNameFileLineAndColumn) {
  const std::string text = std::string(kImuCsvHeader) +
                           "\n0,1,2,3,4,5,6\n0.005,1,2,nan,4,5,6\n0,1,2,3,4,5,6\n0.01,1,2,3\n0.02,1,2,3,4,5,x\n";
  std::vector<ValidationIssue> issues;
  const std::vector<ImuSample> samples = ParseImuCsv(text, "imu/data.csv", &issues);
  EXPECT_THAT(Issues(issues), HasSubstr("imu/data.csv: line 3: column w_z: `nan` is not a finite number"));
  EXPECT_THAT(Issues(issues), HasSubstr("imu/data.csv: line 4: column timestamp: 0 is not after the previous stamp 0"));
  EXPECT_THAT(Issues(issues), HasSubstr("imu/data.csv: line 5: expected 7 comma-separated fields, found 4"));
  EXPECT_THAT(Issues(issues), HasSubstr("imu/data.csv: line 6: column a_z: `x`"));
  std::vector<ValidationIssue> header;
  ParseImuBiasCsv(text, "imu/bias.csv", &header);
  EXPECT_THAT(Issues(header),
              HasSubstr("imu/bias.csv: line 1: expected the header `" + std::string(kImuBiasCsvHeader)));
}

TEST(ImuFiles, RecordAndMountRoundTripThroughDatasetJson) {
  const std::string dir = TempDir("record");
  fs::copy(fs::path(ROVO_TEST_DATA_DIR) / "datasets" / "valid" / "dataset.json", dir + "/dataset.json");
  DatasetInfo info = ReadDatasetInfo(dir);
  EXPECT_FALSE(info.imu);
  EXPECT_FALSE(info.rig.imu_from_rig);
  ImuRecord r;
  r.rate_hz = 400.0;
  r.noise_profile = "custom";
  r.noise.gyroscope_noise_density = 1.5e-4;
  r.noise.accelerometer_random_walk = 3e-3;
  r.noise.gyroscope_initial_bias = Eigen::Vector3d(1e-3, -2e-3, 3e-3);
  r.seed = 99;
  r.time_offset_s = -0.0042;
  r.sample_count = 81;
  r.first_timestamp = -0.0042;
  info.imu = r;
  // An IMU needs its mount.
  EXPECT_THROW(WriteDatasetInfo(dir, info), std::invalid_argument);
  info.rig.imu_from_rig = PresetImuFromRig();
  WriteDatasetInfo(dir, info);
  const DatasetInfo back = ReadDatasetInfo(dir);
  ASSERT_TRUE(back.imu);
  EXPECT_EQ(*back.imu, r);
  ASSERT_TRUE(back.rig.imu_from_rig);
  EXPECT_EQ(back.rig.imu_from_rig->translation, PresetImuFromRig().translation);
  // The mount is neither the identity nor at camera 0.
  EXPECT_GT(PresetImuFromRig().translation.norm(), 0.01);
  EXPECT_GT(RotationAngleDeg(PresetImuFromRig().rotation), 1.0);
  EXPECT_GT((PresetImuFromRig().Inverse().translation - CameraPositionInRig(back.rig.cameras[0].cam_from_rig)).norm(),
            0.01);
  // Bad fields are named.
  nlohmann::json root = ReadJsonFile(dir + "/dataset.json");
  root["imu"]["rate_hz"] = -200.0;
  root["imu"]["noise"]["gyroscope_noise_density"] = nullptr;
  WriteJsonFileAtomic(dir + "/dataset.json", root);
  try {
    ReadDatasetInfo(dir);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("/imu/rate_hz: value -200 out of range"));
    EXPECT_THAT(e.what(), HasSubstr("/imu/noise/gyroscope_noise_density: null"));
  }
}

// The valid fixture given an IMU made from its own ground truth.
std::string FixtureWithImu(const std::string& name, const ImuSettings& settings) {
  const std::string dir = TempDir(name);
  fs::remove_all(dir);
  fs::copy(fs::path(ROVO_TEST_DATA_DIR) / "datasets" / "valid", dir, fs::copy_options::recursive);
  DatasetInfo info = ReadDatasetInfo(dir);
  info.rig.imu_from_rig = PresetImuFromRig();
  const ContinuousTrajectory motion(ReadTum(GroundTruthPath(dir)));
  ImuRecord record;
  WriteImuStreams(dir, SimulateImu(motion, *info.rig.imu_from_rig, settings, 4, &record));
  info.imu = record;
  WriteDatasetInfo(dir, info);
  return dir;
}

void ReplaceLine(const std::string& path, int line_number, const std::string& line) {
  std::ifstream in(path);
  std::string text, l;
  for (int n = 1; std::getline(in, l); ++n) text += (n == line_number ? line : l) + "\n";
  WriteFileAtomic(path, text);
}

TEST(ImuFiles, ValidatorAcceptsARenderedImuAndNamesEachFault) {
  ImuSettings noisy;
  ImuSettings exact;
  exact.noise_profile = "none";
  exact.time_offset_s = 0.003;
  for (const ImuSettings& settings : {noisy, exact}) {
    const std::string dir = FixtureWithImu("valid_" + settings.noise_profile, settings);
    EXPECT_EQ(Issues(ValidateDataset(dir)), "");
  }
  {  // An exact value that is not the ground truth's motion.
    const std::string dir = FixtureWithImu("wrong_exact", noisy);
    ReplaceLine(ImuExactPath(dir), 2, "0,0,0,0,0,0,9.81");
    EXPECT_THAT(Issues(ValidateDataset(dir)), HasSubstr(ImuExactPath(dir) + ": line 2: differs from the ground truth"));
  }
  {  // A missing sample, a NaN, a stamp off the rate.
    const std::string dir = FixtureWithImu("faults", exact);
    const ImuStreams s = ReadImuStreams(dir);
    std::vector<ImuSample> shorter(s.measured.begin(), s.measured.end() - 1);
    WriteImuCsv(ImuDataPath(dir), shorter);
    ReplaceLine(ImuBiasPath(dir), 3, "0.008,0,nan,0,0,0,0");
    ReplaceLine(ImuExactPath(dir), 4, "0.0131,0,0,0,0,0,9.81");
    const std::string issues = Issues(ValidateDataset(dir));
    EXPECT_THAT(issues, HasSubstr(ImuDataPath(dir) + ": lines: 40 samples but dataset.json /imu/sample_count is 41"));
    EXPECT_THAT(issues, HasSubstr(ImuBiasPath(dir) + ": line 3: column bw_y: `nan` is not a finite number"));
    EXPECT_THAT(issues, HasSubstr(ImuExactPath(dir) + ": line 4: column timestamp: 0.0131, expected 0.013"));
  }
  {  // A missing stream.
    const std::string dir = FixtureWithImu("missing", noisy);
    fs::remove(ImuBiasPath(dir));
    EXPECT_THAT(Issues(ValidateDataset(dir)), HasSubstr(ImuBiasPath(dir) + ": file: missing IMU stream"));
  }
}

}  // namespace
}  // namespace rovo
