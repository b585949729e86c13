// Fuzz target: the IMU streams of a dataset (imu/data.csv, imu/exact.csv, imu/bias.csv): ReadImuCsv,
// ReadImuBiasCsv and ParseImuCsv collecting issues, and ReadImuStreams on a dataset folder. The
// input holds up to three files split at PartMarker() (data, exact, bias; a missing part repeats the first).
#include "datasets/imu.h"
#include "datasets/io.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("imu");
  const std::string dir = scratch.Fresh("imu");
  const std::string data_path = rovo::ImuDataPath(dir);
  const std::vector<std::string> parts = rovo::fuzz::SplitParts(data, size, 3);
  rovo::fuzz::WriteText(data_path, parts[0]);
  rovo::fuzz::WriteText(rovo::ImuExactPath(dir), parts[1].empty() ? parts[0] : parts[1]);
  rovo::fuzz::WriteText(rovo::ImuBiasPath(dir), parts[2].empty() ? parts[0] : parts[2]);
  rovo::fuzz::ExpectClearError({data_path}, [&] { rovo::ReadImuCsv(data_path); });
  rovo::fuzz::ExpectClearError({rovo::ImuBiasPath(dir)}, [&] { rovo::ReadImuBiasCsv(rovo::ImuBiasPath(dir)); });
  std::vector<rovo::ValidationIssue> issues;
  rovo::ParseImuCsv(rovo::ReadFile(data_path), data_path, &issues);
  for (const rovo::ValidationIssue& issue : issues) {
    if (issue.file != data_path || issue.field.empty() || issue.message.empty())
      rovo::fuzz::Finding("IMU csv issue without file, line or message", issue.message);
  }
  rovo::fuzz::ExpectClearError({data_path, rovo::ImuExactPath(dir), rovo::ImuBiasPath(dir)},
                               [&] { rovo::ReadImuStreams(dir); });
  return 0;
}
