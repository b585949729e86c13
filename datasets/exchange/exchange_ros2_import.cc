// Import of ROS 2 bags (MCAP storage) as rovo datasets (ros2_bag.h).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "datasets/exchange/exchange.h"
#include "datasets/exchange/mcap_reader.h"
#include "datasets/exchange/ros2_bag.h"
#include "datasets/exchange/ros2_bag_internal.h"
#include "datasets/exchange/ros2_messages.h"
#include "datasets/image_file.h"
#include "datasets/io.h"
#include "rovo/version.h"

namespace rovo {
namespace fs = std::filesystem;
namespace {

// The .mcap of a rosbag2 folder: metadata.yaml's first relative_file_paths entry, else the only .mcap.
std::string McapPath(const std::string& bag) {
  if (!fs::is_directory(bag)) return bag;
  const fs::path metadata = fs::path(bag) / "metadata.yaml";
  if (fs::exists(metadata)) {
    try {
      const YAML::Node files = YAML::LoadFile(metadata.string())["rosbag2_bagfile_information"]["relative_file_paths"];
      if (files && files.IsSequence() && files.size() > 0) return (fs::path(bag) / files[0].as<std::string>()).string();
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(metadata.string() + ": rosbag2_bagfile_information/relative_file_paths: " + e.what());
    }
    throw std::runtime_error(metadata.string() + ": rosbag2_bagfile_information/relative_file_paths: missing");
  }
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(bag)) {
    if (entry.path().extension() == ".mcap") found.push_back(entry.path().string());
  }
  if (found.size() != 1) {
    throw std::runtime_error(bag + ": expected metadata.yaml or exactly one .mcap file, found " +
                             std::to_string(found.size()) + " .mcap files");
  }
  return found.front();
}

// What the bag holds, decoded (images are written out as they are read).
struct BagContents {
  std::vector<std::string> image_topics;             // sorted: camera k = image_topics[k]
  std::map<std::string, RosCameraInfo> camera_info;  // by image topic (the first message of its sibling)
  std::vector<std::vector<int64_t>> image_stamps;    // per camera
  std::vector<RosTransform> transforms;              // /tf_static
  std::vector<RosOdometry> odometry;                 // /ground_truth/odometry (or the only Odometry topic)
  Ros2ImuImport imu;
  McapStringMap metadata;  // the "rovo" Metadata record
};

std::string Sibling(const std::string& image_topic, const std::string& leaf) {
  const size_t slash = image_topic.rfind('/');
  return (slash == std::string::npos ? std::string() : image_topic.substr(0, slash)) + "/" + leaf;
}

void WritePng(const RosImage& image, const std::string& where, const std::string& path) {
  int channels = 0;
  if (image.encoding == "mono8") channels = 1;
  if (image.encoding == "rgb8" || image.encoding == "bgr8") channels = 3;
  if (channels == 0)
    throw std::runtime_error(where + ": encoding: '" + image.encoding + "' (mono8, rgb8 or bgr8 are read)");
  if (image.width == 0 || image.height == 0 || image.step < image.width * static_cast<uint32_t>(channels)) {
    throw std::runtime_error(where + ": step: " + std::to_string(image.step) + " bytes is less than a row of " +
                             std::to_string(image.width) + " pixels of " + image.encoding);
  }
  std::vector<uint8_t> pixels(static_cast<size_t>(image.width) * image.height * static_cast<size_t>(channels));
  const size_t row = static_cast<size_t>(image.width) * static_cast<size_t>(channels);
  for (uint32_t y = 0; y < image.height; ++y) {
    std::copy_n(image.data.begin() + static_cast<std::ptrdiff_t>(static_cast<size_t>(y) * image.step), row,
                pixels.begin() + static_cast<std::ptrdiff_t>(y * row));
  }
  if (image.encoding == "bgr8") {
    for (size_t i = 0; i < pixels.size(); i += 3) std::swap(pixels[i], pixels[i + 2]);
  }
  WritePng8(path, static_cast<int>(image.width), static_cast<int>(image.height), channels, pixels,
            "rovo " ROVO_VERSION);
}

std::vector<std::string> ImageTopics(const McapContents& contents, const std::string& what) {
  std::vector<std::string> topics;
  for (const auto& [id, channel] : contents.channels) {
    const auto schema = contents.schemas.find(channel.schema_id);
    if (schema != contents.schemas.end() && schema->second.name == kRosImageType) topics.push_back(channel.topic);
  }
  std::sort(topics.begin(), topics.end());
  topics.erase(std::unique(topics.begin(), topics.end()), topics.end());
  if (topics.empty()) throw std::runtime_error(what + ": no sensor_msgs/msg/Image channel");
  return topics;
}

// Second pass: decodes every message rovo uses, writing images as camK/NNNNNN.png.
BagContents Decode(std::string_view bytes, const std::string& what, const McapContents& index,
                   const std::string& out_dir) {
  BagContents bag;
  bag.image_topics = ImageTopics(index, what);
  bag.image_stamps.resize(bag.image_topics.size());
  for (const McapMetadata& m : index.metadata) {
    if (m.name == "rovo") bag.metadata = bag.imu.metadata = m.metadata;
  }
  std::map<std::string, size_t> camera_of;
  for (size_t k = 0; k < bag.image_topics.size(); ++k) camera_of[bag.image_topics[k]] = k;
  std::map<std::string, std::string> info_topic;  // camera_info topic -> image topic
  for (const std::string& t : bag.image_topics) info_topic[Sibling(t, "camera_info")] = t;
  ReadMcap(bytes, what, [&](const McapSchema* schema, const McapChannel& channel, const McapMessage& m) {
    if (schema == nullptr || channel.message_encoding != "cdr") return;
    const std::string& type = schema->name;
    if (type == kRosImageType) {
      const size_t k = camera_of.at(channel.topic);
      const RosImage image = DecodeRosImage(m.data, m.where);
      WritePng(image, m.where,
               ImagePath(out_dir, "cam" + std::to_string(k), static_cast<int>(bag.image_stamps[k].size())));
      bag.image_stamps[k].push_back(RosTimeToNs(image.header.stamp));
    } else if (type == kRosCameraInfoType && info_topic.count(channel.topic) != 0) {
      const std::string& image_topic = info_topic.at(channel.topic);
      if (bag.camera_info.count(image_topic) == 0) bag.camera_info[image_topic] = DecodeRosCameraInfo(m.data, m.where);
    } else if (type == kRosTfMessageType && channel.topic == kRos2TfStaticTopic) {
      for (RosTransform& t : DecodeRosTfMessage(m.data, m.where)) bag.transforms.push_back(std::move(t));
    } else if (type == kRosOdometryType) {
      bag.odometry.push_back(DecodeRosOdometry(m.data, m.where));
    } else if (type == kRosImuType && channel.topic == kRos2ImuTopic) {
      bag.imu.samples.push_back(DecodeRosImu(m.data, m.where));
    } else if (type == kRosImuType && channel.topic == kRos2ImuExactTopic) {
      bag.imu.exact.push_back(DecodeRosImu(m.data, m.where));
    } else if (type == kRosImuType && channel.topic == kRos2ImuBiasTopic) {
      bag.imu.bias.push_back(DecodeRosImu(m.data, m.where));
    }
  });
  return bag;
}

// parent_from_child of every frame relative to the root of its /tf_static tree.
std::map<std::string, Rigid3> RootFromFrame(const std::vector<RosTransform>& transforms, const std::string& what) {
  std::map<std::string, std::pair<std::string, Rigid3>> parent;
  for (const RosTransform& t : transforms) {
    if (t.rotation.norm() < 1e-9)
      throw std::runtime_error(what + ": /tf_static: " + t.child_frame_id + ": zero rotation");
    parent[t.child_frame_id] = {t.header.frame_id, Rigid3(t.rotation.normalized(), t.translation)};
  }
  std::map<std::string, Rigid3> out;
  for (const auto& [frame, link] : parent) {
    Rigid3 root_from_frame = link.second;
    std::string up = link.first;
    for (size_t hops = 0; parent.count(up) != 0; ++hops) {
      if (hops > parent.size()) throw std::runtime_error(what + ": /tf_static: a cycle through " + frame);
      root_from_frame = parent.at(up).second * root_from_frame;
      up = parent.at(up).first;
    }
    out[frame] = root_from_frame;
    out[up] = Rigid3::Identity();
  }
  return out;
}

double MetadataNumber(const McapStringMap& metadata, const std::string& name) {
  for (const auto& [key, value] : metadata) {
    if (key == name) {
      try {
        return std::stod(value);
      } catch (const std::exception&) {
        return 0.0;
      }
    }
  }
  return 0.0;
}

// The rig frame: "rig" when /tf_static has it, else camera 0's frame.
std::string RigFrame(const BagContents& bag, const std::map<std::string, Rigid3>& root_from) {
  if (root_from.count("rig") != 0) return "rig";
  const auto info = bag.camera_info.find(bag.image_topics[0]);
  return info == bag.camera_info.end() ? std::string("rig") : info->second.header.frame_id;
}

Rig RigFromBag(const BagContents& bag, const std::map<std::string, Rigid3>& root_from, const std::string& what) {
  const std::string rig_frame = RigFrame(bag, root_from);
  Rig rig;
  for (size_t k = 0; k < bag.image_topics.size(); ++k) {
    const std::string& topic = bag.image_topics[k];
    const auto info = bag.camera_info.find(topic);
    const std::string where = what + ": " + Sibling(topic, "camera_info");
    if (info == bag.camera_info.end()) throw std::runtime_error(where + ": no CameraInfo beside " + topic);
    const RosCameraInfo& ci = info->second;
    if (ci.distortion_model != "equidistant" || ci.d.size() != 4) {
      throw std::runtime_error(where + ": distortion_model: '" + ci.distortion_model + "' with " +
                               std::to_string(ci.d.size()) + " coefficients (rovo reads equidistant with 4)");
    }
    if (ci.width < 1 || ci.width > 65536 || ci.height < 1 || ci.height > 65536) {
      throw std::runtime_error(where + ": width, height: " + std::to_string(ci.width) + " x " +
                               std::to_string(ci.height) + " is not an image size in [1, 65536]");
    }
    for (double v : ci.k) {
      if (!std::isfinite(v)) throw std::runtime_error(where + ": k: not finite");
    }
    for (double v : ci.d) {
      if (!std::isfinite(v)) throw std::runtime_error(where + ": d: not finite");
    }
    RigCamera rc;
    rc.name = "cam" + std::to_string(k);
    const std::vector<double> params = {ci.k[0], ci.k[4], ci.k[2], ci.k[5], ci.d[0], ci.d[1], ci.d[2], ci.d[3]};
    rc.camera = CameraFromExchangeLens(ExchangeLensModel::kKannalaBrandt4, params, static_cast<int>(ci.width),
                                       static_cast<int>(ci.height), 360.0, where);
    const double fov = MetadataNumber(bag.metadata, "rovo_" + rc.name + "_max_fov_deg");
    rc.camera.max_fov_deg = fov > 0 && fov < 360 ? fov : ImageFovDeg(rc.camera);
    const std::string& frame = ci.header.frame_id;
    if (root_from.count(frame) == 0 || root_from.count(rig_frame) == 0) {
      throw std::runtime_error(where + ": header.frame_id: '" + frame + "' is not placed on the rig by /tf_static");
    }
    rc.cam_from_rig = root_from.at(frame).Inverse() * root_from.at(rig_frame);
    rig.cameras.push_back(rc);
  }
  rig.Check(what);
  return rig;
}

// world_from_rig at each odometry stamp (strictly increasing, unit-normable orientations).
Trajectory GroundTruth(const std::vector<RosOdometry>& odometry, const std::string& what) {
  Trajectory gt;
  for (size_t i = 0; i < odometry.size(); ++i) {
    const RosOdometry& o = odometry[i];
    const std::string where = what + ": nav_msgs/msg/Odometry " + std::to_string(i) + ": ";
    const double t = static_cast<double>(RosTimeToNs(o.header.stamp)) * 1e-9;
    if (!gt.empty() && !(t > gt.back().timestamp)) throw std::runtime_error(where + "header.stamp: not increasing");
    if (o.orientation.norm() < 1e-9) throw std::runtime_error(where + "pose.pose.orientation: zero quaternion");
    gt.push_back({t, Rigid3(o.orientation, o.position)});
  }
  return gt;
}

}  // namespace

Ros2ImportReport ImportRos2Bag(const std::string& bag_path, const std::string& out_dir) {
  const std::string path = McapPath(bag_path);
  const std::string bytes = ReadFile(path);
  const McapContents index = ReadMcap(bytes, path, nullptr);
  if (index.profile != "ros2") throw std::runtime_error(path + ": Header: profile: '" + index.profile + "', not ros2");
  EnsureWritableDir(out_dir);
  BagContents bag = Decode(bytes, path, index, out_dir);

  DatasetInfo info;
  info.generator = "rovo dataset import";
  info.preset = "";
  info.scene_hash = "import ros2";
  const std::map<std::string, Rigid3> root_from = RootFromFrame(bag.transforms, path);
  info.rig = RigFromBag(bag, root_from, path);
  size_t frames = bag.image_stamps[0].size();
  for (const auto& stamps : bag.image_stamps) frames = std::min(frames, stamps.size());
  if (frames == 0) throw std::runtime_error(path + ": " + bag.image_topics[0] + ": no images");
  info.frame_count = static_cast<int>(frames);

  Trajectory gt = GroundTruth(bag.odometry, path);
  const bool gt_per_frame = gt.size() == frames;
  std::vector<double> times;
  for (size_t f = 0; f < frames; ++f) {
    times.push_back(gt_per_frame ? gt[f].timestamp : static_cast<double>(bag.image_stamps[0][f]) * 1e-9);
  }
  if (!gt_per_frame && !gt.empty()) {
    Trajectory at_frames;
    for (double t : times) at_frames.push_back({t, InterpolatePose(gt, t)});
    gt = at_frames;
  }
  const double rate = MetadataNumber(bag.metadata, "rovo_frame_rate_hz");
  info.frame_rate = rate > 0 ? rate
                    : frames > 1 && times.back() > times.front()
                        ? (static_cast<double>(frames) - 1) / (times.back() - times.front())
                        : 10.0;
  if (root_from.count("imu") != 0) {
    bag.imu.imu_from_rig = root_from.at("imu").Inverse() * root_from.at(RigFrame(bag, root_from));
  }
  const bool imu = ImportRos2Imu(bag.imu, path, out_dir, &info);
  info.has_ground_truth = !gt.empty();
  if (!gt.empty()) WriteTum(GroundTruthPath(out_dir), gt);
  WriteDatasetInfo(out_dir, info);

  Ros2ImportReport report;
  report.frames = info.frame_count;
  report.cameras = info.rig.NumCameras();
  report.ground_truth = !gt.empty();
  report.imu = imu;
  report.issues = ValidateDataset(out_dir);
  return report;
}

}  // namespace rovo
