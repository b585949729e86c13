#pragma once
// The ROS 2 messages of rovo's bags (exchange_ros2.cc), their CDR encoding and their definitions.
//
// Encoding: the ROS 2 `cdr` message encoding, XCDR1 (OMG DDS-XTypes 1.3 section 7.4.3, "plain CDR"):
// a 4-byte encapsulation header (0x00 0x01 = little-endian, then two option bytes 0x00 0x00),
// then the fields in definition order, each primitive aligned to its size counted from the end of
// the header, strings as uint32 length including a terminating NUL, sequences as uint32 count then
// the elements, fixed arrays as their elements. Serialised with eProsima Fast CDR (Debian's
// libfastcdr, `DDS_CDR` mode); big-endian input (0x00 0x00) is read too.
//
// Definitions: `ros2msg` schema text as rosbag2 stores it in MCAP (foxglove/mcap registry,
// "ros2msg"): the type's fields, then each type it uses after a line of 80 '=' and `MSG: pkg/Type`.
// The field lists are those of ros2/common_interfaces (sensor_msgs, std_msgs, geometry_msgs,
// nav_msgs), ros2/geometry2 (tf2_msgs) and ros2/rcl_interfaces (builtin_interfaces); comments are
// left out.
//
// Decoders throw std::runtime_error "<where>: <field>: <problem>" (where = file and record).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rovo {

// builtin_interfaces/Time: seconds and nanoseconds since the dataset's time 0.
struct RosTime {
  int32_t sec = 0;
  uint32_t nanosec = 0;
};
RosTime RosTimeFromNs(int64_t ns);  // ns >= 0 and < 2^31 s
int64_t RosTimeToNs(const RosTime& time);

// std_msgs/Header.
struct RosHeader {
  RosTime stamp;
  std::string frame_id;
};

// sensor_msgs/msg/Image.
struct RosImage {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string encoding;  // "mono8", "rgb8", ...
  uint8_t is_bigendian = 0;
  uint32_t step = 0;  // bytes per row
  std::vector<uint8_t> data;
};

// sensor_msgs/msg/CameraInfo (with its RegionOfInterest).
struct RosCameraInfo {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string distortion_model;  // "equidistant", "plumb_bob", "rational_polynomial"
  std::vector<double> d;
  std::array<double, 9> k{}, r{};  // row-major 3x3
  std::array<double, 12> p{};      // row-major 3x4
  uint32_t binning_x = 0, binning_y = 0;
  uint32_t roi_x_offset = 0, roi_y_offset = 0, roi_height = 0, roi_width = 0;
  bool roi_do_rectify = false;
};

// sensor_msgs/msg/Imu. Covariance[0] = -1 marks an unknown quantity (the message's rule).
struct RosImu {
  RosHeader header;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  std::array<double, 9> orientation_covariance{};
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  std::array<double, 9> angular_velocity_covariance{};
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();
  std::array<double, 9> linear_acceleration_covariance{};
};

// geometry_msgs/msg/TransformStamped: parent_from_child, header.frame_id the parent.
struct RosTransform {
  RosHeader header;
  std::string child_frame_id;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

// nav_msgs/msg/Odometry: pose of child_frame_id in header.frame_id, twist in child_frame_id.
struct RosOdometry {
  RosHeader header;
  std::string child_frame_id;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  std::array<double, 36> pose_covariance{};
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  std::array<double, 36> twist_covariance{};
};

// Type names as MCAP schemas and rosbag2 metadata spell them.
inline constexpr const char* kRosImageType = "sensor_msgs/msg/Image";
inline constexpr const char* kRosCameraInfoType = "sensor_msgs/msg/CameraInfo";
inline constexpr const char* kRosImuType = "sensor_msgs/msg/Imu";
inline constexpr const char* kRosTfMessageType = "tf2_msgs/msg/TFMessage";
inline constexpr const char* kRosOdometryType = "nav_msgs/msg/Odometry";

// The ros2msg definition of one of the types above; throws std::invalid_argument for another.
std::string Ros2MessageDefinition(const std::string& type);

// CDR bytes (with the encapsulation header).
std::string EncodeRosImage(const RosImage& message);
std::string EncodeRosCameraInfo(const RosCameraInfo& message);
std::string EncodeRosImu(const RosImu& message);
std::string EncodeRosTfMessage(const std::vector<RosTransform>& transforms);
std::string EncodeRosOdometry(const RosOdometry& message);

RosImage DecodeRosImage(std::string_view cdr, const std::string& where);
RosCameraInfo DecodeRosCameraInfo(std::string_view cdr, const std::string& where);
RosImu DecodeRosImu(std::string_view cdr, const std::string& where);
std::vector<RosTransform> DecodeRosTfMessage(std::string_view cdr, const std::string& where);
RosOdometry DecodeRosOdometry(std::string_view cdr, const std::string& where);

}  // namespace rovo
