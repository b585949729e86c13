// Export of rovo datasets as ROS 2 bags (ros2_bag.h).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <tuple>

#include "datasets/exchange/exchange.h"
#include "datasets/exchange/mcap_writer.h"
#include "datasets/exchange/ros2_bag.h"
#include "datasets/exchange/ros2_bag_internal.h"
#include "datasets/exchange/ros2_messages.h"
#include "datasets/image_file.h"
#include "datasets/io.h"
#include "rovo/version.h"

namespace rovo {
namespace fs = std::filesystem;

std::string Ros2ImageTopic(const std::string& camera) { return "/" + camera + "/image_raw"; }
std::string Ros2CameraInfoTopic(const std::string& camera) { return "/" + camera + "/camera_info"; }

namespace {

// QoS of a recorded topic as rosbag2 (metadata version 8) writes it: a YAML list with the
// rmw enum values (history 1 keep_last, reliability 1 reliable, durability 1 transient_local /
// 2 volatile, liveliness 1 automatic) and durations 0 (unspecified, the default).
std::string QosProfiles(bool transient_local) {
  const std::string zero = "\n    sec: 0\n    nsec: 0";
  return std::string("- history: 1\n  depth: ") + (transient_local ? "1" : "10") +
         "\n  reliability: 1\n  durability: " + (transient_local ? "1" : "2") + "\n  deadline:" + zero +
         "\n  lifespan:" + zero + "\n  liveliness: 1\n  liveliness_lease_duration:" + zero +
         "\n  avoid_ros_namespace_conventions: false";
}

// One topic of the bag: its channel and what rosbag2's metadata.yaml says about it.
struct Topic {
  std::string name, type;
  bool transient_local = false;
  uint16_t channel = 0;
  uint64_t count = 0;
};

class BagWriter {
 public:
  explicit BagWriter(const std::string& path) : mcap_(path, "ros2", std::string("rovo ") + ROVO_VERSION) {}
  size_t AddTopic(const std::string& name, const std::string& type, bool transient_local = false) {
    auto schema = schemas_.find(type);
    if (schema == schemas_.end()) {
      schema = schemas_.emplace(type, mcap_.AddSchema(type, "ros2msg", Ros2MessageDefinition(type))).first;
    }
    Topic topic{name, type, transient_local, 0, 0};
    topic.channel =
        mcap_.AddChannel(schema->second, name, "cdr", {{"offered_qos_profiles", QosProfiles(transient_local)}});
    topics_.push_back(topic);
    return topics_.size() - 1;
  }
  void AddMetadata(const McapStringMap& map) { mcap_.AddMetadata("rovo", map); }
  void Write(size_t topic, int64_t stamp_ns, const std::string& cdr) {
    Topic& t = topics_[topic];
    mcap_.WriteMessage(t.channel, static_cast<uint32_t>(t.count), static_cast<uint64_t>(stamp_ns),
                       static_cast<uint64_t>(stamp_ns), cdr);
    ++t.count;
    if (first_ns_ < 0 || stamp_ns < first_ns_) first_ns_ = stamp_ns;
    last_ns_ = std::max(last_ns_, stamp_ns);
  }
  void Close() { mcap_.Close(); }
  const std::vector<Topic>& topics() const { return topics_; }
  int64_t first_ns() const { return std::max<int64_t>(first_ns_, 0); }
  int64_t duration_ns() const { return first_ns_ < 0 ? 0 : last_ns_ - first_ns_; }
  uint64_t count() const { return mcap_.MessageCount(); }

 private:
  McapWriter mcap_;
  std::map<std::string, uint16_t> schemas_;
  std::vector<Topic> topics_;
  int64_t first_ns_ = -1, last_ns_ = 0;
};

std::string MetadataYaml(const BagWriter& bag, const std::string& file, const McapStringMap& custom) {
  YAML::Emitter out;
  auto nanoseconds = [&](const char* key, const char* inner, int64_t ns) {
    out << YAML::Key << key << YAML::Value << YAML::BeginMap << YAML::Key << inner << YAML::Value << ns << YAML::EndMap;
  };
  out << YAML::BeginMap << YAML::Key << "rosbag2_bagfile_information" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "version" << YAML::Value << 8 << YAML::Key << "storage_identifier" << YAML::Value << "mcap";
  nanoseconds("duration", "nanoseconds", bag.duration_ns());
  nanoseconds("starting_time", "nanoseconds_since_epoch", bag.first_ns());
  out << YAML::Key << "message_count" << YAML::Value << bag.count();
  out << YAML::Key << "topics_with_message_count" << YAML::Value << YAML::BeginSeq;
  for (const Topic& t : bag.topics()) {
    out << YAML::BeginMap << YAML::Key << "topic_metadata" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << t.name << YAML::Key << "type" << YAML::Value << t.type;
    out << YAML::Key << "serialization_format" << YAML::Value << "cdr";
    out << YAML::Key << "offered_qos_profiles" << YAML::Value << YAML::DoubleQuoted << QosProfiles(t.transient_local);
    out << YAML::Key << "type_description_hash" << YAML::Value << YAML::DoubleQuoted << "";
    out << YAML::EndMap << YAML::Key << "message_count" << YAML::Value << t.count << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "compression_format" << YAML::Value << YAML::DoubleQuoted << "";
  out << YAML::Key << "compression_mode" << YAML::Value << YAML::DoubleQuoted << "";
  out << YAML::Key << "relative_file_paths" << YAML::Value << YAML::BeginSeq << file << YAML::EndSeq;
  out << YAML::Key << "files" << YAML::Value << YAML::BeginSeq << YAML::BeginMap;
  out << YAML::Key << "path" << YAML::Value << file;
  nanoseconds("starting_time", "nanoseconds_since_epoch", bag.first_ns());
  nanoseconds("duration", "nanoseconds", bag.duration_ns());
  out << YAML::Key << "message_count" << YAML::Value << bag.count() << YAML::EndMap << YAML::EndSeq;
  out << YAML::Key << "custom_data" << YAML::Value << YAML::BeginMap;
  for (const auto& [key, value] : custom) out << YAML::Key << key << YAML::Value << YAML::DoubleQuoted << value;
  out << YAML::EndMap << YAML::Key << "ros_distro" << YAML::Value << "jazzy";
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

// An 8-bit image as mono8 (1 channel) or rgb8 (3; a 4th channel is dropped).
RosImage ReadRosImage(const std::string& path) {
  const ImageHeader header = ReadImageHeader(path);
  if (header.channels != 1 && header.channels != 3 && header.channels != 4) {
    throw std::runtime_error(path + ": " + std::to_string(header.channels) + " channels (mono8 or rgb8 wanted)");
  }
  Image8 pixels = ReadPng8(path, {header.channels == 1 ? 1 : 3, true});
  RosImage image;
  image.width = static_cast<uint32_t>(pixels.width);
  image.height = static_cast<uint32_t>(pixels.height);
  image.encoding = pixels.channels == 1 ? "mono8" : "rgb8";
  image.step = image.width * static_cast<uint32_t>(pixels.channels);
  image.data = std::move(pixels.pixels);
  return image;
}

RosCameraInfo CameraInfo(const LensFit& fit, const Camera& camera) {
  RosCameraInfo info;
  info.width = static_cast<uint32_t>(camera.width);
  info.height = static_cast<uint32_t>(camera.height);
  info.distortion_model = "equidistant";
  const std::vector<double>& p = fit.params;  // fx fy cx cy k1..k4
  info.d = {p[4], p[5], p[6], p[7]};
  info.k = {p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1};
  info.r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.p = {p[0], 0, p[2], 0, 0, p[1], p[3], 0, 0, 0, 1, 0};
  return info;
}

RosTransform Transform(const std::string& parent, const std::string& child, const Rigid3& parent_from_child,
                       int64_t stamp_ns) {
  RosTransform t;
  t.header.stamp = RosTimeFromNs(stamp_ns);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.translation = parent_from_child.translation;
  t.rotation = parent_from_child.rotation;
  return t;
}

// world_from_rig at line i with the rig's velocity (world frame, turned into the rig frame) and
// angular rate (rig frame) by central differences, one-sided at the ends.
RosOdometry Odometry(const Trajectory& gt, size_t i) {
  RosOdometry odom;
  odom.header.stamp = RosTimeFromNs(SecondsToNs(gt[i].timestamp));
  odom.header.frame_id = "world";
  odom.child_frame_id = "rig";
  const Rigid3& pose = gt[i].world_from_rig;
  odom.position = pose.translation;
  odom.orientation = pose.rotation;
  const size_t a = i > 0 ? i - 1 : i, b = i + 1 < gt.size() ? i + 1 : i;
  const double dt = gt[b].timestamp - gt[a].timestamp;
  if (b != a && dt > 0) {
    const Rigid3& pa = gt[a].world_from_rig;
    const Rigid3& pb = gt[b].world_from_rig;
    odom.linear_velocity = pose.rotation.conjugate() * ((pb.translation - pa.translation) / dt);
    const Eigen::AngleAxisd turn(pa.rotation.conjugate() * pb.rotation);  // rig_a_from_rig_b
    odom.angular_velocity = turn.axis() * turn.angle() / dt;
  }
  return odom;
}

// Per camera: frame i's image at t_i + the camera's trigger offset (dataset.json timing).
int64_t ImageStampNs(const DatasetInfo& info, const Trajectory& gt, int frame, size_t camera) {
  double t = gt.empty() ? frame / info.frame_rate : gt[static_cast<size_t>(frame)].timestamp;
  if (info.timing && camera < info.timing->trigger_offset_ms.size()) t += info.timing->trigger_offset_ms[camera] / 1000;
  return SecondsToNs(t);
}

McapStringMap CustomData(const DatasetInfo& info, const std::string& dataset_dir, const std::vector<LensFit>& fits) {
  McapStringMap custom = {{"rovo_source", dataset_dir},
                          {"rovo_generator", info.generator + " " + info.generator_version},
                          {"rovo_seed", std::to_string(info.seed)},
                          {"rovo_preset", info.preset},
                          {"rovo_frame_rate_hz", YamlNumber(info.frame_rate)}};
  for (size_t k = 0; k < fits.size(); ++k) {
    const std::string& name = info.rig.cameras[k].name;
    custom.emplace_back("rovo_" + name + "_max_fov_deg", YamlNumber(info.rig.cameras[k].camera.max_fov_deg));
    custom.emplace_back("rovo_" + name + "_fit_max_error_px", YamlNumber(fits[k].max_error_px));
  }
  return custom;
}

std::vector<LensFit> FitCameras(const std::string& dataset_dir, const DatasetInfo& info, double bound) {
  std::vector<LensFit> fits;
  for (const RigCamera& rc : info.rig.cameras) {
    fits.push_back(FitExchangeLens(rc.camera, ExchangeLensModel::kKannalaBrandt4));
    if (!(fits.back().max_error_px <= bound)) {
      throw std::runtime_error(dataset_dir + ": " + rc.name + ": the equidistant (kb4) fit of the lens errs by up to " +
                               YamlNumber(fits.back().max_error_px) + " px, more than the bound of " +
                               YamlNumber(bound) + " px (--max-fit-error)");
    }
  }
  return fits;
}

// Every message after /tf_static in the order of its stamp (ties: ground truth, IMU, cameras in rig order).
struct Event {
  int64_t stamp_ns = 0;
  int kind = 0;  // 0 ground truth, 1 IMU, 2 camera
  size_t index = 0, camera = 0;
  bool operator<(const Event& o) const {
    return std::tie(stamp_ns, kind, index, camera) < std::tie(o.stamp_ns, o.kind, o.index, o.camera);
  }
};

struct TopicIds {
  std::vector<std::pair<size_t, size_t>> cameras;  // image, camera_info
  size_t tf = 0, gt = 0, imu = 0, imu_exact = 0, imu_bias = 0;
};

void WriteMessages(const std::string& dataset_dir, const DatasetInfo& info, const Trajectory& gt,
                   const std::vector<LensFit>& fits, const Ros2ImuExport& imu, const TopicIds& topics, BagWriter* bag) {
  std::vector<Event> events;
  for (size_t i = 0; i < gt.size(); ++i) events.push_back({SecondsToNs(gt[i].timestamp), 0, i, 0});
  for (size_t i = 0; i < imu.samples.size(); ++i) {
    events.push_back({RosTimeToNs(imu.samples[i].header.stamp), 1, i, 0});
  }
  for (int f = 0; f < info.frame_count; ++f) {
    for (size_t k = 0; k < info.rig.cameras.size(); ++k) {
      events.push_back({ImageStampNs(info, gt, f, k), 2, static_cast<size_t>(f), k});
    }
  }
  std::stable_sort(events.begin(), events.end());
  for (const Event& e : events) {
    if (e.kind == 0) {
      bag->Write(topics.gt, e.stamp_ns, EncodeRosOdometry(Odometry(gt, e.index)));
    } else if (e.kind == 1) {
      bag->Write(topics.imu, e.stamp_ns, EncodeRosImu(imu.samples[e.index]));
      bag->Write(topics.imu_exact, e.stamp_ns, EncodeRosImu(imu.exact[e.index]));
      bag->Write(topics.imu_bias, e.stamp_ns, EncodeRosImu(imu.bias[e.index]));
    } else {
      const RigCamera& rc = info.rig.cameras[e.camera];
      RosImage image = ReadRosImage(ImagePath(dataset_dir, rc.name, static_cast<int>(e.index)));
      image.header = {RosTimeFromNs(e.stamp_ns), rc.name};
      RosCameraInfo camera_info = CameraInfo(fits[e.camera], rc.camera);
      camera_info.header = image.header;
      bag->Write(topics.cameras[e.camera].first, e.stamp_ns, EncodeRosImage(image));
      bag->Write(topics.cameras[e.camera].second, e.stamp_ns, EncodeRosCameraInfo(camera_info));
    }
  }
}

// /tf_static: rig -> camK (rig_from_cam of `extrinsics`; a kb4 fit of a lens whose ocam affine turns the
// image axes is in a camera frame turned by roll_deg about the axis) and rig -> imu.
std::vector<RosTransform> StaticTransforms(const DatasetInfo& info, const std::vector<Rigid3>& extrinsics,
                                           const std::vector<LensFit>& fits, const Ros2ImuExport& imu,
                                           int64_t stamp_ns) {
  std::vector<RosTransform> tf;
  for (size_t k = 0; k < info.rig.cameras.size(); ++k) {
    const Rigid3 exported_from_cam(
        Eigen::Quaterniond(Eigen::AngleAxisd(fits[k].roll_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ())),
        Eigen::Vector3d::Zero());
    const Rigid3 cam_from_rig = exported_from_cam * extrinsics[k];
    tf.push_back(Transform("rig", info.rig.cameras[k].name, cam_from_rig.Inverse(), stamp_ns));
  }
  if (!imu.samples.empty()) tf.push_back(Transform("rig", "imu", imu.imu_from_rig.Inverse(), stamp_ns));
  return tf;
}

}  // namespace

Ros2ExportReport ExportRos2Bag(const std::string& dataset_dir, const Ros2ExportOptions& options) {
  const DatasetInfo info = ReadDatasetInfo(dataset_dir);
  Ros2ExportReport report;
  if (!options.cam_from_rig.empty() && options.cam_from_rig.size() != info.rig.cameras.size()) {
    throw std::runtime_error(dataset_dir + ": " + std::to_string(options.cam_from_rig.size()) +
                             " extrinsics given for /tf_static, the rig has " +
                             std::to_string(info.rig.cameras.size()) + " cameras");
  }
  const std::vector<Rigid3> extrinsics = options.cam_from_rig.empty() ? info.rig.Extrinsics() : options.cam_from_rig;
  report.fits = FitCameras(dataset_dir, info, options.max_fit_error_px);
  Trajectory gt;
  if (info.has_ground_truth && fs::exists(GroundTruthPath(dataset_dir))) gt = ReadTum(GroundTruthPath(dataset_dir));
  EnsureWritableDir(options.out_dir);
  const std::string name = fs::absolute(options.out_dir).lexically_normal().filename().string();
  const std::string file = (name.empty() ? std::string("rovo") : name) + "_0.mcap";
  report.bag_path = (fs::path(options.out_dir) / file).string();
  const Ros2ImuExport imu = ReadRos2ImuExport(dataset_dir, info);

  BagWriter bag(report.bag_path);
  TopicIds topics;
  for (const RigCamera& rc : info.rig.cameras) {
    topics.cameras.emplace_back(bag.AddTopic(Ros2ImageTopic(rc.name), kRosImageType),
                                bag.AddTopic(Ros2CameraInfoTopic(rc.name), kRosCameraInfoType));
  }
  topics.tf = bag.AddTopic(kRos2TfStaticTopic, kRosTfMessageType, true);
  if (!gt.empty()) topics.gt = bag.AddTopic(kRos2GroundTruthTopic, kRosOdometryType);
  if (!imu.samples.empty()) {
    topics.imu = bag.AddTopic(kRos2ImuTopic, kRosImuType);
    topics.imu_exact = bag.AddTopic(kRos2ImuExactTopic, kRosImuType);
    topics.imu_bias = bag.AddTopic(kRos2ImuBiasTopic, kRosImuType);
  }
  McapStringMap custom = CustomData(info, dataset_dir, report.fits);
  custom.insert(custom.end(), imu.metadata.begin(), imu.metadata.end());
  bag.AddMetadata(custom);

  int64_t first_ns = gt.empty() ? 0 : SecondsToNs(gt.front().timestamp);
  if (!imu.samples.empty()) first_ns = std::min(first_ns, RosTimeToNs(imu.samples.front().header.stamp));
  for (size_t k = 0; k < info.rig.cameras.size() && info.frame_count > 0; ++k) {
    first_ns = std::min(first_ns, ImageStampNs(info, gt, 0, k));
  }
  bag.Write(topics.tf, first_ns, EncodeRosTfMessage(StaticTransforms(info, extrinsics, report.fits, imu, first_ns)));
  WriteMessages(dataset_dir, info, gt, report.fits, imu, topics, &bag);
  bag.Close();
  WriteFileAtomic((fs::path(options.out_dir) / "metadata.yaml").string(), MetadataYaml(bag, file, custom));

  for (const Topic& t : bag.topics()) report.messages[t.name] = t.count;
  report.frames = info.frame_count;
  report.ground_truth = !gt.empty();
  report.imu = !imu.samples.empty();
  return report;
}

}  // namespace rovo
