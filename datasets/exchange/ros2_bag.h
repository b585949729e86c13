#pragma once
// rovo datasets as ROS 2 bags and back (docs/exchange.md, "ROS 2 bags").
//
//   <out>/metadata.yaml     rosbag2_bagfile_information, version 8, storage_identifier mcap
//   <out>/<name>_0.mcap     profile ros2, schemas ros2msg, messages cdr (mcap_writer.h, ros2_messages.h)
//
// Topics (frame ids in brackets):
//   /camK/image_raw        sensor_msgs/msg/Image, mono8 or rgb8 as the dataset's images  [camK]
//   /camK/camera_info      sensor_msgs/msg/CameraInfo, distortion_model "equidistant": the
//                          Kannala-Brandt fit of the lens (lens_fit.h kb4; d = k1..k4 on the angle
//                          from the optical axis, valid past 180 degrees), K and P from fx fy cx cy,
//                          R identity; one per image, same stamp                          [camK]
//   /imu0                  sensor_msgs/msg/Imu, angular rate and specific force in the IMU frame,
//                          orientation unknown (covariance[0] = -1), when the dataset has an IMU [imu]
//   /tf_static             tf2_msgs/msg/TFMessage, one message at the first stamp: rig -> camK
//                          (rig_from_cam) and rig -> imu (rig_from_imu), transient-local QoS
//   /ground_truth/odometry nav_msgs/msg/Odometry per ground-truth line: world_from_rig, twist of the
//                          rig in the rig frame by central differences                [world -> rig]
// Frames: world and rig REP-103 (x forward, y left, z up; gravity -z), camK the OpenCV optical
// frame (x right, y down, z along the axis), imu the IMU frame. Every stamp is the dataset's time in
// nanoseconds (log_time = publish_time = header.stamp): images at t_i + trigger offset of camera K,
// ground truth at t_i, IMU samples at their own stamps.
//
// Import reads such a bag (any profile-ros2 MCAP whose Image topics have CameraInfo siblings with
// an equidistant model, and tf_static placing the camera frames): frame k is the k-th image of
// every camera, its time the k-th ground-truth stamp (else camera 0's stamp).

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/exchange/lens_fit.h"

namespace rovo {

struct Ros2ExportOptions {
  std::string out_dir;
  double max_fit_error_px = 5.0;  // refuse when a camera's equidistant fit is worse
  // The extrinsics /tf_static carries, one cam_from_rig per camera of the rig (empty: the dataset's own);
  // a suite run's given calibration (docs/systems.md). Throws when the count is not the rig's.
  std::vector<Rigid3> cam_from_rig;
};

struct Ros2ExportReport {
  std::string bag_path;                      // the .mcap file
  std::vector<LensFit> fits;                 // per camera (kb4)
  std::map<std::string, uint64_t> messages;  // per topic
  int frames = 0;
  bool ground_truth = false;
  bool imu = false;
};

// Throws std::runtime_error naming the dataset and camera when a fit is too poor, or a file that
// cannot be read.
Ros2ExportReport ExportRos2Bag(const std::string& dataset_dir, const Ros2ExportOptions& options);

struct Ros2ImportReport {
  int frames = 0;
  int cameras = 0;
  bool ground_truth = false;
  bool imu = false;
  std::vector<ValidationIssue> issues;  // ValidateDataset of the result
};

// `bag` is a rosbag2 folder (its .mcap named by metadata.yaml's relative_file_paths, else the only
// .mcap in it) or an .mcap file. Throws std::runtime_error naming the file, the record and field.
Ros2ImportReport ImportRos2Bag(const std::string& bag, const std::string& out_dir);

// Topic names.
std::string Ros2ImageTopic(const std::string& camera);       // /camK/image_raw
std::string Ros2CameraInfoTopic(const std::string& camera);  // /camK/camera_info
inline constexpr const char* kRos2ImuTopic = "/imu0";
inline constexpr const char* kRos2TfStaticTopic = "/tf_static";
inline constexpr const char* kRos2GroundTruthTopic = "/ground_truth/odometry";

}  // namespace rovo
