// Fuzz target: ROS 2 bags in MCAP (ReadMcap, mcap_reader.cc, with every message decoded by its
// schema's CDR decoder, ros2_messages.cc; then ImportRos2Bag, exchange_ros2_import.cc, on the same
// file). The input is the .mcap file.
#include "datasets/exchange/mcap_reader.h"
#include "datasets/exchange/ros2_bag.h"
#include "datasets/exchange/ros2_messages.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

void DecodeByType(const rovo::McapSchema* schema, const rovo::McapMessage& m) {
  if (schema == nullptr) return;
  if (schema->name == rovo::kRosImageType) rovo::DecodeRosImage(m.data, m.where);
  if (schema->name == rovo::kRosCameraInfoType) rovo::DecodeRosCameraInfo(m.data, m.where);
  if (schema->name == rovo::kRosImuType) rovo::DecodeRosImu(m.data, m.where);
  if (schema->name == rovo::kRosTfMessageType) rovo::DecodeRosTfMessage(m.data, m.where);
  if (schema->name == rovo::kRosOdometryType) rovo::DecodeRosOdometry(m.data, m.where);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("mcap");
  const std::string dir = scratch.Fresh("bag");
  const std::string path = dir + "/bag_0.mcap";
  rovo::fuzz::WriteBytes(path, data, size);
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  rovo::fuzz::ExpectClearError({path}, [&] {
    rovo::ReadMcap(bytes, path,
                   [](const rovo::McapSchema* schema, const rovo::McapChannel&, const rovo::McapMessage& m) {
                     DecodeByType(schema, m);
                   });
  });
  const std::string out = scratch.Fresh("imported");
  rovo::fuzz::ExpectClearError({path, out}, [&] { rovo::ImportRos2Bag(path, out); });
  return 0;
}
