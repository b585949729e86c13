// Fuzz target: a camera image read by the VO's replay (LoadFrameImages, vo/image_loader.h, with the
// fast PNG path of vo/png_gray.h; and FrameReader with lens corrections, whose colour path decodes
// through libpng and vo/lateral_colour.h, then vo/flat_field.h). The input becomes cam0/000000.png of a one-camera
// 32x31 rig. Besides the error contract: whenever the fast path decodes the bytes, OpenCV's decoder must give the same
// image (the fast path must never accept what libpng would read otherwise or refuse), and whenever OpenCV decodes a
// PNG, ReadGrayImage gives its image.
#include "datasets/dataset.h"
#include "datasets/rig.h"
#include "tests/fuzz/fuzz_rig.h"
#include "tests/fuzz/fuzz_util.h"
#include "tests/fuzz/opencv_gray.h"
#include "vo/image_loader.h"
#include "vo/png_gray.h"

namespace {

rovo::Rig OneCameraRig() {
  rovo::Rig rig;
  rig.cameras.push_back(rovo::fuzz::SmallFuzzCamera());
  return rig;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const rovo::fuzz::ScratchDir scratch("png_gray");
  static const std::string dir = scratch.Fresh("dataset");
  static const rovo::Rig rig = OneCameraRig();
  const std::string path = rovo::ImagePath(dir, "cam0", 0);
  rovo::fuzz::WriteBytes(path, data, size);
  const cv::Mat expected = rovo::fuzz::OpenCvGray(data, size);
  if (const auto fast = rovo::DecodePngGrayFast(data, size)) {
    if (expected.size() != fast->size() || cv::countNonZero(expected != *fast) != 0) {
      rovo::fuzz::Finding("fast PNG path differs from OpenCV", path);
    }
  }
  const bool png = size >= 4 && data[1] == 'P' && data[2] == 'N' && data[3] == 'G';
  if (png && !expected.empty()) {  // OpenCV's reader of other formats is not rovo's concern
    const cv::Mat read = rovo::ReadGrayImage(path);
    if (read.size() != expected.size() || cv::countNonZero(read != expected) != 0) {
      rovo::fuzz::Finding("gray PNG differs from OpenCV's", path);
    }
  }
  static const rovo::FrameReader plain(dir, rig);
  static const rovo::FrameReader lateral_colour(dir, rig, {{0.01, -0.02}, {0.3, 0.4}, "srgb"});
  for (const rovo::FrameReader* reader : {&plain, &lateral_colour}) {
    rovo::fuzz::ExpectClearError({path}, [&] {
      const rovo::LoadedFrame loaded = reader->Load(0, reader == &plain);
      if (loaded.images.size() != 1 || loaded.images[0].rows != 31 || loaded.images[0].cols != 32) {
        rovo::fuzz::Finding("loaded image of the wrong size", path);
      }
      if (!loaded.missing_cameras.empty() && loaded.problems.find(path) == std::string::npos) {
        rovo::fuzz::Finding("missing image not named", loaded.problems);
      }
    });
  }
  return 0;
}
