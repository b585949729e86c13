#pragma once
// The IMU part of the ROS 2 bag export and import (exchange_ros2_imu.cc), apart from the cameras.

#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/exchange/mcap_writer.h"
#include "datasets/exchange/ros2_messages.h"

namespace rovo {

// What the bag carries of a dataset's IMU: one sensor_msgs/Imu per measured sample (frame "imu",
// stamps on the IMU clock), the IMU's placement, and its record as MCAP metadata (rovo_imu_* keys).
// Empty samples when the dataset has no IMU.
struct Ros2ImuExport {
  std::vector<RosImu> samples;
  Rigid3 imu_from_rig;
  McapStringMap metadata;
};
Ros2ImuExport ReadRos2ImuExport(const std::string& dataset_dir, const DatasetInfo& info);

// The bag's IMU messages and metadata, written into the dataset being imported (`info` gets its
// IMU record and placement); nothing when `samples` is empty. `what` names the bag in errors.
void ImportRos2Imu(const std::vector<RosImu>& samples, const McapStringMap& metadata, const Rigid3& imu_from_rig,
                   const std::string& what, const std::string& out_dir, DatasetInfo* info);

}  // namespace rovo
