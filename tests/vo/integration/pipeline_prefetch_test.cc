// End to end: a replay from PNG files (decoded ahead on the prefetch thread, through the fast PNG
// path) gives the same run as one from images decoded beforehand (--preload): the same trajectory
// and extrinsics files byte for byte; and every image the renderer writes takes the fast path and
// decodes to what cv::imread gives.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/run.h"
#include "vo/pipeline.h"
#include "vo/png_gray.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

constexpr int kFrames = 12;

// One rendered quick cloudy_urban sequence for the tests below.
class PipelinePrefetch : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    fs::remove_all(Root());
    ASSERT_EQ(std::system((std::string(ROVO_BINARY) + " render --preset cloudy_urban --quick --frames 0:" +
                           std::to_string(kFrames) + " --quiet --out " + Dataset())
                              .c_str()),
              0);
  }
  static void TearDownTestSuite() { fs::remove_all(Root()); }
  static fs::path Root() { return fs::temp_directory_path() / "rovo_vo_prefetch_test"; }
  static std::string Dataset() { return (Root() / "dataset").string(); }
};

TEST_F(PipelinePrefetch, PngReplayEqualsPreloadedImagesByteForByte) {
  const fs::path root = Root();
  const std::string dataset = Dataset();
  const int frames = kFrames;
  const DatasetInfo info = ReadDatasetInfo(dataset);
  for (int frame = 0; frame < frames; ++frame) {
    for (const RigCamera& cam : info.rig.cameras) {
      const std::string path = ImagePath(dataset, cam.name, frame);
      const std::string bytes = ReadText(path);
      const auto fast = DecodePngGrayFast(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
      ASSERT_TRUE(fast.has_value()) << path << ": the renderer's PNG does not take the fast path";
      const cv::Mat expected = cv::imread(path, cv::IMREAD_GRAYSCALE);
      ASSERT_EQ(fast->size(), expected.size()) << path;
      ASSERT_EQ(cv::countNonZero(*fast != expected), 0) << path;
    }
  }
  std::vector<std::string> runs;
  for (const bool preload : {true, false}) {
    VoOptions options;
    options.io.dataset_dir = dataset;
    options.io.out_dir = (root / (preload ? "preloaded" : "prefetched")).string();
    options.io.frames.begin = 0;
    options.io.frames.end = frames;
    options.io.threads = 2;
    options.io.quiet = true;
    options.io.preload = preload;
    const VoSummary summary = RunVo(options);
    EXPECT_EQ(summary.frames, frames);
    EXPECT_GE(summary.frames_ok, frames - 2);
    runs.push_back(options.io.out_dir);
  }
  for (const char* file : {"trajectory.tum", "extrinsics.csv"}) {
    const std::string preloaded = ReadText(fs::path(runs[0]) / file);
    ASSERT_FALSE(preloaded.empty()) << file;
    EXPECT_EQ(preloaded, ReadText(fs::path(runs[1]) / file)) << file;
  }
}

// Timing from a later frame (--timed-from) changes what the summary averages, not the run; a start that
// leaves no frame to time is refused before any work.
TEST_F(PipelinePrefetch, TimedFromAveragesTheLaterFramesOfTheSameRun) {
  VoOptions options;
  options.io.dataset_dir = Dataset();
  options.io.frames.begin = 0;
  options.io.frames.end = kFrames;
  options.io.threads = 2;
  options.io.quiet = true;
  options.io.preload = true;
  std::vector<std::string> runs;
  for (const int timed_from : {0, kFrames - 4}) {
    options.io.timed_from = timed_from;
    options.io.out_dir = (Root() / ("timed_from_" + std::to_string(timed_from))).string();
    const VoSummary summary = RunVo(options);
    EXPECT_EQ(summary.frames, kFrames);
    EXPECT_GT(summary.stage_ms.track, 0.0);
    // The whole frame's mean is that of the timed frames' recorded times.
    const RunData run = ReadRun(options.io.out_dir);
    ASSERT_EQ(static_cast<int>(run.frames.size()), kFrames);
    double sum = 0.0;
    for (int k = timed_from; k < kFrames; ++k) sum += run.frames[k].time_ms;
    const double mean = sum / (kFrames - timed_from);
    EXPECT_GT(mean, 0.0);
    EXPECT_NEAR(summary.stage_ms.total, mean, 1e-9 * mean) << "timed from " << timed_from;
    runs.push_back(options.io.out_dir);
  }
  EXPECT_EQ(ReadText(fs::path(runs[0]) / "trajectory.tum"), ReadText(fs::path(runs[1]) / "trajectory.tum"));
  options.io.timed_from = kFrames;
  options.io.out_dir = (Root() / "timed_from_all").string();
  try {
    RunVo(options);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--timed-from"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(options.io.out_dir));
}

// `rovo bench vo --floor` prints its table and a ratio of two measured CPU times.
TEST_F(PipelinePrefetch, FloorBenchmarkPrintsTheFrontEndAgainstTheFloor) {
  const std::string out = (Root() / "floor.txt").string();
  ASSERT_EQ(std::system((std::string(ROVO_BINARY) + " bench vo " + Dataset() +
                         " --floor --frames 0:4 --threads 1 --quiet > " + out)
                            .c_str()),
            0);
  const std::string text = ReadText(out);
  for (const char* row : {"| warp ", "| track (pyramid + LK) ", "| detect + describe ", "| match ", "| total "}) {
    EXPECT_NE(text.find(row), std::string::npos) << row << " missing from:\n" << text;
  }
  const size_t at = text.find("front-end / floor: ");
  ASSERT_NE(at, std::string::npos) << text;
  const double ratio = std::stod(text.substr(at + std::string("front-end / floor: ").size()));
  EXPECT_GT(ratio, 0.5) << text;  // both sides measured, the same work
  EXPECT_LT(ratio, 3.0) << text;
  EXPECT_NE(text.find("machine reference"), std::string::npos) << text;
  // --timed-from selects frames of the pipeline's timing, which the floor does not run.
  EXPECT_NE(std::system((std::string(ROVO_BINARY) + " bench vo " + Dataset() +
                         " --floor --timed-from 2 --frames 0:4 --quiet > /dev/null 2>&1")
                            .c_str()),
            0);
}

// `rovo bench vo --against-mode`: both modes run in turn each round, into their own run folders, and
// the printed ratio of a round is the quotient of the two times printed beside it.
TEST_F(PipelinePrefetch, ModeComparisonPrintsPairedRatios) {
  const std::string out = (Root() / "against.txt").string();
  const std::string err = (Root() / "against_err.txt").string();
  const std::string runs = (Root() / "against_run").string();
  ASSERT_EQ(std::system((std::string(ROVO_BINARY) + " bench vo " + Dataset() +
                         " --frames 0:4 --threads 1 --against-mode noisy --rounds 2 --out " + runs + " > " + out +
                         " 2> /dev/null")
                            .c_str()),
            0);
  const std::string text = ReadText(out);
  EXPECT_NE(text.find("gt against noisy, 2 rounds (odd rounds gt first, even rounds noisy first)"), std::string::npos)
      << text;
  for (const char* mode : {"gt", "noisy"}) {
    EXPECT_TRUE(fs::exists(fs::path(runs + "_" + mode) / "trajectory.tum")) << mode;
  }
  for (const char* round : {"\n| 1 | ", "\n| 2 | "}) {
    const size_t at = text.find(round);
    ASSERT_NE(at, std::string::npos) << round << " missing from:\n" << text;
    double a = 0, b = 0, ratio = 0;
    ASSERT_EQ(std::sscanf(text.c_str() + at + std::string(round).size(), "%lf | %lf | %lf", &a, &b, &ratio), 3) << text;
    ASSERT_GT(a, 0.0);
    ASSERT_GT(b, 0.0);
    // The times are printed to 0.01 ms, the ratio to 0.001.
    EXPECT_NEAR(ratio, a / b, (a / b) * (0.005 / a + 0.005 / b) + 5e-4) << text;
  }
  EXPECT_NE(text.find("gt / noisy: median "), std::string::npos) << text;
  // The run's own mode is no comparison; --rounds needs --against-mode.
  EXPECT_NE(std::system((std::string(ROVO_BINARY) + " bench vo " + Dataset() + " --frames 0:4 --against-mode gt > " +
                         out + " 2> " + err)
                            .c_str()),
            0);
  EXPECT_NE(ReadText(err).find("--against-mode gt is the run's own mode"), std::string::npos) << ReadText(err);
  EXPECT_NE(std::system((std::string(ROVO_BINARY) + " bench vo " + Dataset() + " --frames 0:4 --rounds 2 > " + out +
                         " 2> " + err)
                            .c_str()),
            0);
  EXPECT_NE(ReadText(err).find("--rounds requires --against-mode"), std::string::npos) << ReadText(err);
}

}  // namespace
}  // namespace rovo
