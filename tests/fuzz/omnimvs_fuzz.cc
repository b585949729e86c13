// Fuzz target: OmniMVS config.yaml (ReadOmniMvsConfig, ReadOmniMvsCapture and the image names the
// capture's img_fmt gives).
#include "datasets/exchange/omnimvs.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("omnimvs");
  const std::string path = scratch.Fresh("omnimvs") + "/config.yaml";
  rovo::fuzz::WriteBytes(path, data, size);
  std::string report;
  rovo::fuzz::ExpectClearError({path}, [&] { rovo::ReadOmniMvsConfig(path, &report); });
  rovo::fuzz::ExpectClearError({path}, [&] {
    const rovo::OmniMvsCapture capture = rovo::ReadOmniMvsCapture(path);
    for (int cam_id : capture.cam_ids) rovo::OmniMvsImageName(capture, cam_id, capture.end);
  });
  return 0;
}
