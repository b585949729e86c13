// ROS 2 messages in CDR (ros2_messages.h), with eProsima Fast CDR.
#include "datasets/exchange/ros2_messages.h"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastcdr/exceptions/Exception.h>

#include <cmath>
#include <map>
#include <stdexcept>

namespace rovo {
namespace {

namespace cdr = eprosima::fastcdr;

// ---- definitions -------------------------------------------------------------------------------

const std::map<std::string, std::string>& FieldLists() {
  static const std::map<std::string, std::string> lists = {
      {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
      {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
      {"sensor_msgs/Image",
       "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\n"
       "uint8[] data\n"},
      {"sensor_msgs/CameraInfo",
       "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\nfloat64[] d\nfloat64[9] k\n"
       "float64[9] r\nfloat64[12] p\nuint32 binning_x\nuint32 binning_y\nRegionOfInterest roi\n"},
      {"sensor_msgs/RegionOfInterest",
       "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n"},
      {"sensor_msgs/Imu",
       "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
       "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
       "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n"},
      {"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
      {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Pose", "Point position\nQuaternion orientation\n"},
      {"geometry_msgs/PoseWithCovariance", "Pose pose\nfloat64[36] covariance\n"},
      {"geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"},
      {"geometry_msgs/TwistWithCovariance", "Twist twist\nfloat64[36] covariance\n"},
      {"geometry_msgs/Transform", "Vector3 translation\nQuaternion rotation\n"},
      {"geometry_msgs/TransformStamped", "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"},
      {"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"},
      {"nav_msgs/Odometry",
       "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
       "geometry_msgs/TwistWithCovariance twist\n"},
  };
  return lists;
}

// Each type's dependencies, in the order they follow it.
const std::map<std::string, std::vector<std::string>>& Dependencies() {
  static const std::map<std::string, std::vector<std::string>> deps = {
      {"sensor_msgs/Image", {"std_msgs/Header", "builtin_interfaces/Time"}},
      {"sensor_msgs/CameraInfo", {"std_msgs/Header", "builtin_interfaces/Time", "sensor_msgs/RegionOfInterest"}},
      {"sensor_msgs/Imu",
       {"std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/Quaternion", "geometry_msgs/Vector3"}},
      {"tf2_msgs/TFMessage",
       {"geometry_msgs/TransformStamped", "std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/Transform",
        "geometry_msgs/Vector3", "geometry_msgs/Quaternion"}},
      {"nav_msgs/Odometry",
       {"std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/PoseWithCovariance", "geometry_msgs/Pose",
        "geometry_msgs/Point", "geometry_msgs/Quaternion", "geometry_msgs/TwistWithCovariance", "geometry_msgs/Twist",
        "geometry_msgs/Vector3"}},
  };
  return deps;
}

// ---- writing -----------------------------------------------------------------------------------

class CdrOut {
 public:
  CdrOut() : cdr_(buffer_, cdr::Cdr::LITTLE_ENDIANNESS, cdr::Cdr::DDS_CDR) { cdr_.serialize_encapsulation(); }
  template <typename T>
  void Put(T value) {
    cdr_.serialize(value);
  }
  void Put(const std::string& s) { cdr_.serialize(s); }
  template <size_t N>
  void Put(const std::array<double, N>& a) {
    cdr_.serializeArray(a.data(), N);
  }
  void Put(const RosHeader& h) {
    Put(h.stamp.sec);
    Put(h.stamp.nanosec);
    Put(h.frame_id);
  }
  void Put(const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) Put(v[i]);
  }
  void Put(const Eigen::Quaterniond& q) {
    for (double v : {q.x(), q.y(), q.z(), q.w()}) Put(v);
  }
  void Sequence(const std::vector<double>& v) {
    Put(static_cast<uint32_t>(v.size()));
    if (!v.empty()) cdr_.serializeArray(v.data(), v.size());
  }
  void Sequence(const std::vector<uint8_t>& v) {
    Put(static_cast<uint32_t>(v.size()));
    if (!v.empty()) cdr_.serializeArray(v.data(), v.size());
  }
  std::string Bytes() { return std::string(buffer_.getBuffer(), cdr_.getSerializedDataLength()); }

 private:
  cdr::FastBuffer buffer_;
  cdr::Cdr cdr_;
};

// ---- reading -----------------------------------------------------------------------------------

class CdrIn {
 public:
  CdrIn(std::string_view data, std::string where)
      : size_(data.size()),
        // Fast CDR reads through a char*; deserialisation never writes to it.
        buffer_(const_cast<char*>(data.data()), data.size()),
        cdr_(buffer_, cdr::Cdr::DEFAULT_ENDIAN, cdr::Cdr::DDS_CDR),
        where_(std::move(where)) {
    if (data.size() < 4)
      Fail("encapsulation", "the message has " + std::to_string(data.size()) + " bytes, fewer than 4");
    if (data[0] != 0 || (data[1] != 0 && data[1] != 1)) {
      Fail("encapsulation", "kind 0x" + Hex(data[0]) + Hex(data[1]) +
                                " is not plain CDR (0x0000 big-endian, 0x0001 little-endian; XCDR2 is not read)");
    }
    Guard("encapsulation", [&] { cdr_.read_encapsulation(); });
  }
  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    throw std::runtime_error(where_ + ": " + field + ": " + problem);
  }
  template <typename T>
  T Get(const char* field) {
    T value{};
    Guard(field, [&] { cdr_.deserialize(value); });
    return value;
  }
  std::string String(const char* field) {
    std::string s;
    Guard(field, [&] { cdr_.deserialize(s); });
    return s;
  }
  template <size_t N>
  std::array<double, N> Doubles(const char* field) {
    std::array<double, N> a{};
    Guard(field, [&] { cdr_.deserializeArray(a.data(), N); });
    return a;
  }
  double Finite(const char* field) {
    const double v = Get<double>(field);
    if (!std::isfinite(v)) Fail(field, "not finite");
    return v;
  }
  Eigen::Vector3d Vector(const char* field) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = Finite(field);
    return v;
  }
  Eigen::Quaterniond Quaternion(const char* field) {
    Eigen::Vector4d xyzw;
    for (int i = 0; i < 4; ++i) xyzw[i] = Finite(field);
    return Eigen::Quaterniond(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
  }
  RosHeader Header(const char* field) {
    RosHeader h;
    h.stamp.sec = Get<int32_t>(field);
    h.stamp.nanosec = Get<uint32_t>(field);
    if (h.stamp.nanosec >= 1000000000u) Fail(field, "stamp.nanosec " + std::to_string(h.stamp.nanosec) + " >= 1e9");
    h.frame_id = String(field);
    return h;
  }
  // A sequence's count, checked against the bytes left (each element takes `element_size`).
  uint32_t Count(const char* field, size_t element_size) {
    const auto n = Get<uint32_t>(field);
    if (static_cast<uint64_t>(n) * element_size > Remaining()) {
      Fail(field, "a sequence of " + std::to_string(n) + " elements, more than the " + std::to_string(Remaining()) +
                      " bytes left hold");
    }
    return n;
  }
  std::vector<double> DoubleSequence(const char* field) {
    std::vector<double> v(Count(field, 8));
    if (!v.empty()) Guard(field, [&] { cdr_.deserializeArray(v.data(), v.size()); });
    return v;
  }
  std::vector<uint8_t> ByteSequence(const char* field) {
    std::vector<uint8_t> v(Count(field, 1));
    if (!v.empty()) Guard(field, [&] { cdr_.deserializeArray(v.data(), v.size()); });
    return v;
  }
  size_t Remaining() const { return size_ - cdr_.getSerializedDataLength(); }

 private:
  static std::string Hex(char c) {
    static const char* digits = "0123456789abcdef";
    const auto b = static_cast<uint8_t>(c);
    return {digits[b >> 4], digits[b & 15]};
  }
  template <typename F>
  void Guard(const char* field, F&& read) {
    try {
      read();
    } catch (const cdr::exception::Exception& e) {
      Fail(field, std::string("the message ends inside it (") + e.what() + ")");
    }
  }

  size_t size_;
  cdr::FastBuffer buffer_;
  cdr::Cdr cdr_;
  std::string where_;
};

}  // namespace

RosTime RosTimeFromNs(int64_t ns) {
  if (ns < 0 || ns / 1000000000 > INT32_MAX) {
    throw std::invalid_argument("time " + std::to_string(ns) + " ns is outside builtin_interfaces/Time's range");
  }
  return {static_cast<int32_t>(ns / 1000000000), static_cast<uint32_t>(ns % 1000000000)};
}

int64_t RosTimeToNs(const RosTime& time) { return int64_t{time.sec} * 1000000000 + time.nanosec; }

std::string Ros2MessageDefinition(const std::string& type) {
  // "sensor_msgs/msg/Image" -> "sensor_msgs/Image"
  std::string key = type;
  const size_t msg = key.find("/msg/");
  if (msg != std::string::npos) key.erase(msg, 4);
  const auto deps = Dependencies().find(key);
  if (deps == Dependencies().end()) throw std::invalid_argument("no ros2msg definition of " + type);
  std::string text = FieldLists().at(key);
  for (const std::string& dep : deps->second) {
    text += std::string(80, '=') + "\nMSG: " + dep + "\n" + FieldLists().at(dep);
  }
  return text;
}

std::string EncodeRosImage(const RosImage& m) {
  CdrOut out;
  out.Put(m.header);
  out.Put(m.height);
  out.Put(m.width);
  out.Put(m.encoding);
  out.Put(m.is_bigendian);
  out.Put(m.step);
  out.Sequence(m.data);
  return out.Bytes();
}

std::string EncodeRosCameraInfo(const RosCameraInfo& m) {
  CdrOut out;
  out.Put(m.header);
  out.Put(m.height);
  out.Put(m.width);
  out.Put(m.distortion_model);
  out.Sequence(m.d);
  out.Put(m.k);
  out.Put(m.r);
  out.Put(m.p);
  out.Put(m.binning_x);
  out.Put(m.binning_y);
  for (uint32_t v : {m.roi_x_offset, m.roi_y_offset, m.roi_height, m.roi_width}) out.Put(v);
  out.Put(m.roi_do_rectify);
  return out.Bytes();
}

std::string EncodeRosImu(const RosImu& m) {
  CdrOut out;
  out.Put(m.header);
  out.Put(m.orientation);
  out.Put(m.orientation_covariance);
  out.Put(m.angular_velocity);
  out.Put(m.angular_velocity_covariance);
  out.Put(m.linear_acceleration);
  out.Put(m.linear_acceleration_covariance);
  return out.Bytes();
}

std::string EncodeRosTfMessage(const std::vector<RosTransform>& transforms) {
  CdrOut out;
  out.Put(static_cast<uint32_t>(transforms.size()));
  for (const RosTransform& t : transforms) {
    out.Put(t.header);
    out.Put(t.child_frame_id);
    out.Put(t.translation);
    out.Put(t.rotation);
  }
  return out.Bytes();
}

std::string EncodeRosOdometry(const RosOdometry& m) {
  CdrOut out;
  out.Put(m.header);
  out.Put(m.child_frame_id);
  out.Put(m.position);
  out.Put(m.orientation);
  out.Put(m.pose_covariance);
  out.Put(m.linear_velocity);
  out.Put(m.angular_velocity);
  out.Put(m.twist_covariance);
  return out.Bytes();
}

RosImage DecodeRosImage(std::string_view data, const std::string& where) {
  CdrIn in(data, where);
  RosImage m;
  m.header = in.Header("header");
  m.height = in.Get<uint32_t>("height");
  m.width = in.Get<uint32_t>("width");
  m.encoding = in.String("encoding");
  m.is_bigendian = in.Get<uint8_t>("is_bigendian");
  m.step = in.Get<uint32_t>("step");
  m.data = in.ByteSequence("data");
  if (static_cast<uint64_t>(m.step) * m.height != m.data.size()) {
    in.Fail("data", std::to_string(m.data.size()) + " bytes, but step x height = " + std::to_string(m.step) + " x " +
                        std::to_string(m.height));
  }
  return m;
}

RosCameraInfo DecodeRosCameraInfo(std::string_view data, const std::string& where) {
  CdrIn in(data, where);
  RosCameraInfo m;
  m.header = in.Header("header");
  m.height = in.Get<uint32_t>("height");
  m.width = in.Get<uint32_t>("width");
  m.distortion_model = in.String("distortion_model");
  m.d = in.DoubleSequence("d");
  m.k = in.Doubles<9>("k");
  m.r = in.Doubles<9>("r");
  m.p = in.Doubles<12>("p");
  m.binning_x = in.Get<uint32_t>("binning_x");
  m.binning_y = in.Get<uint32_t>("binning_y");
  m.roi_x_offset = in.Get<uint32_t>("roi.x_offset");
  m.roi_y_offset = in.Get<uint32_t>("roi.y_offset");
  m.roi_height = in.Get<uint32_t>("roi.height");
  m.roi_width = in.Get<uint32_t>("roi.width");
  m.roi_do_rectify = in.Get<bool>("roi.do_rectify");
  return m;
}

RosImu DecodeRosImu(std::string_view data, const std::string& where) {
  CdrIn in(data, where);
  RosImu m;
  m.header = in.Header("header");
  m.orientation = in.Quaternion("orientation");
  m.orientation_covariance = in.Doubles<9>("orientation_covariance");
  m.angular_velocity = in.Vector("angular_velocity");
  m.angular_velocity_covariance = in.Doubles<9>("angular_velocity_covariance");
  m.linear_acceleration = in.Vector("linear_acceleration");
  m.linear_acceleration_covariance = in.Doubles<9>("linear_acceleration_covariance");
  return m;
}

std::vector<RosTransform> DecodeRosTfMessage(std::string_view data, const std::string& where) {
  CdrIn in(data, where);
  // The smallest TransformStamped: 8 bytes of stamp, two empty strings (4 bytes each at least), 7 doubles.
  const uint32_t n = in.Count("transforms", 8 + 4 + 4 + 7 * 8);
  std::vector<RosTransform> out(n);
  for (RosTransform& t : out) {
    t.header = in.Header("transforms.header");
    t.child_frame_id = in.String("transforms.child_frame_id");
    t.translation = in.Vector("transforms.transform.translation");
    t.rotation = in.Quaternion("transforms.transform.rotation");
  }
  return out;
}

RosOdometry DecodeRosOdometry(std::string_view data, const std::string& where) {
  CdrIn in(data, where);
  RosOdometry m;
  m.header = in.Header("header");
  m.child_frame_id = in.String("child_frame_id");
  m.position = in.Vector("pose.pose.position");
  m.orientation = in.Quaternion("pose.pose.orientation");
  m.pose_covariance = in.Doubles<36>("pose.covariance");
  m.linear_velocity = in.Vector("twist.twist.linear");
  m.angular_velocity = in.Vector("twist.twist.angular");
  m.twist_covariance = in.Doubles<36>("twist.covariance");
  return m;
}

}  // namespace rovo
