// Fuzz target: image headers read by ValidateDataset (datasets/image_file.h). The input becomes
// cam0/000000.png, depth/cam0/000000.exr, masks/cam0/000000.png and static_masks/cam0.png of a
// one-camera, one-frame dataset whose dataset.json is fixed.
#include "datasets/dataset.h"
#include "datasets/rig.h"
#include "tests/fuzz/fuzz_rig.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

rovo::DatasetInfo OneCameraInfo() {
  rovo::DatasetInfo info;
  info.frame_count = 1;
  info.has_depth = true;
  info.has_masks = true;
  info.has_ground_truth = false;
  info.has_static_masks = true;
  info.rig.cameras.push_back(rovo::fuzz::SmallFuzzCamera());
  return info;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("image_header");
  static const std::string dir = [] {
    const std::string d = scratch.Fresh("dataset");
    rovo::WriteDatasetInfo(d, OneCameraInfo());
    return d;
  }();
  for (const std::string& path : {rovo::ImagePath(dir, "cam0", 0), rovo::DepthPath(dir, "cam0", 0),
                                  rovo::MaskPath(dir, "cam0", 0), rovo::StaticMaskPath(dir, "cam0")}) {
    rovo::fuzz::WriteBytes(path, data, size);
  }
  for (const rovo::ValidationIssue& issue : rovo::ValidateDataset(dir)) {
    if (issue.file.find(dir) != 0 || issue.field.empty() || issue.message.empty()) {
      rovo::fuzz::Finding("validation issue without file, field or message", issue.file + ": " + issue.field);
    }
  }
  return 0;
}
