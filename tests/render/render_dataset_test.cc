// RenderDataset on a small saved box scene: outputs, resume, shards, threads, bad input.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <utility>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "render/render.h"
#include "tests/render/box_scene.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

class RenderDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("rovo_render_test_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    scene_dir_ = (root_ / "scene").string();
    SaveScene(testing::MakeBoxScene(kFrames, true), scene_dir_);
  }
  void TearDown() override { fs::remove_all(root_); }

  RenderOptions Options(const std::string& out) const {
    RenderOptions options;
    options.scene_dir = scene_dir_;
    options.out_dir = (root_ / out).string();
    options.rig = "omnimvs4";
    options.scale = 0.1;  // 80x77 per view
    options.spp = 2;
    options.quiet = true;
    return options;
  }

  // Relative path -> content of every file under dir.
  static std::map<std::string, std::string> Files(const std::string& dir) {
    std::map<std::string, std::string> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (entry.is_regular_file()) files[fs::relative(entry.path(), dir).string()] = ReadFile(entry.path().string());
    }
    return files;
  }

  static constexpr int kFrames = 10;
  fs::path root_;
  std::string scene_dir_;
};

TEST_F(RenderDatasetTest, WritesACompleteReadableDataset) {
  RenderOptions options = Options("out");
  options.depth = true;
  options.masks = true;
  options.seed = 5;
  const RenderSummary summary = RenderDataset(options);
  EXPECT_EQ(summary.frames_total, kFrames);
  EXPECT_EQ(summary.frames_rendered, kFrames);
  EXPECT_EQ(summary.frames_skipped, 0);
  const DatasetInfo info = ReadDatasetInfo(options.out_dir);
  EXPECT_EQ(info.frame_count, kFrames);
  EXPECT_EQ(info.seed, 5u);
  EXPECT_EQ(info.rig.NumCameras(), 4);
  EXPECT_EQ(info.rig.cameras[0].camera.width, 80);
  EXPECT_TRUE(info.has_depth);
  EXPECT_TRUE(info.has_masks);
  ASSERT_GE(info.perturbed.size(), 5u);
  for (size_t i = 0; i < info.perturbed.size(); ++i) {
    EXPECT_DOUBLE_EQ(info.perturbed[i].sigma_rotation_deg, 5.0);
    for (size_t j = 0; j < i; ++j) EXPECT_NE(info.perturbed[i].seed, info.perturbed[j].seed);
  }
  EXPECT_FALSE(info.scene_hash.empty());
  EXPECT_EQ(ReadTum(GroundTruthPath(options.out_dir)).size(), static_cast<size_t>(kFrames));
  const std::vector<ValidationIssue> issues = ValidateDataset(options.out_dir);
  for (const ValidationIssue& issue : issues)
    ADD_FAILURE() << issue.file << " " << issue.field << ": " << issue.message;
  for (int f = 0; f < kFrames; ++f) EXPECT_TRUE(FrameComplete(options.out_dir, info.rig, f, true, true));
  // No temporary files left behind.
  for (const auto& [path, content] : Files(options.out_dir)) EXPECT_EQ(path.find(".tmp."), std::string::npos) << path;
}

TEST_F(RenderDatasetTest, ResumeSkipsCompleteFramesAndRedoesMissingOnes) {
  const RenderOptions options = Options("out");
  RenderDataset(options);
  const auto before = Files(options.out_dir);
  fs::remove(ImagePath(options.out_dir, "cam2", 3));
  const RenderSummary summary = RenderDataset(options);
  EXPECT_EQ(summary.frames_rendered, 1);
  EXPECT_EQ(summary.frames_skipped, kFrames - 1);
  EXPECT_EQ(Files(options.out_dir), before);
}

TEST_F(RenderDatasetTest, ShardsUnionEqualsFullRunAndWholeRangeFilesMatch) {
  RenderOptions full = Options("full");
  full.frame_begin = 1;
  full.frame_end = 10;  // 9 frames: chunks of 8 -> shard 0 gets 8, shard 1 gets 1
  RenderDataset(full);
  RenderOptions shard = full;
  shard.out_dir = (root_ / "sharded").string();
  shard.shard_count = 2;
  shard.shard_index = 1;
  const RenderSummary s1 = RenderDataset(shard);
  EXPECT_EQ(s1.frames_rendered, 1);
  // dataset.json and groundtruth.tum already describe the whole range after one shard.
  EXPECT_EQ(ReadFile(DatasetJsonPath(shard.out_dir)), ReadFile(DatasetJsonPath(full.out_dir)));
  EXPECT_EQ(ReadFile(GroundTruthPath(shard.out_dir)), ReadFile(GroundTruthPath(full.out_dir)));
  shard.shard_index = 0;
  const RenderSummary s0 = RenderDataset(shard);
  EXPECT_EQ(s0.frames_rendered, 8);
  EXPECT_EQ(Files(shard.out_dir), Files(full.out_dir));
}

TEST_F(RenderDatasetTest, ImagesAreByteIdenticalForOneAndTwoThreads) {
  RenderOptions one = Options("one");
  one.threads = 1;
  one.frame_end = 3;
  one.masks = true;
  RenderOptions two = one;
  two.out_dir = (root_ / "two").string();
  two.threads = 2;
  RenderDataset(one);
  RenderDataset(two);
  EXPECT_EQ(Files(one.out_dir), Files(two.out_dir));
}

// Each bad input fails with a message naming the file or option and writes nothing.
void ExpectFailsNaming(const RenderOptions& options, const std::string& needle) {
  try {
    RenderDataset(options);
    ADD_FAILURE() << "expected an error naming " << needle;
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(options.out_dir)) << "output written despite the error";
}

TEST_F(RenderDatasetTest, BadInputFailsCleanly) {
  RenderOptions missing = Options("out_missing");
  missing.scene_dir = (root_ / "no_such_scene").string();
  ExpectFailsNaming(missing, "no_such_scene");

  RenderOptions range = Options("out_range");
  range.frame_begin = 5;
  range.frame_end = kFrames + 1;
  ExpectFailsNaming(range, "--frames");

  RenderOptions rig = Options("out_rig");
  rig.rig = (root_ / "no_rig.json").string();
  ExpectFailsNaming(rig, "no_rig.json");

  RenderOptions shard = Options("out_shard");
  shard.shard_index = 2;
  shard.shard_count = 2;
  ExpectFailsNaming(shard, "--shard");

  // Unwritable output: a folder below a regular file.
  WriteFileAtomic((root_ / "plain_file").string(), "x");
  RenderOptions unwritable = Options("plain_file/out");
  try {
    RenderDataset(unwritable);
    ADD_FAILURE() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("plain_file"), std::string::npos) << e.what();
  }

  // Malformed scene.json.
  const std::string json_path = (fs::path(scene_dir_) / "scene.json").string();
  const std::string good_json = ReadFile(json_path);
  WriteFileAtomic(json_path, good_json.substr(0, good_json.size() / 2));
  ExpectFailsNaming(Options("out_json"), "scene.json");
  WriteFileAtomic(json_path, good_json);

  // Missing texture file.
  fs::path texture;
  for (const auto& entry : fs::recursive_directory_iterator(scene_dir_))
    if (entry.path().extension() == ".png") texture = entry.path();
  ASSERT_FALSE(texture.empty());
  fs::remove(texture);
  ExpectFailsNaming(Options("out_texture"), texture.filename().string());
}

TEST_F(RenderDatasetTest, RefusesToMixWithAnotherDataset) {
  RenderOptions options = Options("out");
  options.frame_end = 2;
  RenderDataset(options);
  options.seed = 123;  // a different seed changes the perturbed extrinsics: another dataset
  try {
    RenderDataset(options);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("dataset.json"), std::string::npos) << e.what();
  }
}

// A scene folder's rig.json (as scenes/blender/export_scene.py writes it) is the default rig of
// --scene; an explicit rig wins; without rig.json the scene's rig_preset, then rovo4.
TEST_F(RenderDatasetTest, SceneFolderRigJsonIsTheDefaultRig) {
  const Rig scene_rig = MakeRigPreset("rovo4").Scaled(0.04);  // 64x61 ocam; the box scene names omnimvs4
  const std::string rig_json = (fs::path(scene_dir_) / "rig.json").string();
  WriteRigJson(rig_json, scene_rig, "test");

  RenderOptions options = Options("out_scene_rig");
  options.rig = "";
  options.scale = 0.0;
  options.frame_end = 1;
  const RenderSummary summary = RenderDataset(options);
  EXPECT_NE(summary.rig.find(rig_json + " (the scene's rig.json)"), std::string::npos) << summary.rig;
  EXPECT_NE(summary.rig.find("4 cameras, ocam 64x61"), std::string::npos) << summary.rig;
  const Rig written = ReadDatasetInfo(options.out_dir).rig;
  ASSERT_EQ(written.NumCameras(), scene_rig.NumCameras());
  for (int c = 0; c < scene_rig.NumCameras(); ++c) {
    EXPECT_EQ(written.cameras[c].camera.model, scene_rig.cameras[c].camera.model);
    EXPECT_EQ(written.cameras[c].camera.width, scene_rig.cameras[c].camera.width);
    EXPECT_EQ(written.cameras[c].camera.height, scene_rig.cameras[c].camera.height);
    EXPECT_EQ(written.cameras[c].camera.params, scene_rig.cameras[c].camera.params);
    EXPECT_TRUE(written.cameras[c].cam_from_rig.translation.isApprox(scene_rig.cameras[c].cam_from_rig.translation));
  }

  // An explicit rig wins over the scene's rig.json.
  const Scene scene = LoadScene(scene_dir_);
  const RigChoice explicit_rig = ChooseRig("omnimvs4", scene, scene_dir_, 0.1);
  EXPECT_EQ(explicit_rig.source, "preset omnimvs4 (--rig)");
  EXPECT_EQ(explicit_rig.rig.cameras[0].camera.width, 80);
  const RigChoice explicit_json = ChooseRig(rig_json, scene, "", 0.0);
  EXPECT_EQ(explicit_json.source, rig_json + " (--rig)");

  // A broken rig.json in the scene folder is an error naming it, not a silent fallback.
  WriteFileAtomic(rig_json, "{\"cameras\": 3}");
  try {
    ChooseRig("", scene, scene_dir_, 0.0);
    ADD_FAILURE() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("rig.json"), std::string::npos) << e.what();
  }

  // Without rig.json: the scene's rig_preset, then rovo4.
  fs::remove(rig_json);
  const RigChoice from_preset = ChooseRig("", scene, scene_dir_, 0.0);
  EXPECT_EQ(from_preset.source, "preset omnimvs4 (the scene's rig_preset)");
  Scene unnamed = scene;
  unnamed.rig_preset = "";
  const RigChoice fallback = ChooseRig("", unnamed, scene_dir_, 0.0);
  EXPECT_EQ(fallback.source, "preset rovo4 (the default: the scene names no rig)");
  EXPECT_EQ(fallback.rig.cameras[0].camera.width, MakeRigPreset("rovo4").cameras[0].camera.width);
}

}  // namespace
}  // namespace rovo

namespace rovo {
namespace {

// --imu adds the IMU streams and records and changes no image; the exact stream agrees with the
// continuous-time ground truth the validator rebuilds; the rig carries the mount only with an IMU.
TEST_F(RenderDatasetTest, ImuAddsItsStreamsAndChangesNoImage) {
  RenderOptions plain = Options("plain");
  RenderDataset(plain);
  RenderOptions with_imu = Options("imu");
  with_imu.imu = true;
  with_imu.imu_settings.noise_profile = "none";
  with_imu.imu_settings.time_offset_s = 0.002;
  RenderDataset(with_imu);
  const auto a = Files(plain.out_dir), b = Files(with_imu.out_dir);
  for (const auto& [path, content] : a) {
    if (path == "dataset.json") continue;
    ASSERT_TRUE(b.count(path)) << path;
    EXPECT_EQ(content, b.at(path)) << path;
  }
  EXPECT_FALSE(ReadDatasetInfo(plain.out_dir).rig.imu_from_rig);
  EXPECT_FALSE(fs::exists(ImuDataPath(plain.out_dir)));
  const DatasetInfo info = ReadDatasetInfo(with_imu.out_dir);
  ASSERT_TRUE(info.imu);
  ASSERT_TRUE(info.rig.imu_from_rig);
  EXPECT_EQ(info.imu->rate_hz, 200.0);
  EXPECT_EQ(info.imu->noise_profile, "none");
  const ImuStreams streams = ReadImuStreams(with_imu.out_dir);
  EXPECT_EQ(static_cast<int>(streams.measured.size()), info.imu->sample_count);
  EXPECT_DOUBLE_EQ(streams.measured.front().timestamp,
                   ReadTum(GroundTruthPath(with_imu.out_dir)).front().timestamp + 0.002);
  for (const ValidationIssue& issue : ValidateDataset(with_imu.out_dir))
    ADD_FAILURE() << issue.file << " " << issue.field << ": " << issue.message;
  // Bad settings fail before any output, naming the option.
  RenderOptions bad = Options("bad");
  bad.imu = true;
  bad.imu_settings.rate_hz = -1.0;
  ExpectFailsNaming(bad, "--imu-rate");
  EXPECT_FALSE(fs::exists(bad.out_dir + "/dataset.json"));
}

// The command line: bad IMU settings fail naming the option and write nothing; the IMU options
// set the record.
TEST_F(RenderDatasetTest, CommandLineImuOptions) {
  const std::string log = (root_ / "log.txt").string();
  auto run = [&](const std::string& out, const std::string& args) {
    const int status =
        std::system((std::string(ROVO_BINARY) + " render --scene " + scene_dir_ + " --out " + (root_ / out).string() +
                     " --rig omnimvs4 --scale 0.1 --spp 1 --frames 0:3 --quiet " + args + " > " + log + " 2>&1")
                        .c_str());
    return std::make_pair(status, ReadFile(log));
  };
  const std::pair<std::string, std::string> bad[] = {
      {"--imu --imu-rate -200", "--imu-rate -200"},
      {"--imu --imu-gyro-noise-density nan", "--imu-gyro-noise-density nan"},
      {"--imu --imu-accel-random-walk -1", "--imu-accel-random-walk"},
      {"--imu --imu-noise tactical", "--imu-noise `tactical`"},
      {"--imu-rate 100", "--imu-rate: needs --imu"}};
  for (const auto& [args, needle] : bad) {
    const auto [status, text] = run("bad", args);
    EXPECT_NE(status, 0) << args;
    EXPECT_NE(text.find(needle), std::string::npos) << args << ": " << text;
    EXPECT_FALSE(fs::exists(root_ / "bad")) << args;
  }
  const auto [status, text] = run(
      "good", "--imu --imu-rate 400 --imu-gyro-noise-density 1e-3 --imu-accel-bias 0.1,0.2,0.3 --imu-time-offset-ms 5");
  ASSERT_EQ(status, 0) << text;
  const DatasetInfo info = ReadDatasetInfo((root_ / "good").string());
  ASSERT_TRUE(info.imu);
  EXPECT_EQ(info.imu->rate_hz, 400.0);
  EXPECT_EQ(info.imu->noise_profile, "custom");
  EXPECT_EQ(info.imu->noise.gyroscope_noise_density, 1e-3);
  EXPECT_EQ(info.imu->noise.accelerometer_noise_density, 2e-3);  // the profile's
  EXPECT_EQ(info.imu->noise.accelerometer_initial_bias, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_DOUBLE_EQ(info.imu->time_offset_s, 0.005);
  EXPECT_EQ(info.imu->sample_count, 81);  // 0.2 s at 400 Hz
}

}  // namespace
}  // namespace rovo
