// `rovo dataset export` checked by an independent reader (exchange_check.py: PyYAML + numpy, the
// double-sphere projection from its paper, EuRoC's documented ground-truth columns), the round
// trip export -> import, and `rovo eval` on other systems' trajectory formats.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "datasets/trajectory.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

int RunShell(const std::string& command, const std::string& log) {
  const int status = std::system((command + " > " + log + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class ExchangeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = (fs::temp_directory_path() / ("rovo_exchange_" + std::to_string(::getpid()))).string();
    fs::create_directories(root_);
    // Three frames of the quick cloudy_urban preset (rovo4 ocam lenses at the quick scale).
    const std::string command = std::string(ROVO_BINARY) +
                                " render --preset cloudy_urban --quick --frames 0:3 --spp 1 "
                                "--quiet --out " +
                                Dataset();
    ASSERT_EQ(RunShell(command, root_ + "/render.log"), 0) << ReadFile(root_ + "/render.log");
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static std::string Dataset() { return root_ + "/dataset"; }

  // Exports, then runs the independent Python reader on the result.
  static void ExportAndCheck(const std::string& format, const std::string& extra, const std::string& out) {
    const std::string log = root_ + "/export_" + format + ".log";
    ASSERT_EQ(RunShell(std::string(ROVO_BINARY) + " dataset export " + Dataset() + " --format " + format + " --out " +
                           out + " " + extra,
                       log),
              0)
        << ReadFile(log);
    EXPECT_NE(ReadFile(log).find("max error"), std::string::npos);
    const std::string check_log = root_ + "/check_" + format + ".log";
    ASSERT_EQ(RunShell("/usr/bin/python3 " + std::string(ROVO_SOURCE_DIR) +
                           "/tests/datasets/integration/exchange_check.py " + out + " " + Dataset() + " " + format,
                       check_log),
              0)
        << ReadFile(check_log);
  }

  // Import of an export equals the original: images, poses, extrinsics, perturbed sets; lenses
  // within the reported fit error.
  static void CheckRoundTrip(const std::string& exported, const std::string& format, bool with_perturbed = true) {
    const std::string imported = root_ + "/imported_" + format;
    const std::string log = root_ + "/import_" + format + ".log";
    ASSERT_EQ(RunShell(std::string(ROVO_BINARY) + " dataset import " + exported + " --format " + format + " --out " +
                           imported,
                       log),
              0)
        << ReadFile(log);
    const DatasetInfo a = ReadDatasetInfo(Dataset()), b = ReadDatasetInfo(imported);
    EXPECT_TRUE(ValidateDataset(imported).empty()) << ReadFile(log);
    ASSERT_EQ(a.frame_count, b.frame_count);
    ASSERT_EQ(a.rig.NumCameras(), b.rig.NumCameras());
    EXPECT_NEAR(a.frame_rate, b.frame_rate, 1e-6);
    const Trajectory gt_a = ReadTum(GroundTruthPath(Dataset())), gt_b = ReadTum(GroundTruthPath(imported));
    ASSERT_EQ(gt_a.size(), gt_b.size());
    for (size_t i = 0; i < gt_a.size(); ++i) {
      EXPECT_NEAR(gt_a[i].timestamp, gt_b[i].timestamp, 1e-9);
      EXPECT_LT((gt_a[i].world_from_rig.translation - gt_b[i].world_from_rig.translation).norm(), 1e-9);
      EXPECT_LT(gt_a[i].world_from_rig.rotation.angularDistance(gt_b[i].world_from_rig.rotation), 1e-9);
    }
    const nlohmann::json report = ReadJsonFile(exported + "/rovo_export.json");
    for (int k = 0; k < a.rig.NumCameras(); ++k) {
      const RigCamera &ca = a.rig.cameras[k], &cb = b.rig.cameras[k];
      EXPECT_LT((ca.cam_from_rig.translation - cb.cam_from_rig.translation).norm(), 1e-9);
      EXPECT_LT(ca.cam_from_rig.rotation.angularDistance(cb.cam_from_rig.rotation), 1e-9);
      EXPECT_EQ(ca.camera.max_fov_deg, cb.camera.max_fov_deg);
      for (int f = 0; f < a.frame_count; ++f) {
        EXPECT_EQ(ReadFile(ImagePath(Dataset(), ca.name, f)), ReadFile(ImagePath(imported, cb.name, f)));
      }
      // The imported lens projects like the original within the reported fit error.
      const double bound = report["fits"][k]["max_error_px"].get<double>();
      double worst = 0.0;
      for (double angle = 0; angle <= 0.5 * ca.camera.max_fov_deg; angle += 1.0) {
        for (double azimuth = 0; azimuth < 360; azimuth += 7.5) {
          const double t = angle * M_PI / 180, p = azimuth * M_PI / 180;
          const Eigen::Vector3d bearing(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
          const auto uv_a = ca.camera.Project(bearing);
          if (!uv_a || !ca.camera.InImage(*uv_a)) continue;
          const auto uv_b = cb.camera.Project(bearing);
          ASSERT_TRUE(uv_b.has_value()) << "angle " << angle;
          worst = std::max(worst, (*uv_a - *uv_b).norm());
        }
      }
      EXPECT_LE(worst, bound * 1.05 + 1e-6) << ca.name;
    }
    if (!with_perturbed) {  // EuRoC's sensor.yaml files carry one extrinsic set
      EXPECT_TRUE(b.perturbed.empty());
      return;
    }
    ASSERT_FALSE(a.perturbed.empty());
    ASSERT_EQ(a.perturbed.size(), b.perturbed.size());
    for (size_t s = 0; s < a.perturbed.size(); ++s) {
      EXPECT_EQ(a.perturbed[s].seed, b.perturbed[s].seed);
      EXPECT_DOUBLE_EQ(a.perturbed[s].sigma_rotation_deg, b.perturbed[s].sigma_rotation_deg);
      for (size_t k = 0; k < a.perturbed[s].cam_from_rig.size(); ++k) {
        EXPECT_LT(a.perturbed[s].cam_from_rig[k].rotation.angularDistance(b.perturbed[s].cam_from_rig[k].rotation),
                  1e-9);
      }
    }
  }

  static std::string root_;
};
std::string ExchangeTest::root_;

TEST_F(ExchangeTest, KalibrDoubleSphereExportPassesTheIndependentReaderAndRoundTrips) {
  const std::string out = root_ + "/kalibr";
  ExportAndCheck("kalibr", "--model ds --keep-color", out);
  EXPECT_TRUE(fs::exists(out + "/camchain-perturbed-0.yaml") || ReadDatasetInfo(Dataset()).perturbed.empty());
  CheckRoundTrip(out, "kalibr");
}

TEST_F(ExchangeTest, BasaltExportPassesTheIndependentReaderAndRoundTrips) {
  const std::string out = root_ + "/basalt";
  ExportAndCheck("basalt", "--keep-color", out);
  CheckRoundTrip(out, "basalt");
}

TEST_F(ExchangeTest, EurocExportPassesTheIndependentReaderAndRoundTrips) {
  const std::string out = root_ + "/euroc";
  ExportAndCheck("euroc", "--keep-color", out);
  CheckRoundTrip(out, "euroc", false);
}

// --cameras 3,1: two cameras, renumbered cam0 = dataset cam3, cam1 = dataset cam1, in every file (the
// independent reader checks lenses, extrinsics and images against the mapped dataset cameras), grey
// images by default (the reader decodes the PNGs itself and recomputes the luminance).
TEST_F(ExchangeTest, CameraSubsetWithGreyImagesPassesTheIndependentReader) {
  for (const std::string format : {"basalt", "euroc"}) {
    const std::string out = root_ + "/subset_" + format;
    ExportAndCheck(format, "--cameras 3,1", out);
    EXPECT_TRUE(fs::exists(out + "/mav0/cam1/data.csv"));
    EXPECT_FALSE(fs::exists(out + "/mav0/cam2"));
    const nlohmann::json report = ReadJsonFile(out + "/rovo_export.json");
    ASSERT_EQ(report["cameras"].size(), 2u);
    EXPECT_EQ(report["cameras"][0]["source_name"], "cam3");
    EXPECT_EQ(report["cameras"][1]["source_index"], 1);
  }
  const nlohmann::json basalt = ReadJsonFile(root_ + "/subset_basalt/calibration.json");
  EXPECT_EQ(basalt["value0"]["T_imu_cam"].size(), 2u);
  if (!ReadDatasetInfo(Dataset()).perturbed.empty()) {
    EXPECT_EQ(ReadJsonFile(root_ + "/subset_basalt/calibration-perturbed-0.json")["value0"]["T_imu_cam"].size(), 2u);
  }
  const std::string log = root_ + "/bad_subset.log";
  EXPECT_EQ(RunShell(std::string(ROVO_BINARY) + " dataset export " + Dataset() + " --cameras 0,7 --out " + root_ +
                         "/bad_subset",
                     log),
            1);
  EXPECT_NE(ReadFile(log).find("--cameras"), std::string::npos) << ReadFile(log);
  EXPECT_NE(ReadFile(log).find("camera 7 does not exist"), std::string::npos) << ReadFile(log);
}

TEST_F(ExchangeTest, ExportRefusesAFitWorseThanTheBound) {
  const std::string log = root_ + "/refuse.log";
  EXPECT_EQ(RunShell(std::string(ROVO_BINARY) + " dataset export " + Dataset() + " --format kalibr --model ds " +
                         "--max-fit-error 0.01 --out " + root_ + "/refused",
                     log),
            1);
  EXPECT_NE(ReadFile(log).find("more than the bound"), std::string::npos) << ReadFile(log);
}

// `rovo eval` scores another system's trajectory: TUM with nanosecond timestamps and a EuRoC csv.
TEST_F(ExchangeTest, EvalScoresTumNanosecondsAndEurocCsv) {
  const Trajectory gt = ReadTum(GroundTruthPath(Dataset()));
  std::string tum_ns = "# timestamp[ns] tx ty tz qx qy qz qw\n";
  for (const StampedPose& p : gt) {
    const Eigen::Vector3d t = p.world_from_rig.translation + Eigen::Vector3d(5, -3, 1);  // another world origin
    const Eigen::Quaterniond& q = p.world_from_rig.rotation;
    char line[256];
    std::snprintf(line, sizeof(line), "%lld %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n",
                  static_cast<long long>(std::llround(p.timestamp * 1e9)), t.x(), t.y(), t.z(), q.x(), q.y(), q.z(),
                  q.w());
    tum_ns += line;
  }
  WriteFileAtomic(root_ + "/other/stamped_traj_estimate.txt", tum_ns);
  const std::string euroc = root_ + "/euroc_estimate";
  ASSERT_EQ(RunShell(std::string(ROVO_BINARY) + " dataset export " + Dataset() + " --format euroc --out " + euroc,
                     root_ + "/e.log"),
            0);
  const std::string log = root_ + "/eval.log";
  ASSERT_EQ(RunShell(std::string(ROVO_BINARY) + " eval " + Dataset() + " " + root_ + "/other " + euroc +
                         "/mav0/state_groundtruth_estimate0/data.csv --no-plots --out " + root_ + "/report",
                     log),
            0)
      << ReadFile(log);
  const std::string text = ReadFile(log);
  EXPECT_NE(text.find("nanoseconds"), std::string::npos) << text;
  EXPECT_NE(text.find("EuRoC csv"), std::string::npos) << text;
  const nlohmann::json metrics = ReadJsonFile(root_ + "/report/metrics.json");
  const std::string dump = metrics.dump();
  ASSERT_NE(dump.find("external"), std::string::npos) << dump;
  int runs = 0;
  for (const nlohmann::json& run : metrics["runs"]) {
    ++runs;
    EXPECT_EQ(run["associated_frames"].get<int>(), static_cast<int>(gt.size())) << run.dump();
    EXPECT_LT(run["rmse_se3_m"].get<double>(), 1e-6) << run.dump();
  }
  EXPECT_EQ(runs, 2);
  EXPECT_NE(ReadFile(root_ + "/report/table.md").find("n/a"), std::string::npos);
}

}  // namespace
}  // namespace rovo
