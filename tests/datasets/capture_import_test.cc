// Importing a real capture in the OmniMVS layout (shared/data/itbt_real: three synchronous shots of a
// four-camera 220 deg rig, no ground-truth poses) as a dataset.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "datasets/dataset.h"
#include "datasets/exchange/omnimvs.h"
#include "datasets/io.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

const std::string kCapture = std::string(ROVO_SHARED_DIR) + "/data/itbt_real";

std::string Scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rovo_capture_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir.string();
}

TEST(CaptureImport, RealCaptureBecomesAValidDatasetWithoutGroundTruth) {
  const std::string out = Scratch("ok");
  const std::string report = ImportOmniMvsCapture(kCapture + "/config.yaml", kCapture, "", out);
  EXPECT_NE(report.find("imported 3 frames x 4 cameras"), std::string::npos) << report;
  EXPECT_TRUE(ValidateDataset(out).empty());
  const DatasetInfo info = ReadDatasetInfo(out);
  EXPECT_FALSE(info.has_ground_truth);
  EXPECT_EQ(info.frame_count, 3);
  EXPECT_EQ(info.perturbed.size(), 3u);
  EXPECT_FALSE(fs::exists(GroundTruthPath(out)));
  // Frame k of the dataset is the capture's k-th index (cam_id 1 -> cam0).
  EXPECT_EQ(ReadFile(ImagePath(out, "cam0", 1)), ReadFile(kCapture + "/cam1/00002.png"));
  EXPECT_EQ(ReadFile(ImagePath(out, "cam3", 2)), ReadFile(kCapture + "/cam4/00003.png"));
  fs::remove_all(out);
}

TEST(CaptureImport, DatasetWithGroundTruthStillNeedsTheFile) {
  const std::string out = Scratch("gt");
  ImportOmniMvsCapture(kCapture + "/config.yaml", kCapture, "", out);
  nlohmann::json j = ReadJsonFile(DatasetJsonPath(out));
  j["has_ground_truth"] = true;
  WriteJsonFileAtomic(DatasetJsonPath(out), j);
  const auto issues = ValidateDataset(out);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].file, GroundTruthPath(out));
  fs::remove_all(out);
}

TEST(CaptureImport, MissingMaskAndMissingImageAreNamed) {
  const std::string masks = Scratch("masks");
  fs::create_directories(masks);
  const std::string out = Scratch("nomask");
  try {
    ImportOmniMvsCapture(kCapture + "/config.yaml", kCapture, masks, out);
    FAIL() << "no error for a missing mask";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(masks + "/cam0.png"), std::string::npos) << e.what();
  }
  const std::string empty_images = Scratch("noimages");
  fs::create_directories(empty_images);
  try {
    ImportOmniMvsCapture(kCapture + "/config.yaml", empty_images, "", Scratch("noimg_out"));
    FAIL() << "no error for missing images";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cam1/00001.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dataset.img_fmt"), std::string::npos) << e.what();
  }
  fs::remove_all(masks);
  fs::remove_all(empty_images);
}

TEST(CaptureImport, StaticMasksAreCopiedAndValidated) {
  const std::string out = Scratch("withmask");
  const std::string masks = Scratch("maskdir");
  fs::create_directories(masks);
  // The capture's own images serve as masks of the right size (any 1-channel PNG is a mask).
  for (int c = 0; c < 4; ++c) {
    fs::copy_file(kCapture + "/cam" + std::to_string(c + 1) + "/00001.png",
                  masks + "/cam" + std::to_string(c) + ".png");
  }
  ImportOmniMvsCapture(kCapture + "/config.yaml", kCapture, masks, out);
  EXPECT_TRUE(ReadDatasetInfo(out).has_static_masks);
  EXPECT_TRUE(ValidateDataset(out).empty());
  fs::remove(StaticMaskPath(out, "cam2"));
  const auto issues = ValidateDataset(out);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].file, StaticMaskPath(out, "cam2"));
  fs::remove_all(out);
  fs::remove_all(masks);
}

// img_fmt is a printf pattern from the file: only two integer fields (camera id, frame index) are
// accepted, and the frame range must stay countable (tests/fuzz/omnimvs_fuzz.cc fuzzes this path).
TEST(CaptureImport, ImageFormatAndRangeFromTheFileAreChecked) {
  const std::string dir = Scratch("fmt");
  fs::create_directories(dir);
  const std::string yaml = dir + "/config.yaml";
  auto expect_error = [&](const std::string& dataset, const std::string& field) {
    WriteFileAtomic(yaml, "dataset:\n" + dataset + "cameras:\n  - cam_id: 1\n");
    try {
      ReadOmniMvsCapture(yaml);
      FAIL() << "no error for " << dataset;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(yaml + ": " + field), std::string::npos) << e.what();
    }
  };
  expect_error("  img_fmt: cam%d/%s.png\n", "dataset.img_fmt");
  expect_error("  img_fmt: cam%d/%05d_%d.png\n", "dataset.img_fmt");
  expect_error("  img_fmt: cam%d/%0999999d.png\n", "dataset.img_fmt");
  expect_error("  img_fmt: cam%ld/%d.png\n", "dataset.img_fmt");
  expect_error("  start: -2147483648\n  end: 2147483647\n", "dataset");
  WriteFileAtomic(yaml, "dataset:\n  img_fmt: cam%d/%%%05d.png\n  start: 2\n  end: 5\ncameras:\n  - cam_id: 1\n");
  const OmniMvsCapture capture = ReadOmniMvsCapture(yaml);
  EXPECT_EQ(OmniMvsImageName(capture, 1, 3), "cam1/%00003.png");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rovo
