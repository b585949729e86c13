#pragma once
// The IMU part of the ROS 2 bag export and import (exchange_ros2_imu.cc), apart from the cameras.

#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/exchange/mcap_writer.h"
#include "datasets/exchange/ros2_messages.h"

namespace rovo {

// What the bag carries of a dataset's IMU: one sensor_msgs/Imu per measured sample (frame "imu",
// stamps on the IMU clock, white-noise variances on the covariance diagonals), the noise-free
// samples and the true biases (angular_velocity = gyroscope bias, linear_acceleration =
// accelerometer bias) as Imu messages of the same stamps, the IMU's placement, and its record as
// MCAP metadata (rovo_imu_* keys). Empty when the dataset has no IMU.
struct Ros2ImuExport {
  std::vector<RosImu> samples, exact, bias;
  Rigid3 imu_from_rig;
  McapStringMap metadata;
};
Ros2ImuExport ReadRos2ImuExport(const std::string& dataset_dir, const DatasetInfo& info);

// The IMU messages of a bag being imported.
struct Ros2ImuImport {
  std::vector<RosImu> samples, exact, bias;  // /imu0, /ground_truth/imu0/exact, /ground_truth/imu0/bias
  McapStringMap metadata;                    // the "rovo" Metadata record
  Rigid3 imu_from_rig;                       // from /tf_static
};
// Writes the three streams into the dataset being imported and gives `info` its IMU record and
// mount. Returns false (nothing written) when the bag lacks the IMU or its ground truth (a rovo
// dataset holds the noise-free values and the biases too). `what` names the bag in errors.
bool ImportRos2Imu(const Ros2ImuImport& imu, const std::string& what, const std::string& out_dir, DatasetInfo* info);

inline constexpr const char* kRos2ImuExactTopic = "/ground_truth/imu0/exact";
inline constexpr const char* kRos2ImuBiasTopic = "/ground_truth/imu0/bias";

}  // namespace rovo
