// The IMU in ROS 2 bags (ros2_bag_internal.h).
#include "datasets/exchange/ros2_bag_internal.h"

namespace rovo {

Ros2ImuExport ReadRos2ImuExport(const std::string& /*dataset_dir*/, const DatasetInfo& /*info*/) { return {}; }

void ImportRos2Imu(const std::vector<RosImu>& /*samples*/, const McapStringMap& /*metadata*/,
                   const Rigid3& /*imu_from_rig*/, const std::string& /*what*/, const std::string& /*out_dir*/,
                   DatasetInfo* /*info*/) {}

}  // namespace rovo
