// End to end OnlineExt: render a short cloudy_urban sequence, run `rovo vo --extrinsics online` from
// the most perturbed noise set twice with two threads, and check that (a) the runs are identical
// byte for byte (determinism for a fixed seed and thread count), the start-up calibration (its ring
// pairs and joint starts solved in parallel) the same as on one thread, and (b) the start-up calibration and
// the online BA bring every camera's rotation relative to camera 0 from degrees off to within a
// fraction of a degree of the ground truth.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/run.h"

namespace rovo {
namespace {

namespace fs = std::filesystem;

int RunCommand(const std::string& command) { return std::system(command.c_str()); }

double RelativeRotationErrorDeg(const std::vector<Rigid3>& estimate, const std::vector<Rigid3>& truth, size_t j) {
  const Eigen::Quaterniond est = estimate[j].rotation * estimate[0].rotation.conjugate();
  const Eigen::Quaterniond gt = truth[j].rotation * truth[0].rotation.conjugate();
  return RotationDistanceDeg(est, gt);
}

TEST(PipelineIntegration, OnlineCalibrationIsDeterministicAndConverges) {
  const fs::path root = fs::temp_directory_path() / "rovo_vo_online_test";
  fs::remove_all(root);
  const std::string dataset = (root / "dataset").string();
  constexpr int kFrames = 25;
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " render --preset cloudy_urban --quick --frames 0:" +
                       std::to_string(kFrames) + " --quiet --out " + dataset),
            0);
  const DatasetInfo info = ReadDatasetInfo(dataset);
  const std::vector<Rigid3> truth = info.rig.Extrinsics();
  // The noise set whose largest relative rotation error is largest.
  int noise_set = 0;
  double worst = 0.0;
  for (size_t k = 0; k < info.perturbed.size(); ++k) {
    for (size_t j = 1; j < truth.size(); ++j) {
      const double e = RelativeRotationErrorDeg(info.perturbed[k].cam_from_rig, truth, j);
      if (e > worst) {
        worst = e;
        noise_set = static_cast<int>(k);
      }
    }
  }
  ASSERT_GT(worst, 5.0);

  std::string runs[2];
  for (int r = 0; r < 2; ++r) {
    runs[r] = (root / ("run" + std::to_string(r))).string();
    ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics online --noise-set " +
                         std::to_string(noise_set) + " --threads 2 --quiet --out " + runs[r]),
              0);
  }
  for (const char* file : {"trajectory.tum", "extrinsics.csv"}) {
    EXPECT_EQ(ReadFile(runs[0] + "/" + file), ReadFile(runs[1] + "/" + file)) << file << " differs between runs";
  }
  const std::string serial = (root / "serial").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics online --noise-set " +
                       std::to_string(noise_set) + " --threads 1 --quiet --out " + serial),
            0);
  const auto startup_result = [](const std::string& run_dir) {
    nlohmann::json startup = ReadRun(run_dir).info.at("startup_calibration");
    startup.erase("ms");
    startup.erase("cpu_ms");
    return startup.dump();
  };
  EXPECT_EQ(startup_result(runs[0]), startup_result(serial)) << "the start-up calibration depends on the threads";

  const RunData run = ReadRun(runs[0]);
  ASSERT_EQ(run.frames.size(), static_cast<size_t>(kFrames));
  int ok = 0;
  for (const FrameRecord& f : run.frames) ok += f.status == FrameStatus::kOk;
  EXPECT_GE(ok, kFrames - 2);
  // After the start-up calibration (frame 0) the error is a fraction of a degree: one frame pins the
  // relative yaw only through far points, so a few tenths may remain (up to 0.43 deg seen); the online
  // BA then removes it with the rig's motion (below 0.1 deg at frame 24 in our runs).
  for (const auto& [frame, bound_deg] : {std::pair<int, double>{0, 1.0}, {kFrames - 1, 0.2}}) {
    std::vector<Rigid3> estimate(truth.size());
    for (const ExtrinsicsRecord& e : run.extrinsics) {
      if (e.frame == frame) estimate[e.camera] = e.cam_from_rig;
    }
    for (size_t j = 1; j < truth.size(); ++j) {
      EXPECT_LT(RelativeRotationErrorDeg(estimate, truth, j), bound_deg)
          << "camera " << j << " at frame " << frame << " (started " << worst << " deg off at worst)";
    }
  }

  // Poor overlaps ask for more shots: with one shot and an inlier floor no pair reaches, the start-up
  // runs again on every shot the frames allow (--online-startup-max-shots) and says why; at the
  // default floor this scene's overlaps are rich, so the default run above kept its three shots.
  // The start-up record of a `rovo vo` run of this dataset with `flags`, into root/name.
  const auto startup_of = [&](const std::string& name, const std::string& flags) {
    const std::string out = (root / name).string();
    EXPECT_EQ(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --extrinsics online --noise-set " +
                         std::to_string(noise_set) + " " + flags + " --threads 2 --quiet --out " + out),
              0);
    return ReadRun(out).info.at("startup_calibration");
  };
  const nlohmann::json more_startup =
      startup_of("more_shots",
                 "--frames 0:5 --online-startup-shots 1 --online-startup-spacing 2 --online-startup-max-shots 3"
                 " --online-startup-min-inliers 1000000");
  EXPECT_EQ(more_startup.at("first_shots"), nlohmann::json({0}));
  EXPECT_EQ(more_startup.at("shots"), nlohmann::json({0, 2, 4}));
  EXPECT_NE(more_startup.at("more_shots_reason").get<std::string>().find("(< 1000000)"), std::string::npos);
  EXPECT_TRUE(more_startup.at("converged").get<bool>());
  // Without a frame for another shot the first attempt stands and says so.
  const nlohmann::json last_startup =
      startup_of("no_frame_left", "--frames 0:2 --online-startup-shots 1 --online-startup-min-inliers 1000000");
  EXPECT_EQ(last_startup.at("shots"), nlohmann::json({0}));
  EXPECT_TRUE(last_startup.at("first_shots").empty());
  EXPECT_NE(last_startup.at("more_shots_reason").get<std::string>().find("no frame left"), std::string::npos);
  const nlohmann::json default_startup = run.info.at("startup_calibration");
  EXPECT_EQ(default_startup.at("shots"), nlohmann::json({0, 10, 20}));
  EXPECT_EQ(default_startup.at("more_shots_reason"), "");
  fs::remove_all(root);
}

// The keyframe BA beside the next frame's front-end (default) gives the same GTExt run, byte for
// byte, as the BA run before it (--sync-ba): the back-end state is only touched once the BA is joined.
TEST(PipelineIntegration, AsyncBaMatchesSynchronousBa) {
  const fs::path root = fs::temp_directory_path() / "rovo_vo_async_ba_test";
  fs::remove_all(root);
  const std::string dataset = (root / "dataset").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " render --preset cloudy_urban --quick --frames 0:12 --quiet --out " +
                       dataset),
            0);
  const std::string async_run = (root / "async").string(), sync_run = (root / "sync").string();
  ASSERT_EQ(RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --threads 2 --quiet --out " + async_run), 0);
  ASSERT_EQ(
      RunCommand(std::string(ROVO_BINARY) + " vo " + dataset + " --threads 2 --sync-ba --quiet --out " + sync_run), 0);
  EXPECT_EQ(ReadFile(async_run + "/trajectory.tum"), ReadFile(sync_run + "/trajectory.tum"));
  const RunData a = ReadRun(async_run), b = ReadRun(sync_run);
  ASSERT_EQ(a.frames.size(), 12u);
  ASSERT_EQ(b.frames.size(), 12u);
  int keyframes = 0;
  for (size_t i = 0; i < a.frames.size(); ++i) {
    EXPECT_EQ(a.frames[i].status, b.frames[i].status);
    EXPECT_EQ(a.frames[i].num_inliers, b.frames[i].num_inliers) << "frame " << i;
    keyframes += a.frames[i].keyframe;
  }
  EXPECT_GE(keyframes, 3);  // BAs did run
  fs::remove_all(root);
}

}  // namespace
}  // namespace rovo
