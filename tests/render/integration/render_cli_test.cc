// `rovo render` as a process: SIGKILL mid-run then rerun equals an uninterrupted run; CLI errors;
// the quick preset end to end; `rovo scene preview`; the scene folder's rig.json as the default rig.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "render/render.h"
#include "tests/render/box_scene.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

// Starts ROVO_BINARY with `args`, stdout and stderr into `log`; returns the pid.
pid_t Spawn(const std::vector<std::string>& args, const std::string& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    std::vector<char*> argv;
    std::string binary = ROVO_BINARY;
    argv.push_back(binary.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

int RunRovo(const std::vector<std::string>& args, const std::string& log) {
  int status = 0;
  ::waitpid(Spawn(args, log), &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::map<std::string, std::string> Files(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file()) files[fs::relative(entry.path(), dir).string()] = ReadFile(entry.path().string());
  return files;
}

class RenderCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("rovo_render_cli_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  std::string Path(const std::string& name) const { return (root_ / name).string(); }
  fs::path root_;
};

TEST_F(RenderCliTest, KilledRunResumesToTheSameBytes) {
  constexpr int kFrames = 16;
  SaveScene(testing::MakeBoxScene(kFrames, true), Path("scene"));
  auto args = [&](const std::string& out) {
    return std::vector<std::string>{"render",  "--scene",   Path("scene"), "--rig", "omnimvs4",
                                    "--scale", "0.3",       "--spp",       "4",     "--depth",
                                    "--masks", "--threads", "1",           "--out", out};
  };
  ASSERT_EQ(RunRovo(args(Path("reference")), Path("reference.log")), 0) << ReadFile(Path("reference.log"));

  const pid_t pid = Spawn(args(Path("killed")), Path("killed.log"));
  // Kill once a few frames are on disk (and well before the end).
  const std::string probe = ImagePath(Path("killed"), "cam3", 2);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!fs::exists(probe) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the render finished before it could be killed";
  EXPECT_FALSE(FrameComplete(Path("killed"), MakeRigPreset("omnimvs4"), kFrames - 1, true, true));

  ASSERT_EQ(RunRovo(args(Path("killed")), Path("resume.log")), 0) << ReadFile(Path("resume.log"));
  const auto reference = Files(Path("reference"));
  const auto resumed = Files(Path("killed"));
  ASSERT_EQ(resumed.size(), reference.size());
  for (const auto& [path, content] : reference) {
    ASSERT_TRUE(resumed.count(path)) << path;
    EXPECT_TRUE(resumed.at(path) == content) << path << " differs";
  }
  EXPECT_TRUE(ValidateDataset(Path("killed")).empty());
}

TEST_F(RenderCliTest, BadInputExitsNonZeroNamingTheProblem) {
  EXPECT_EQ(RunRovo({"render", "--scene", Path("missing_scene"), "--out", Path("out")}, Path("a.log")), 1);
  EXPECT_NE(ReadFile(Path("a.log")).find("missing_scene"), std::string::npos) << ReadFile(Path("a.log"));
  EXPECT_FALSE(fs::exists(Path("out")));
  EXPECT_NE(RunRovo({"render", "--preset", "no_such_preset", "--out", Path("out")}, Path("b.log")), 0);
  EXPECT_NE(ReadFile(Path("b.log")).find("no_such_preset"), std::string::npos) << ReadFile(Path("b.log"));
  EXPECT_FALSE(fs::exists(Path("out")));
  EXPECT_NE(RunRovo({"render", "--scene", Path("x"), "--shard", "3", "--out", Path("out")}, Path("c.log")), 0);
  EXPECT_NE(ReadFile(Path("c.log")).find("--shard"), std::string::npos) << ReadFile(Path("c.log"));
}

TEST_F(RenderCliTest, QuickPresetRendersAValidDataset) {
  ASSERT_EQ(RunRovo({"render", "--preset", "static_urban", "--quick", "--frames", "0:2", "--scale", "0.2", "--masks",
                     "--out", Path("quick")},
                    Path("quick.log")),
            0)
      << ReadFile(Path("quick.log"));
  const DatasetInfo info = ReadDatasetInfo(Path("quick"));
  EXPECT_EQ(info.frame_count, 2);
  EXPECT_EQ(info.preset, "static_urban");
  for (const ValidationIssue& issue : ValidateDataset(Path("quick")))
    ADD_FAILURE() << issue.file << " " << issue.field << ": " << issue.message;
  // The street scene is not blank: the image has many distinct values.
  const cv::Mat image = cv::imread(ImagePath(Path("quick"), "cam0", 1), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(image.empty());
  ASSERT_EQ(image.depth(), CV_8U);
  std::vector<int> histogram(256, 0);
  for (auto it = image.datastart; it != image.dataend; ++it) ++histogram[*it];
  int distinct = 0;
  for (int h : histogram) distinct += h > 0;
  EXPECT_GT(distinct, 100);
}

TEST_F(RenderCliTest, ScenePreviewWritesAContactSheet) {
  SaveScene(testing::MakeBoxScene(4, true), Path("scene"));
  ASSERT_EQ(RunRovo({"scene", "preview", Path("scene"), "--frames", "0,3", "--rig", "omnimvs4", "--scale", "0.1",
                     "--out", Path("sheet.png")},
                    Path("p.log")),
            0)
      << ReadFile(Path("p.log"));
  const cv::Mat sheet = cv::imread(Path("sheet.png"), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(sheet.cols, 4 * 80);
  EXPECT_EQ(sheet.rows, 2 * 77);
}

// `rovo render --scene DIR` renders with DIR/rig.json (the Blender exporter's rig) and says so.
TEST_F(RenderCliTest, SceneFolderRigJsonIsUsedAndPrinted) {
  SaveScene(testing::MakeBoxScene(2, false), Path("scene"));
  const std::string rig_json = (fs::path(Path("scene")) / "rig.json").string();
  WriteRigJson(rig_json, MakeRigPreset("rovo4").Scaled(0.04), "test");
  ASSERT_EQ(RunRovo({"render", "--scene", Path("scene"), "--frames", "0:1", "--out", Path("out")}, Path("r.log")), 0)
      << ReadFile(Path("r.log"));
  const std::string log = ReadFile(Path("r.log"));
  EXPECT_NE(log.find("rig: " + rig_json + " (the scene's rig.json): 4 cameras, ocam 64x61"), std::string::npos) << log;
  EXPECT_EQ(ReadDatasetInfo(Path("out")).rig.cameras[0].camera.width, 64);

  ASSERT_EQ(RunRovo({"render", "--scene", Path("scene"), "--frames", "0:1", "--rig", "omnimvs4", "--scale", "0.1",
                     "--out", Path("out_explicit")},
                    Path("e.log")),
            0)
      << ReadFile(Path("e.log"));
  EXPECT_NE(ReadFile(Path("e.log")).find("rig: preset omnimvs4 (--rig)"), std::string::npos) << ReadFile(Path("e.log"));
  EXPECT_EQ(ReadDatasetInfo(Path("out_explicit")).rig.cameras[0].camera.width, 80);
}

// `rovo bench render --against PRESET` times both scenes' default render and prints the ratio; an
// unknown preset is named.
TEST_F(RenderCliTest, BenchRenderPrintsTheRatioAgainstAPreset) {
  SaveScene(testing::MakeBoxScene(2, false), Path("scene"));
  ASSERT_EQ(RunRovo({"bench", "render", "--scene", Path("scene"), "--frames", "2", "--scale", "0.25", "--threads", "2",
                     "--against", "static_urban"},
                    Path("b.log")),
            0)
      << ReadFile(Path("b.log"));
  const std::string log = ReadFile(Path("b.log"));
  const size_t at = log.find("against preset static_urban, frames in turn: ");
  ASSERT_NE(at, std::string::npos) << log;
  double mine = 0.0, reference = 0.0, ratio = 0.0;
  ASSERT_EQ(
      std::sscanf(log.c_str() + log.find(": ", at) + 2, "%lf / %lf CPU s/frame = %lfx", &mine, &reference, &ratio), 3)
      << log;
  EXPECT_GT(mine, 0.0);
  EXPECT_GT(reference, 0.0);
  EXPECT_NEAR(ratio, mine / reference, 0.05 * ratio + 0.01);

  EXPECT_NE(RunRovo({"bench", "render", "--scene", Path("scene"), "--frames", "1", "--scale", "0.05", "--against",
                     "no_such_preset"},
                    Path("bad.log")),
            0);
  EXPECT_NE(ReadFile(Path("bad.log")).find("no_such_preset"), std::string::npos) << ReadFile(Path("bad.log"));
}

}  // namespace
}  // namespace rovo
