// Front-end on a small rendered dataset (cloudy_urban, quick form, with depth): accepted inter-view
// matches are checked against the depth ground truth, and the projection study runs end to end.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "datasets/dataset.h"
#include "eval/studies/projection_study.h"
#include "vo/frontend.h"

namespace rovo {
namespace {

constexpr int kFrames = 4;

class RenderedQuick : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(
        (std::filesystem::temp_directory_path() / ("rovo_frontend_it_" + std::to_string(::getpid()))).string());
    const std::string command =
        std::string(ROVO_BINARY) +
        " render --preset cloudy_urban --quick --depth --quiet --frames 0:" + std::to_string(kFrames) + " --out " +
        *dir_;
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static std::string* dir_;
};
std::string* RenderedQuick::dir_ = nullptr;

TEST_F(RenderedQuick, AcceptedInterViewMatchesAreCorrect) {
  const DatasetInfo info = ReadDatasetInfo(*dir_);
  ASSERT_TRUE(info.has_depth);
  const Rig& rig = info.rig;
  Frontend frontend(rig, FrontendOptions{});
  int64_t counted = 0, inliers = 0, merged = 0;
  for (int t = 0; t < kFrames; ++t) {
    std::vector<cv::Mat> images;
    std::vector<cv::Mat> depths;
    for (const RigCamera& rc : rig.cameras) {
      images.push_back(cv::imread(ImagePath(*dir_, rc.name, t), cv::IMREAD_GRAYSCALE));
      ASSERT_FALSE(images.back().empty());
      depths.push_back(ReadDepthImage(DepthPath(*dir_, rc.name, t)));
    }
    const FrontendFrame frame = frontend.Process(images);
    merged += static_cast<int64_t>(frame.merged_ids.size());
    for (int c = 0; c < rig.NumCameras(); ++c) EXPECT_GT(frame.features_per_camera[c].size(), 200u);
    for (const Frontend::ViewMatch& m : frontend.last_matches()) {
      const int verdict = FrontendMatchVerdict(frontend, rig, m, depths, 2.0);
      ASSERT_NE(verdict, -2) << "an accepted match has a pixel without bearing or fisheye pixel";
      if (verdict < 0) continue;
      ++counted;
      inliers += verdict;
    }
  }
  EXPECT_GT(counted, 50 * kFrames);  // measured 2026-11-21: about 120 per frame (178 before filter 8)
  EXPECT_GT(merged, 0);
  // The target: at least 90 % of the accepted matches are correct by ground truth.
  EXPECT_GE(inliers, 0.90 * counted) << inliers << " of " << counted;
}

TEST_F(RenderedQuick, ProjectionStudyWritesItsTable) {
  ProjectionStudyOptions options;
  options.dataset_dir = *dir_;
  options.out_dir = *dir_ + "/study";
  options.frames = kFrames;
  options.quiet = true;
  const ProjectionStudyResult result = RunProjectionStudy(options);
  EXPECT_EQ(result.frames, kFrames);
  EXPECT_GT(result.tracked_pairs_hybrid, 500);
  EXPECT_GT(result.tracked_pairs_fisheye, 500);
  // Descriptor drift along tracks: the hybrid images keep descriptors closer to their first
  // sighting (measured 2026-11-21 on cloudy_urban quick, frames 0-7: 61.1 vs 72.2; the paper's
  // ratio 0.28 is not reached on our scenes, see the study's table).
  EXPECT_LT(result.hamming_hybrid, result.hamming_fisheye);
  EXPECT_GT(result.mean_age_hybrid, 0.5);
  // Table II's second row (hybrid >= 80 % and >= 3x the fisheye's) is NOT reproduced on our scenes:
  // rectified overlaps put repeated facade structure on one image row, and plain nearest-neighbour
  // matching picks the wrong copy (measured frames 0-7: hybrid 67 %, fisheye 78 %; 100 frames at
  // half size: 65 % vs 70 %). Asserted: real ratios over real counts, and the front-end's filters
  // (ratio, ZNCC, epipolar uniqueness) lift the hybrid matches to the 90 % target.
  EXPECT_GT(result.matches_hybrid, 100);
  EXPECT_GT(result.matches_fisheye, 100);
  EXPECT_GT(result.InlierRatioHybrid(), 0.5);
  EXPECT_GT(result.InlierRatioFisheye(), 0.5);
  EXPECT_LE(result.InlierRatioFisheye(), 1.0);
  EXPECT_GE(result.InlierRatioFrontend(), 0.90);
  EXPECT_GT(result.InlierRatioFrontend(), result.InlierRatioHybrid());
  // Descriptors alone (no geometric filter) and the same filter chain on both arms: the chain's
  // precision is similar, the hybrid images give more correct matches (measured 2026-11-21 at half
  // size, 100 frames: 9793 vs 6977, 92.5 vs 93.5 %).
  EXPECT_GT(result.raw_matches_hybrid, result.matches_hybrid);
  EXPECT_LT(result.RawInlierRatioHybrid(), result.InlierRatioHybrid());
  EXPECT_GE(result.ChainInlierRatioHybrid(), 0.85);
  EXPECT_GE(result.ChainInlierRatioFisheye(), 0.85);
  EXPECT_GT(result.chain_inliers_hybrid, result.chain_inliers_fisheye);
  for (const char* name :
       {"table.md", "study.json", "matches_hybrid.png", "matches_fisheye.png", "matches_frontend.png"}) {
    EXPECT_TRUE(std::filesystem::exists(options.out_dir + "/" + name)) << name;
  }
}

}  // namespace
}  // namespace rovo
