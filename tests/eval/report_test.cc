// EvaluateAndReport over a synthetic dataset (dataset.json + groundtruth.tum, no images) and runs.
#include "eval/report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/run.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = (fs::temp_directory_path() / ("rovo_report_test_" + std::to_string(::getpid()))).string();
    fs::remove_all(root_);
    dataset_ = root_ + "/dataset";
    fs::create_directories(dataset_);
    DatasetInfo info;
    info.generator_version = "test";
    info.seed = 11;
    info.preset = "cloudy_urban";
    info.frame_rate = 10.0;
    info.frame_count = 50;
    info.rig = MakeRigPreset("rovo4");
    info.perturbed.push_back(PerturbExtrinsics(info.rig, 5.0, 0.0, 3));
    WriteDatasetInfo(dataset_, info);
    // A gentle S-curve at 1 m per frame, with some height change.
    for (int i = 0; i < 50; ++i) {
      const double yaw = 0.3 * std::sin(i * 0.1);
      gt_.push_back({i * 0.1, Rigid3(QuaternionFromRollPitchYawDeg(0, 0, yaw * 180 / M_PI),
                                     Eigen::Vector3d(i, 5.0 * std::sin(i * 0.1), 0.02 * i))});
    }
    WriteTum(GroundTruthPath(dataset_), gt_);
    gt_ext_ = info.rig.Extrinsics();
    noisy_ext_ = info.perturbed[0].cam_from_rig;
  }
  void TearDown() override { fs::remove_all(root_); }

  // A run whose trajectory is the gt in another world frame plus `noise` m of alternating error,
  // without frame `skip`.
  std::string MakeRun(const std::string& name, const std::string& mode, double noise, int skip,
                      const std::vector<Rigid3>& extrinsics) {
    RunData run;
    run.info = {{"mode", mode}, {"dataset", dataset_}, {"seed", 5}, {"noise_set", 0}};
    const Rigid3 est_from_gt = Rigid3::FromAxisAngle(Eigen::Vector3d(0, 0, 1.0), Eigen::Vector3d(3, 2, 1));
    for (int i = 0; i < 50; ++i) {
      FrameRecord f;
      f.frame = i;
      f.timestamp = i * 0.1;
      f.num_correspondences = 200;
      f.num_inliers = i == skip ? 0 : 120;
      f.inlier_ratio = f.num_inliers / 200.0;
      f.mean_reproj_error_deg = i == skip ? 0.0 : 0.15;
      f.status = i == skip ? FrameStatus::kLost : FrameStatus::kOk;
      f.time_ms = 20.0;
      run.frames.push_back(f);
      for (int c = 0; c < 4; ++c) run.extrinsics.push_back({i, i * 0.1, c, extrinsics[static_cast<size_t>(c)]});
      if (i == skip) continue;
      StampedPose p = gt_[static_cast<size_t>(i)];
      p.world_from_rig = est_from_gt * p.world_from_rig;
      p.world_from_rig.translation.z() += (i % 2 ? noise : -noise);
      run.trajectory.push_back(p);
    }
    const std::string dir = root_ + "/" + name;
    WriteRun(dir, run);
    return dir;
  }

  std::string root_, dataset_;
  Trajectory gt_;
  std::vector<Rigid3> gt_ext_, noisy_ext_;
};

TEST_F(ReportTest, WritesMetricsTablesCsvsAndKitti) {
  const std::string gt_run = MakeRun("gt", "gt", 0.01, 7, gt_ext_);
  const std::string noisy_run = MakeRun("noisy_0", "noisy", 0.5, -1, noisy_ext_);
  EvalReportOptions options;
  options.kitti = true;
  options.plots = false;
  options.quiet = true;
  const std::string out = root_ + "/report";
  const std::vector<RunEvaluation> evaluations = EvaluateAndReport(dataset_, {gt_run, noisy_run}, out, options);
  ASSERT_EQ(evaluations.size(), 2u);
  const RunMetrics& gt = evaluations[0].metrics;
  EXPECT_EQ(gt.label, "gt");
  EXPECT_EQ(gt.missing_frames, 1);
  EXPECT_EQ(gt.associated_frames, 49);
  ASSERT_TRUE(gt.rmse_se3_m.has_value());
  EXPECT_NEAR(*gt.rmse_se3_m, 0.01, 2e-3);
  EXPECT_NEAR(gt.max_final_ext_rotation_deg, 0.0, 1e-9);
  const RunMetrics& noisy = evaluations[1].metrics;
  EXPECT_NEAR(*noisy.rmse_se3_m, 0.5, 0.1);
  EXPECT_GT(noisy.max_final_ext_rotation_deg, 1.0);  // sigma 5 deg perturbation, relative to cam 0

  const nlohmann::json metrics = ReadJsonFile(out + "/metrics.json");
  EXPECT_EQ(metrics["dataset_seed"], 11);
  ASSERT_EQ(metrics["runs"].size(), 2u);
  EXPECT_EQ(metrics["runs"][1]["run_seed"], 5);
  const RunMetrics back = MetricsFromJson(metrics["runs"][1], "metrics.json");
  EXPECT_EQ(back.mode, "noisy");
  EXPECT_DOUBLE_EQ(*back.rmse_se3_m, *noisy.rmse_se3_m);
  EXPECT_THROW(MetricsFromJson(nlohmann::json::object(), "x"), std::runtime_error);

  const std::string table = ReadFile(out + "/table.md");
  EXPECT_NE(table.find("| gt | gt |"), std::string::npos) << table;
  EXPECT_NE(table.find("Umeyama"), std::string::npos);
  for (const char* f : {"/summary.csv", "/groundtruth.csv", "/gt/errors.csv", "/gt/frames.csv",
                        "/gt/extrinsic_errors.csv", "/gt/kitti_estimate.txt", "/gt/kitti_groundtruth.txt"}) {
    EXPECT_TRUE(fs::is_regular_file(out + f)) << f;
  }
  // KITTI: one line of 12 numbers per associated frame.
  const std::string kitti = ReadFile(out + "/gt/kitti_estimate.txt");
  EXPECT_EQ(std::count(kitti.begin(), kitti.end(), '\n'), 49);
  // Extrinsic errors: 3 cameras x 50 frames plus the header.
  const std::string ext = ReadFile(out + "/noisy_0/extrinsic_errors.csv");
  EXPECT_EQ(std::count(ext.begin(), ext.end(), '\n'), 151);
}

TEST_F(ReportTest, PlotsAndHtmlWhenMatplotlibIsThere) {
  const std::string online = MakeRun("online_0", "online", 0.05, -1, gt_ext_);
  EvalReportOptions options;
  options.quiet = true;
  const std::string out = root_ + "/report_plots";
  EvaluateAndReport(dataset_, {online}, out, options);
  const std::string html = ReadFile(out + "/report.html");
  EXPECT_NE(html.find("<table>"), std::string::npos);
  if (std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0) {
    for (const char* png : {"trajectories.png", "extrinsics.png", "frames.png", "error_along_path.png"}) {
      EXPECT_TRUE(fs::is_regular_file(out + "/plots/" + png)) << png;
    }
    EXPECT_NE(html.find("data:image/png;base64,iVBORw0KGgo"), std::string::npos);
  } else {
    EXPECT_NE(html.find("No plots"), std::string::npos);
  }
}

TEST_F(ReportTest, MalformedRunNamesTheFile) {
  const std::string run = MakeRun("bad", "gt", 0.0, -1, gt_ext_);
  WriteFileAtomic(RunFramesPath(run), "frame,timestamp\n1,2\n");
  try {
    EvaluateAndReport(dataset_, {run}, root_ + "/r", EvalReportOptions{});
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad/frames.csv:1: bad header"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rovo
