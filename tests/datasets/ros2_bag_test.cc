// MCAP writer/reader (mcap_writer.h, mcap_reader.h) and the ROS 2 messages' CDR (ros2_messages.h).
// The independent check (Foxglove's readers from npm) is tests/datasets/integration/ros2_bag_test.cc.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>

#include "datasets/exchange/mcap_reader.h"
#include "datasets/exchange/mcap_writer.h"
#include "datasets/exchange/ros2_messages.h"
#include "datasets/io.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

std::string TempFile(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rovo_mcap_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

struct Seen {
  std::string topic, schema;
  uint64_t log_time = 0;
  uint32_t sequence = 0;
  std::string data;
};

McapContents ReadAll(const std::string& bytes, std::vector<Seen>* seen) {
  return ReadMcap(bytes, "test.mcap", [&](const McapSchema* schema, const McapChannel& c, const McapMessage& m) {
    seen->push_back({c.topic, schema ? schema->name : "", m.log_time, m.sequence, std::string(m.data)});
  });
}

// A file of two channels written in chunks of at most ~100 bytes: everything comes back in order.
TEST(Mcap, WriteThenReadBackAcrossChunks) {
  const std::string path = TempFile("round_trip.mcap");
  {
    McapWriter writer(path, "ros2", "rovo test", 100);
    const uint16_t schema = writer.AddSchema("pkg/msg/A", "ros2msg", "int32 a\n");
    const uint16_t a = writer.AddChannel(schema, "/a", "cdr", {{"offered_qos_profiles", "- depth: 1"}});
    const uint16_t b = writer.AddChannel(schema, "/b", "cdr", {});
    writer.AddMetadata("rovo", {{"seed", "7"}});
    for (uint32_t i = 0; i < 10; ++i) {
      writer.WriteMessage(i % 2 ? b : a, i, 1000 * i, 1000 * i, std::string(40, static_cast<char>('a' + i)));
    }
    writer.Close();
  }
  std::vector<Seen> seen;
  const McapContents contents = ReadAll(ReadFile(path), &seen);
  EXPECT_EQ(contents.profile, "ros2");
  EXPECT_EQ(contents.library, "rovo test");
  EXPECT_GT(contents.chunk_count, 2);
  ASSERT_EQ(contents.channels.size(), 2u);
  EXPECT_EQ(contents.channels.at(1).metadata, (McapStringMap{{"offered_qos_profiles", "- depth: 1"}}));
  ASSERT_EQ(contents.metadata.size(), 1u);
  EXPECT_EQ(contents.metadata[0].metadata, (McapStringMap{{"seed", "7"}}));
  ASSERT_EQ(seen.size(), 10u);
  for (uint32_t i = 0; i < 10; ++i) {
    EXPECT_EQ(seen[i].topic, i % 2 ? "/b" : "/a");
    EXPECT_EQ(seen[i].schema, "pkg/msg/A");
    EXPECT_EQ(seen[i].log_time, 1000u * i);
    EXPECT_EQ(seen[i].data, std::string(40, static_cast<char>('a' + i)));
  }
}

// A flipped byte inside a chunk's records is found by the chunk's CRC; the error names the file,
// the record's offset and the field.
TEST(Mcap, CorruptionAndTruncationNameTheRecordAndField) {
  const std::string path = TempFile("corrupt.mcap");
  {
    McapWriter writer(path, "ros2", "rovo test");
    const uint16_t s = writer.AddSchema("pkg/msg/A", "ros2msg", "int32 a\n");
    writer.WriteMessage(writer.AddChannel(s, "/a", "cdr", {}), 0, 5, 5, "payload-bytes");
    writer.Close();
  }
  std::string bytes = ReadFile(path);
  const size_t at = bytes.find("payload-bytes");
  ASSERT_NE(at, std::string::npos);
  std::string corrupt = bytes;
  corrupt[at] = 'P';
  try {
    ReadAll(corrupt, nullptr);
    ADD_FAILURE() << "a corrupt chunk was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("test.mcap: record at byte"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(Chunk): uncompressed_crc"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadAll(bytes.substr(0, bytes.size() - 20), nullptr), std::runtime_error);
  EXPECT_THROW(ReadAll("not an mcap file at all", nullptr), std::runtime_error);
}

// The bytes of a TFMessage with one transform, laid out by hand from the XCDR1 rules: the 4-byte
// encapsulation header, then alignment counted from its end.
TEST(Ros2Messages, TfMessageBytesFollowTheCdrLayout) {
  RosTransform t;
  t.header.stamp = {3, 7};
  t.header.frame_id = "rig";
  t.child_frame_id = "c";
  t.translation = {1.0, 2.0, 3.0};
  t.rotation = Eigen::Quaterniond(1, 0, 0, 0);
  const std::string cdr = EncodeRosTfMessage({t});
  // header 4 | count 4 | sec 4 | nanosec 4 | "rig\0" len 4 + 4 | "c\0" len 4 + 2 | pad 6 to 32 | 7 doubles
  ASSERT_EQ(cdr.size(), 4u + 4 + 4 + 4 + 8 + 6 + 6 + 56);
  EXPECT_EQ(cdr.substr(0, 4), std::string("\x00\x01\x00\x00", 4));
  EXPECT_EQ(cdr[4], 1);   // one transform
  EXPECT_EQ(cdr[8], 3);   // sec
  EXPECT_EQ(cdr[12], 7);  // nanosec
  EXPECT_EQ(cdr[16], 4);  // strlen("rig") + 1
  EXPECT_EQ(cdr.substr(20, 4), std::string("rig\0", 4));
  EXPECT_EQ(cdr[24], 2);  // strlen("c") + 1
  double x = 0;
  std::memcpy(&x, cdr.data() + 4 + 32, 8);  // first double at offset 32 after the header
  EXPECT_EQ(x, 1.0);
  const std::vector<RosTransform> back = DecodeRosTfMessage(cdr, "tf");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].child_frame_id, "c");
  EXPECT_EQ(back[0].translation, t.translation);
  EXPECT_EQ(back[0].rotation.coeffs(), t.rotation.coeffs());
}

TEST(Ros2Messages, EveryMessageRoundTripsExactly) {
  RosImage image;
  image.header = {{12, 345}, "cam0"};
  image.width = 3;
  image.height = 2;
  image.encoding = "mono8";
  image.step = 3;
  image.data = {1, 2, 3, 4, 5, 250};
  const RosImage image_back = DecodeRosImage(EncodeRosImage(image), "image");
  EXPECT_EQ(image_back.data, image.data);
  EXPECT_EQ(image_back.encoding, "mono8");
  EXPECT_EQ(image_back.header.stamp.nanosec, 345u);

  RosCameraInfo info;
  info.header.frame_id = "cam1";
  info.distortion_model = "equidistant";
  info.d = {0.1, -0.2, 0.3, 1e-17};
  info.k = {100.5, 0, 200.25, 0, 100.5, 190.125, 0, 0, 1};
  const RosCameraInfo info_back = DecodeRosCameraInfo(EncodeRosCameraInfo(info), "info");
  EXPECT_EQ(info_back.d, info.d);
  EXPECT_EQ(info_back.k, info.k);
  EXPECT_EQ(info_back.distortion_model, "equidistant");

  RosImu imu;
  imu.angular_velocity = {0.1, -1e-9, 3.25};
  imu.linear_acceleration = {0.5, 0.25, 9.81};
  imu.orientation_covariance[0] = -1;
  const RosImu imu_back = DecodeRosImu(EncodeRosImu(imu), "imu");
  EXPECT_EQ(imu_back.angular_velocity, imu.angular_velocity);
  EXPECT_EQ(imu_back.linear_acceleration, imu.linear_acceleration);
  EXPECT_EQ(imu_back.orientation_covariance[0], -1);

  RosOdometry odom;
  odom.position = {1, 2, 3};
  odom.orientation = Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5);
  odom.linear_velocity = {4, 5, 6};
  const RosOdometry odom_back = DecodeRosOdometry(EncodeRosOdometry(odom), "odom");
  EXPECT_EQ(odom_back.position, odom.position);
  EXPECT_EQ(odom_back.orientation.coeffs(), odom.orientation.coeffs());
  EXPECT_EQ(odom_back.linear_velocity, odom.linear_velocity);
}

TEST(Ros2Messages, BadMessagesNameTheField) {
  RosImage image;
  image.width = image.height = image.step = 2;
  image.encoding = "mono8";
  image.data = {1, 2, 3, 4};
  const std::string cdr = EncodeRosImage(image);
  try {
    DecodeRosImage(cdr.substr(0, cdr.size() - 2), "bag.mcap: record at byte 99 (Message)");
    ADD_FAILURE() << "a truncated image was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bag.mcap: record at byte 99 (Message): data:"), std::string::npos)
        << e.what();
  }
  std::string xcdr2 = cdr;
  xcdr2[1] = 0x07;
  EXPECT_THROW(DecodeRosImage(xcdr2, "x"), std::runtime_error);
  EXPECT_THROW(DecodeRosImu("\x00\x01", "x"), std::runtime_error);
}

TEST(Ros2Messages, DefinitionsCarryTheirDependencies) {
  const std::string imu = Ros2MessageDefinition("sensor_msgs/msg/Imu");
  EXPECT_EQ(imu.rfind("std_msgs/Header header\n", 0), 0u);
  EXPECT_NE(imu.find(std::string(80, '=') + "\nMSG: geometry_msgs/Quaternion\n"), std::string::npos);
  EXPECT_NE(imu.find("MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"), std::string::npos);
  EXPECT_NE(Ros2MessageDefinition("tf2_msgs/msg/TFMessage").find("MSG: geometry_msgs/TransformStamped"),
            std::string::npos);
  EXPECT_THROW(Ros2MessageDefinition("sensor_msgs/msg/PointCloud2"), std::invalid_argument);
}

}  // namespace
}  // namespace rovo
