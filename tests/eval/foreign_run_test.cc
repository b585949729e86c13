// Other systems' trajectories as runs: format detection, KITTI by line, start-time shift.
#include "eval/foreign_run.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "datasets/io.h"
#include "eval/metrics.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

class ForeignRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / ("rovo_foreign_run_" + std::to_string(::getpid()))).string();
    fs::create_directories(dir_);
    for (int i = 0; i < 10; ++i) {
      gt_.push_back({0.1 * i, Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitZ())),
                                     Eigen::Vector3d(i, 0.1 * i * i, 0))});
    }
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
  Trajectory gt_;
};

TEST_F(ForeignRunTest, KittiPosesAreMatchedByLineAndScoreZero) {
  WriteKitti(dir_ + "/poses.txt", gt_);
  std::string note;
  const RunData run = ReadRunOrTrajectory(dir_, gt_, "auto", &note);  // the folder holds one file
  EXPECT_NE(note.find("KITTI"), std::string::npos) << note;
  EXPECT_EQ(run.info["mode"], "external");
  ASSERT_EQ(run.trajectory.size(), gt_.size());
  const RunEvaluation e = EvaluateRun(gt_, {Rigid3()}, run, "kitti");
  EXPECT_EQ(e.metrics.associated_frames, 10);
  ASSERT_TRUE(e.metrics.rmse_se3_m.has_value());
  EXPECT_LT(*e.metrics.rmse_se3_m, 1e-9);
}

// A EuRoC-epoch trajectory against a dataset starting at 0: shifted onto the first gt time, every
// second frame (half the frame rate) associated, the others missing.
TEST_F(ForeignRunTest, AnotherStartTimeIsShiftedAndAnotherRateMatchesNearest) {
  std::string text;
  for (size_t i = 0; i < gt_.size(); i += 2) {
    const Eigen::Vector3d& p = gt_[i].world_from_rig.translation;
    const Eigen::Quaterniond& q = gt_[i].world_from_rig.rotation;
    text += std::to_string(1403636579763555584LL + static_cast<long long>(i) * 100000000LL) + "," +
            std::to_string(p.x()) + "," + std::to_string(p.y()) + "," + std::to_string(p.z()) + "," +
            std::to_string(q.w()) + "," + std::to_string(q.x()) + "," + std::to_string(q.y()) + "," +
            std::to_string(q.z()) + "\n";
  }
  WriteFileAtomic(dir_ + "/estimate.csv", "#timestamp [ns],px,py,pz,qw,qx,qy,qz\n" + text);
  std::string note;
  const RunData run = ReadRunOrTrajectory(dir_ + "/estimate.csv", gt_, "auto", &note);
  EXPECT_NE(note.find("shifted"), std::string::npos) << note;
  EXPECT_NEAR(run.trajectory.front().timestamp, 0.0, 1e-6);
  const RunEvaluation e = EvaluateRun(gt_, {Rigid3()}, run, "euroc");
  EXPECT_EQ(e.metrics.associated_frames, 5);
  EXPECT_EQ(e.metrics.missing_frames, 5);
  EXPECT_LT(*e.metrics.rmse_se3_m, 1e-5);
}

TEST_F(ForeignRunTest, AmbiguousFolderAndUnknownLayoutAreErrors) {
  WriteFileAtomic(dir_ + "/trajectory.txt", "0 1 2 3 0 0 0 1\n");
  WriteFileAtomic(dir_ + "/poses.txt", "1 0 0 1 0 1 0 2 0 0 1 3\n");
  EXPECT_THROW(ReadRunOrTrajectory(dir_, gt_), std::runtime_error);
  WriteFileAtomic(dir_ + "/odd.txt", "0 1 2 3 4\n");
  EXPECT_THROW(ReadRunOrTrajectory(dir_ + "/odd.txt", gt_), std::runtime_error);
}

}  // namespace
}  // namespace rovo
