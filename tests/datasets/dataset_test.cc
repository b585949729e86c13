#include "datasets/dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>

#include "datasets/io.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rovo_dataset_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

DatasetInfo ExampleInfo() {
  DatasetInfo info;
  info.generator_version = "0.1.0";
  info.seed = 18446744073709551557ull;  // near 2^64: must survive JSON
  info.preset = "static_urban";
  info.scene_hash = "0123456789abcdef";
  info.frame_rate = 12.5;
  info.frame_count = 17;
  info.rig = MakeRigPreset("rovo4");
  info.perturbed.push_back(PerturbExtrinsics(info.rig, 5.0, 0.01, 99));
  info.perturbed.push_back(PerturbExtrinsics(info.rig, 2.0, 0.0, 100));
  info.has_depth = true;
  return info;
}

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

bool SameBits(const Rigid3& a, const Rigid3& b) {
  return std::memcmp(a.rotation.coeffs().data(), b.rotation.coeffs().data(), 4 * sizeof(double)) == 0 &&
         std::memcmp(a.translation.data(), b.translation.data(), 3 * sizeof(double)) == 0;
}

TEST(DatasetInfo, RoundTripIsExact) {
  const std::string dir = TempDir("roundtrip");
  const DatasetInfo written = ExampleInfo();
  WriteDatasetInfo(dir, written);
  const DatasetInfo read = ReadDatasetInfo(dir);
  EXPECT_EQ(read.schema_version, kDatasetSchemaVersion);
  EXPECT_EQ(read.generator, "rovo");
  EXPECT_EQ(read.generator_version, "0.1.0");
  EXPECT_EQ(read.seed, written.seed);
  EXPECT_EQ(read.preset, written.preset);
  EXPECT_EQ(read.scene_hash, written.scene_hash);
  EXPECT_EQ(read.frame_rate, written.frame_rate);
  EXPECT_EQ(read.frame_count, written.frame_count);
  EXPECT_TRUE(read.has_depth);
  EXPECT_FALSE(read.has_masks);
  ASSERT_EQ(read.rig.NumCameras(), 4);
  for (int i = 0; i < 4; ++i) {
    const RigCamera& a = read.rig.cameras[i];
    const RigCamera& b = written.rig.cameras[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.camera.model, b.camera.model);
    EXPECT_EQ(a.camera.width, b.camera.width);
    EXPECT_EQ(a.camera.height, b.camera.height);
    EXPECT_TRUE(SameBits(a.camera.params, b.camera.params));
    EXPECT_EQ(a.camera.max_fov_deg, b.camera.max_fov_deg);
    EXPECT_TRUE(SameBits(a.cam_from_rig, b.cam_from_rig)) << i;
  }
  ASSERT_EQ(read.perturbed.size(), 2u);
  EXPECT_EQ(read.perturbed[0].seed, 99u);
  EXPECT_EQ(read.perturbed[0].sigma_rotation_deg, 5.0);
  EXPECT_EQ(read.perturbed[0].sigma_translation_m, 0.01);
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(SameBits(read.perturbed[1].cam_from_rig[i], written.perturbed[1].cam_from_rig[i]));
  }
  // The file states the quaternion order.
  const nlohmann::json json = ReadJsonFile(DatasetJsonPath(dir));
  EXPECT_TRUE(json["rig"]["cameras"][0]["cam_from_rig"].contains("rotation_xyzw"));
  fs::remove_all(dir);
}

TEST(DatasetInfo, WriteRejectsInconsistentPerturbedSet) {
  const std::string dir = TempDir("inconsistent");
  DatasetInfo info = ExampleInfo();
  info.perturbed[0].cam_from_rig.pop_back();
  EXPECT_THROW(WriteDatasetInfo(dir, info), std::invalid_argument);
  fs::remove_all(dir);
}

// Rewrites one field of a valid dataset.json and expects ReadDatasetInfo to name file and field.
void ExpectFieldError(const std::function<void(nlohmann::json&)>& edit, const std::string& field) {
  const std::string dir = TempDir("field");
  WriteDatasetInfo(dir, ExampleInfo());
  nlohmann::json json = ReadJsonFile(DatasetJsonPath(dir));
  edit(json);
  WriteJsonFileAtomic(DatasetJsonPath(dir), json);
  try {
    ReadDatasetInfo(dir);
    ADD_FAILURE() << "no error for " << field;
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(DatasetJsonPath(dir) + ": " + field + ": ")) << e.what();
  }
  fs::remove_all(dir);
}

TEST(DatasetInfo, ReadErrorsNameFileAndField) {
  using J = nlohmann::json;
  ExpectFieldError([](J& j) { j.erase("frame_rate"); }, "/frame_rate");
  ExpectFieldError([](J& j) { j["frame_rate"] = "10"; }, "/frame_rate");
  ExpectFieldError([](J& j) { j["frame_rate"] = -1.0; }, "/frame_rate");
  ExpectFieldError([](J& j) { j["frame_count"] = 2.5; }, "/frame_count");
  ExpectFieldError([](J& j) { j["seed"] = -3; }, "/seed");
  ExpectFieldError([](J& j) { j["has_depth"] = 1; }, "/has_depth");
  ExpectFieldError([](J& j) { j["schema_version"] = 99; }, "/schema_version");
  ExpectFieldError([](J& j) { j["rig"]["cameras"][2]["model"] = "pinhole"; }, "/rig/cameras/2/model");
  ExpectFieldError([](J& j) { j["rig"]["cameras"][1]["width"] = 0; }, "/rig/cameras/1/width");
  ExpectFieldError([](J& j) { j["rig"]["cameras"][1]["params"][4] = nullptr; }, "/rig/cameras/1/params/4");
  ExpectFieldError([](J& j) { j["rig"]["cameras"][3]["name"] = "cam0"; }, "/rig/cameras/3/name");
  ExpectFieldError([](J& j) { j["rig"]["cameras"][0]["cam_from_rig"]["rotation_xyzw"][3] = 2.0; },
                   "/rig/cameras/0/cam_from_rig/rotation_xyzw");
  ExpectFieldError(
      [](J& j) {
        j["rig"]["cameras"][0]["cam_from_rig"]["translation"] = J::array({1, 2});
      },
      "/rig/cameras/0/cam_from_rig/translation");
  ExpectFieldError([](J& j) { j["perturbed"][1]["cam_from_rig"].erase(0); }, "/perturbed/1/cam_from_rig");
  ExpectFieldError([](J& j) { j["perturbed"][0]["sigma_rotation_deg"] = -5; }, "/perturbed/0/sigma_rotation_deg");
}

TEST(DatasetInfo, MalformedJsonNamesFile) {
  const std::string dir = TempDir("malformed");
  WriteFileAtomic(DatasetJsonPath(dir), "{\"schema_version\": 1,");
  try {
    ReadDatasetInfo(dir);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(DatasetJsonPath(dir)));
  }
  fs::remove_all(dir);
}

TEST(DatasetPaths, Layout) {
  EXPECT_EQ(DatasetJsonPath("/d"), "/d/dataset.json");
  EXPECT_EQ(GroundTruthPath("/d"), "/d/groundtruth.tum");
  EXPECT_EQ(ImagePath("/d", "cam2", 17), "/d/cam2/000017.png");
  EXPECT_EQ(DepthPath("/d", "cam0", 3), "/d/depth/cam0/000003.exr");
  EXPECT_EQ(MaskPath("/d", "cam1", 123456), "/d/masks/cam1/123456.png");
}

TEST(RigJson, RoundTripAndDatasetJsonAccepted) {
  const std::string dir = TempDir("rigjson");
  const Rig rig = MakeRigPreset("omnimvs4");
  WriteRigJson(dir + "/rig.json", rig, "preset omnimvs4");
  const nlohmann::json json = ReadJsonFile(dir + "/rig.json");
  EXPECT_EQ(json["source"], "preset omnimvs4");
  EXPECT_EQ(json["schema_version"], kRigSchemaVersion);
  const Rig read = ReadRigJson(dir + "/rig.json");
  ASSERT_EQ(read.NumCameras(), 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(SameBits(read.cameras[i].camera.params, rig.cameras[i].camera.params));
    EXPECT_TRUE(SameBits(read.cameras[i].cam_from_rig, rig.cameras[i].cam_from_rig));
  }
  // A dataset.json works as a rig file too (its /rig).
  WriteDatasetInfo(dir, ExampleInfo());
  EXPECT_EQ(ReadRigJson(DatasetJsonPath(dir)).cameras[0].camera.model, CameraModelId::kOcam);
  // Errors name the file and the field.
  WriteFileAtomic(dir + "/bad.json", R"({"cameras": [{"name": "cam0", "model": "equidistant"}]})");
  try {
    ReadRigJson(dir + "/bad.json");
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr(dir + "/bad.json: /cameras/0/width: missing field"));
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rovo
