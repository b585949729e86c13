// Fuzz target: the CDR decoders of the ROS 2 messages (ros2_messages.cc). The first byte picks the
// message type (Image, CameraInfo, Imu, TFMessage, Odometry), the rest is the message's bytes.
#include "datasets/exchange/ros2_messages.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string_view cdr(reinterpret_cast<const char*>(data) + 1, size - 1);
  const std::string where = "fuzz.mcap: record at byte 0 (Message)";
  rovo::fuzz::ExpectClearError({where}, [&] {
    switch (data[0] % 5) {
      case 0:
        rovo::DecodeRosImage(cdr, where);
        break;
      case 1:
        rovo::DecodeRosCameraInfo(cdr, where);
        break;
      case 2:
        rovo::DecodeRosImu(cdr, where);
        break;
      case 3:
        rovo::DecodeRosTfMessage(cdr, where);
        break;
      default:
        rovo::DecodeRosOdometry(cdr, where);
        break;
    }
  });
  return 0;
}
