// `rovo dataset export --format ros2` read by readers that no one here wrote: Foxglove's @mcap/core
// and @foxglove/rosmsg2-serialization from npm (installed by the test; it fails when npm does),
// run by ros2_bag_check.mjs; and the round trip export -> import.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "datasets/dataset.h"
#include "datasets/exchange/lens_fit.h"
#include "datasets/io.h"
#include "datasets/trajectory.h"
#include "tests/datasets/integration/imu_fixture.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

int RunShell(const std::string& command, const std::string& log) {
  const int status = std::system((command + " > " + log + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<uint8_t> Pixels(const std::string& path, int* channels) {
  cv::Mat image = cv::imread(path, cv::IMREAD_ANYCOLOR);  // OpenCV's reader, independent of rovo's
  EXPECT_FALSE(image.empty()) << path;
  if (image.empty()) return {};
  *channels = image.channels();
  if (*channels == 3) cv::cvtColor(image, image, cv::COLOR_BGR2RGB);
  return std::vector<uint8_t>(image.datastart, image.dataend);
}

class Ros2BagTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = (fs::temp_directory_path() / ("rovo_ros2_" + std::to_string(::getpid()))).string();
    fs::create_directories(root_);
    const std::string render = std::string(ROVO_BINARY) +
                               " render --preset cloudy_urban --quick --frames 0:3 --spp 1 --scale 0.5 --quiet --out " +
                               Dataset();
    ASSERT_EQ(RunShell(render, root_ + "/render.log"), 0) << ReadFile(root_ + "/render.log");
    test::AddImu(Dataset());
    const std::string export_command =
        std::string(ROVO_BINARY) + " dataset export " + Dataset() + " --format ros2 --out " + Bag();
    ASSERT_EQ(RunShell(export_command, root_ + "/export.log"), 0) << ReadFile(root_ + "/export.log");
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static std::string Dataset() { return root_ + "/dataset"; }
  static std::string Bag() { return root_ + "/bag"; }

  static std::string root_;
};
std::string Ros2BagTest::root_;

TEST_F(Ros2BagTest, FoxgloveReadersDecodeTheBagAsTheDatasetHoldsIt) {
  // The independent readers, from npm (a failed install fails the test).
  const std::string modules = root_ + "/npm";
  ASSERT_EQ(RunShell("npm install --prefix " + modules +
                         " --no-audit --no-fund --no-save @mcap/core@2 @foxglove/rosmsg@5 "
                         "@foxglove/rosmsg2-serialization@3",
                     root_ + "/npm.log"),
            0)
      << "npm install failed:\n"
      << ReadFile(root_ + "/npm.log");
  const std::string out = root_ + "/check";
  fs::create_directories(out);
  ASSERT_EQ(RunShell("node " + std::string(ROVO_SOURCE_DIR) + "/tests/datasets/integration/ros2_bag_check.mjs " +
                         modules + "/node_modules " + Bag() + "/bag_0.mcap " + out,
                     root_ + "/node.log"),
            0)
      << ReadFile(root_ + "/node.log");
  const nlohmann::json check = ReadJsonFile(out + "/check.json");
  const DatasetInfo info = ReadDatasetInfo(Dataset());
  const Trajectory gt = ReadTum(GroundTruthPath(Dataset()));
  EXPECT_EQ(check["profile"], "ros2");
  EXPECT_TRUE(check["in_order"].get<bool>());

  // Message counts per topic: by the index, by the statistics record and by a linear scan.
  const ImuStreams imu = ReadImuStreams(Dataset());
  const int samples = static_cast<int>(imu.measured.size());
  std::map<std::string, int> expected = {{"/tf_static", 1},
                                         {"/ground_truth/odometry", info.frame_count},
                                         {"/imu0", samples},
                                         {"/ground_truth/imu0/exact", samples},
                                         {"/ground_truth/imu0/bias", samples}};
  for (const RigCamera& rc : info.rig.cameras) {
    expected["/" + rc.name + "/image_raw"] = info.frame_count;
    expected["/" + rc.name + "/camera_info"] = info.frame_count;
  }
  for (const char* counts : {"indexed_counts", "statistics_counts", "stream_counts"}) {
    const auto got = check[counts].get<std::map<std::string, int>>();
    EXPECT_EQ(got, expected) << counts;
  }

  // One Image: size, encoding, stamp and every byte equal to the dataset's PNG.
  const nlohmann::json& image = check["first"]["/cam0/image_raw"];
  int channels = 0;
  const std::vector<uint8_t> pixels = Pixels(ImagePath(Dataset(), "cam0", 0), &channels);
  EXPECT_EQ(image["width"], info.rig.cameras[0].camera.width);
  EXPECT_EQ(image["height"], info.rig.cameras[0].camera.height);
  EXPECT_EQ(image["encoding"], channels == 1 ? "mono8" : "rgb8");
  EXPECT_EQ(image["step"], info.rig.cameras[0].camera.width * channels);
  EXPECT_EQ(image["header"]["frame_id"], "cam0");
  EXPECT_EQ(
      image["header"]["stamp"]["sec"].get<int64_t>() * 1000000000 + image["header"]["stamp"]["nanosec"].get<int64_t>(),
      std::llround(gt[0].timestamp * 1e9));
  const std::string data = ReadFile(image["data"]["file"].get<std::string>());
  ASSERT_EQ(data.size(), pixels.size());
  EXPECT_TRUE(std::equal(pixels.begin(), pixels.end(), reinterpret_cast<const uint8_t*>(data.data())));

  // One CameraInfo: the equidistant (kb4) fit of the lens, every digit.
  const nlohmann::json& camera_info = check["first"]["/cam0/camera_info"];
  const LensFit fit = FitExchangeLens(info.rig.cameras[0].camera, ExchangeLensModel::kKannalaBrandt4);
  EXPECT_EQ(camera_info["distortion_model"], "equidistant");
  EXPECT_EQ(camera_info["d"].get<std::vector<double>>(),
            (std::vector<double>{fit.params[4], fit.params[5], fit.params[6], fit.params[7]}));
  EXPECT_EQ(camera_info["k"].get<std::vector<double>>(),
            (std::vector<double>{fit.params[0], 0, fit.params[2], 0, fit.params[1], fit.params[3], 0, 0, 1}));
  EXPECT_EQ(camera_info["width"], info.rig.cameras[0].camera.width);

  // /tf_static places every camera (rig_from_cam), the odometry holds the ground truth.
  const nlohmann::json& transforms = check["first"]["/tf_static"]["transforms"];
  ASSERT_GE(transforms.size(), info.rig.cameras.size());
  for (size_t k = 0; k < info.rig.cameras.size(); ++k) {
    const nlohmann::json& t = transforms[k];
    EXPECT_EQ(t["header"]["frame_id"], "rig");
    EXPECT_EQ(t["child_frame_id"], info.rig.cameras[k].name);
    const Eigen::Vector3d centre = info.rig.cameras[k].cam_from_rig.Inverse().translation;
    const nlohmann::json& p = t["transform"]["translation"];
    EXPECT_LT((Eigen::Vector3d(p["x"], p["y"], p["z"]) - centre).norm(), 1e-12);
  }
  const nlohmann::json& imu_tf = transforms[info.rig.cameras.size()];
  EXPECT_EQ(imu_tf["child_frame_id"], "imu");
  const Eigen::Vector3d imu_centre = info.rig.imu_from_rig->Inverse().translation;
  const nlohmann::json& q = imu_tf["transform"]["translation"];
  EXPECT_LT((Eigen::Vector3d(q["x"], q["y"], q["z"]) - imu_centre).norm(), 1e-12);

  // One Imu: the first measured sample, every digit, on the IMU clock.
  const nlohmann::json& first_imu = check["first"]["/imu0"];
  EXPECT_EQ(first_imu["header"]["frame_id"], "imu");
  EXPECT_EQ(first_imu["header"]["stamp"]["sec"].get<int64_t>() * 1000000000 +
                first_imu["header"]["stamp"]["nanosec"].get<int64_t>(),
            std::llround(imu.measured[0].timestamp * 1e9));
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(first_imu["angular_velocity"][axes[i]].get<double>(), imu.measured[0].angular_velocity[i]);
    EXPECT_EQ(first_imu["linear_acceleration"][axes[i]].get<double>(), imu.measured[0].linear_acceleration[i]);
  }
  EXPECT_EQ(first_imu["orientation_covariance"][0].get<double>(), -1.0);
  const double density = info.imu->noise.gyroscope_noise_density;
  EXPECT_DOUBLE_EQ(first_imu["angular_velocity_covariance"][0].get<double>(), density * density * info.imu->rate_hz);
  const nlohmann::json& bias = check["first"]["/ground_truth/imu0/bias"];
  EXPECT_EQ(bias["angular_velocity"]["x"].get<double>(), imu.bias[0].gyroscope_bias.x());

  const nlohmann::json& pose = check["first"]["/ground_truth/odometry"]["pose"]["pose"];
  EXPECT_EQ(pose["position"]["x"].get<double>(), gt[0].world_from_rig.translation.x());
  EXPECT_EQ(pose["orientation"]["w"].get<double>(), gt[0].world_from_rig.rotation.w());
}

TEST_F(Ros2BagTest, ImportGivesTheDatasetBack) {
  const std::string imported = root_ + "/imported";
  ASSERT_EQ(RunShell(std::string(ROVO_BINARY) + " dataset import " + Bag() + " --format ros2 --out " + imported,
                     root_ + "/import.log"),
            0)
      << ReadFile(root_ + "/import.log");
  EXPECT_TRUE(ValidateDataset(imported).empty()) << ReadFile(root_ + "/import.log");
  const DatasetInfo a = ReadDatasetInfo(Dataset()), b = ReadDatasetInfo(imported);
  ASSERT_EQ(a.frame_count, b.frame_count);
  ASSERT_EQ(a.rig.NumCameras(), b.rig.NumCameras());
  EXPECT_EQ(a.frame_rate, b.frame_rate);
  const Trajectory gt_a = ReadTum(GroundTruthPath(Dataset())), gt_b = ReadTum(GroundTruthPath(imported));
  ASSERT_EQ(gt_a.size(), gt_b.size());
  for (size_t i = 0; i < gt_a.size(); ++i) {
    EXPECT_NEAR(gt_a[i].timestamp, gt_b[i].timestamp, 1e-9);
    EXPECT_LT((gt_a[i].world_from_rig.translation - gt_b[i].world_from_rig.translation).norm(), 1e-12);
    EXPECT_LT(gt_a[i].world_from_rig.rotation.angularDistance(gt_b[i].world_from_rig.rotation), 1e-12);
  }
  // The IMU: record, mount and the three streams (stamps to the nanosecond the bag carries).
  ASSERT_TRUE(b.imu.has_value());
  EXPECT_EQ(b.imu->noise, a.imu->noise);
  EXPECT_EQ(b.imu->rate_hz, a.imu->rate_hz);
  EXPECT_EQ(b.imu->seed, a.imu->seed);
  EXPECT_EQ(b.imu->time_offset_s, a.imu->time_offset_s);
  EXPECT_EQ(b.imu->noise_profile, a.imu->noise_profile);
  EXPECT_LT((a.rig.imu_from_rig->translation - b.rig.imu_from_rig->translation).norm(), 1e-15);
  EXPECT_LT(a.rig.imu_from_rig->rotation.angularDistance(b.rig.imu_from_rig->rotation), 1e-15);
  const ImuStreams imu_a = ReadImuStreams(Dataset()), imu_b = ReadImuStreams(imported);
  ASSERT_EQ(imu_a.measured.size(), imu_b.measured.size());
  for (size_t k = 0; k < imu_a.measured.size(); ++k) {
    EXPECT_NEAR(imu_a.measured[k].timestamp, imu_b.measured[k].timestamp, 0.5e-9);
    EXPECT_EQ(imu_a.measured[k].angular_velocity, imu_b.measured[k].angular_velocity);
    EXPECT_EQ(imu_a.measured[k].linear_acceleration, imu_b.measured[k].linear_acceleration);
    EXPECT_EQ(imu_a.exact[k].linear_acceleration, imu_b.exact[k].linear_acceleration);
    EXPECT_EQ(imu_a.bias[k].accelerometer_bias, imu_b.bias[k].accelerometer_bias);
  }
  for (int k = 0; k < a.rig.NumCameras(); ++k) {
    const RigCamera &ca = a.rig.cameras[static_cast<size_t>(k)], &cb = b.rig.cameras[static_cast<size_t>(k)];
    EXPECT_EQ(cb.camera.model, CameraModelId::kEquidistant);
    EXPECT_EQ(cb.camera.max_fov_deg, ca.camera.max_fov_deg);
    EXPECT_EQ(cb.camera.params, FitExchangeLens(ca.camera, ExchangeLensModel::kKannalaBrandt4).params);
    EXPECT_LT((ca.cam_from_rig.translation - cb.cam_from_rig.translation).norm(), 1e-12);
    EXPECT_LT(ca.cam_from_rig.rotation.angularDistance(cb.cam_from_rig.rotation), 1e-12);
    for (int f = 0; f < a.frame_count; ++f) {
      int channels_a = 0, channels_b = 0;
      EXPECT_EQ(Pixels(ImagePath(Dataset(), ca.name, f), &channels_a),
                Pixels(ImagePath(imported, cb.name, f), &channels_b));
      EXPECT_EQ(channels_a, channels_b);
    }
  }
}

}  // namespace
}  // namespace rovo
