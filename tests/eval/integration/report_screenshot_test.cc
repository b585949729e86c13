// `rovo eval` on a synthetic dataset and runs, then report.html rendered by headless Chromium: the
// screenshot must exist and show content (not a blank page).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/run.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

int RunCommand(const std::string& command, std::string* output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output->append(buffer.data(), n);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ReportScreenshot, HeadlessChromiumRendersTheReport) {
  const fs::path root = fs::temp_directory_path() / ("rovo_report_shot_" + std::to_string(::getpid()));
  fs::remove_all(root);
  const std::string dataset = (root / "dataset").string();
  DatasetInfo info;
  info.generator_version = "test";
  info.seed = 1;
  info.frame_count = 80;
  info.rig = MakeRigPreset("rovo4");
  info.perturbed.push_back(PerturbExtrinsics(info.rig, 5.0, 0.0, 9));
  WriteDatasetInfo(dataset, info);
  Trajectory gt;
  for (int i = 0; i < 80; ++i) {
    gt.push_back({i * 0.1, Rigid3(QuaternionFromRollPitchYawDeg(0, 0, 20 * std::sin(i * 0.05)),
                                  Eigen::Vector3d(i, 10 * std::sin(i * 0.05), 0.05 * i))});
  }
  WriteTum(GroundTruthPath(dataset), gt);

  std::vector<std::string> runs;
  const std::vector<std::pair<std::string, double>> modes = {{"gt", 0.02}, {"noisy", 1.0}, {"online", 0.1}};
  for (const auto& [mode, noise] : modes) {
    RunData run;
    run.info = {{"mode", mode}, {"dataset", dataset}, {"seed", 0}};
    for (int i = 0; i < 80; ++i) {
      StampedPose p = gt[static_cast<size_t>(i)];
      p.world_from_rig.translation += noise * Eigen::Vector3d(std::sin(i * 0.3), std::cos(i * 0.2), 0.1 * (i % 3));
      run.trajectory.push_back(p);
      run.frames.push_back({i, i * 0.1, 300, 180 - i % 20, (180.0 - i % 20) / 300.0, 0.1 + 0.01 * (i % 5), i % 5 == 0,
                            FrameStatus::kOk, 30.0, ""});
      // Online: extrinsics converge from the perturbed set to the ground truth over the sequence.
      for (int c = 0; c < 4; ++c) {
        const Rigid3& truth = info.rig.cameras[static_cast<size_t>(c)].cam_from_rig;
        const Rigid3& start = info.perturbed[0].cam_from_rig[static_cast<size_t>(c)];
        const double alpha = mode == "online" ? std::min(1.0, i / 40.0) : (mode == "gt" ? 1.0 : 0.0);
        run.extrinsics.push_back({i, i * 0.1, c, Interpolate(start, truth, alpha)});
      }
    }
    runs.push_back((root / mode).string());
    WriteRun(runs.back(), run);
  }

  const std::string report = (root / "report").string();
  std::string command = std::string(ROVO_BINARY) + " eval " + dataset;
  for (const std::string& r : runs) command += " " + r;
  command += " --out " + report + " --kitti";
  std::string output;
  ASSERT_EQ(RunCommand(command, &output), 0) << output;
  EXPECT_NE(output.find("| gt | gt |"), std::string::npos) << output;
  ASSERT_TRUE(fs::is_regular_file(report + "/report.html"));

  const std::string png = (root / "shot.png").string();
  const std::string profile = (root / "chromium-profile").string();
  output.clear();
  const int status = RunCommand(
      "chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking "
      "--disable-component-update --disable-sync --user-data-dir=" +
          profile + " --screenshot=" + png + " --window-size=1280,2000 file://" +
          fs::absolute(report + "/report.html").string(),
      &output);
  ASSERT_EQ(status, 0) << output;
  ASSERT_TRUE(fs::is_regular_file(png)) << output;
  const cv::Mat image = cv::imread(png, cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 1280);
  EXPECT_EQ(image.rows, 2000);
  // Not blank: a good share of non-white pixels (text, table borders, plots) and real contrast.
  const double non_white = static_cast<double>(cv::countNonZero(image < 200)) / image.total();
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  EXPECT_GT(non_white, 0.02) << "screenshot looks blank";
  EXPECT_GT(stddev[0], 20.0);
  // The plots made it into the page (python3 + matplotlib are Debian dependencies of the project).
  EXPECT_NE(ReadFile(report + "/report.html").find("data:image/png;base64,"), std::string::npos);
  fs::remove_all(root);
}

}  // namespace
}  // namespace rovo
