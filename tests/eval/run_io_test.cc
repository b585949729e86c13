#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "datasets/io.h"
#include "datasets/run.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

class RunIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() /
            ("rovo_run_io_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name()))
               .string();
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static RunData SampleRun() {
    RunData run;
    run.info = {{"mode", "online"}, {"dataset", "/data/x"}, {"seed", 7}, {"noise_set", 1}};
    for (int i = 0; i < 3; ++i) {
      run.trajectory.push_back({0.1 * i, Rigid3::FromAxisAngle(Eigen::Vector3d(0.01 * i, 0.2, -0.1),
                                                               Eigen::Vector3d(i * 1.1, 1.0 / 3.0, -2.0))});
      FrameRecord f;
      f.frame = i;
      f.timestamp = 0.1 * i;
      f.num_correspondences = 300 + i;
      f.num_inliers = 150;
      f.inlier_ratio = 150.0 / (300 + i);
      f.mean_reproj_error_deg = 0.123456789;
      f.keyframe = i % 2 == 0;
      f.status = i == 1 ? FrameStatus::kLost : FrameStatus::kOk;
      f.time_ms = 12.5;
      run.frames.push_back(f);
      for (int c = 0; c < 2; ++c) {
        run.extrinsics.push_back(
            {i, 0.1 * i, c, Rigid3::FromAxisAngle(Eigen::Vector3d(0.3 * c, -0.1, 0.7), Eigen::Vector3d(c, 0.1, 1e-7))});
      }
    }
    return run;
  }

  void ReplaceLine(const std::string& path, int line_number, const std::string& text) {
    std::string content = ReadFile(path), out;
    std::istringstream in(content);
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) out += (n == line_number ? text : line) + "\n";
    std::ofstream(path) << out;
  }

  std::string ErrorOf(const std::string& run_dir) {
    try {
      ReadRun(run_dir);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  std::string dir_;
};

TEST_F(RunIoTest, RoundTripIsExact) {
  const RunData run = SampleRun();
  WriteRun(dir_, run);
  const RunData back = ReadRun(dir_);
  ASSERT_EQ(back.frames.size(), 3u);
  ASSERT_EQ(back.extrinsics.size(), 6u);
  ASSERT_EQ(back.trajectory.size(), 3u);
  EXPECT_EQ(back.info, run.info);
  for (size_t i = 0; i < 3; ++i) {
    const FrameRecord &a = run.frames[i], &b = back.frames[i];
    EXPECT_EQ(a.frame, b.frame);
    EXPECT_EQ(a.timestamp, b.timestamp);
    EXPECT_EQ(a.num_correspondences, b.num_correspondences);
    EXPECT_EQ(a.num_inliers, b.num_inliers);
    EXPECT_EQ(a.inlier_ratio, b.inlier_ratio);
    EXPECT_EQ(a.mean_reproj_error_deg, b.mean_reproj_error_deg);
    EXPECT_EQ(a.keyframe, b.keyframe);
    EXPECT_EQ(a.status, b.status);
    EXPECT_EQ(a.time_ms, b.time_ms);
  }
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(run.extrinsics[i].camera, back.extrinsics[i].camera);
    EXPECT_EQ(run.extrinsics[i].cam_from_rig.rotation.coeffs(), back.extrinsics[i].cam_from_rig.rotation.coeffs());
    EXPECT_EQ(run.extrinsics[i].cam_from_rig.translation, back.extrinsics[i].cam_from_rig.translation);
  }
  // Header lines as documented.
  const std::string ext = ReadFile(RunExtrinsicsPath(dir_));
  EXPECT_EQ(ext.substr(0, ext.find('\n')), "frame,timestamp,camera,qx,qy,qz,qw,tx,ty,tz");
  const std::string frames = ReadFile(RunFramesPath(dir_));
  EXPECT_EQ(
      frames.substr(0, frames.find('\n')),
      "frame,timestamp,num_correspondences,num_inliers,inlier_ratio,mean_reproj_error_deg,keyframe,status,time_ms,"
      "missing_cameras");
  // No temporary files left behind.
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos) << entry.path();
  }
}

TEST_F(RunIoTest, BadNumberNamesFileLineAndColumn) {
  WriteRun(dir_, SampleRun());
  ReplaceLine(RunFramesPath(dir_), 3, "1,0.1,301,150,abc,0.1,0,ok,12.5,");
  const std::string error = ErrorOf(dir_);
  EXPECT_NE(error.find("frames.csv:3"), std::string::npos) << error;
  EXPECT_NE(error.find("column 5 (inlier_ratio)"), std::string::npos) << error;
}

TEST_F(RunIoTest, MissingCamerasRoundTripAndOldFilesStillRead) {
  RunData run = SampleRun();
  run.frames[1].missing_cameras = "1;3";
  WriteRun(dir_, run);
  EXPECT_EQ(ReadRun(dir_).frames[1].missing_cameras, "1;3");
  EXPECT_EQ(ReadRun(dir_).frames[0].missing_cameras, "");
  // A frames.csv without the column (as written before it existed) reads with no camera missing.
  std::string text = ReadFile(RunFramesPath(dir_));
  std::string old;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) old += line.substr(0, line.rfind(',')) + "\n";
  WriteFileAtomic(RunFramesPath(dir_), old);
  const RunData back = ReadRun(dir_);
  ASSERT_EQ(back.frames.size(), run.frames.size());
  EXPECT_EQ(back.frames[1].missing_cameras, "");
  EXPECT_EQ(back.frames[1].status, run.frames[1].status);
  ReplaceLine(RunFramesPath(dir_), 2, "0,0,300,150,0.5,0.1,0,ok,1,x");
  EXPECT_NE(ErrorOf(dir_).find("expected 9 columns"), std::string::npos) << ErrorOf(dir_);
}

TEST_F(RunIoTest, BadRowsAreRejected) {
  WriteRun(dir_, SampleRun());
  ReplaceLine(RunFramesPath(dir_), 2, "0,0,300,150,0.5,0.1,0,ok,1");  // one column short
  EXPECT_NE(ErrorOf(dir_).find("frames.csv:2: expected 10 columns, got 9"), std::string::npos) << ErrorOf(dir_);
  WriteRun(dir_, SampleRun());
  ReplaceLine(RunFramesPath(dir_), 2, "0,0,300,150,0.5,0.1,0,flying,1,");
  EXPECT_NE(ErrorOf(dir_).find("column 8 (status)"), std::string::npos) << ErrorOf(dir_);
  WriteRun(dir_, SampleRun());
  ReplaceLine(RunFramesPath(dir_), 2, "0,0,300,400,0.5,0.1,0,ok,1,");  // more inliers than correspondences
  EXPECT_NE(ErrorOf(dir_).find("column 4 (num_inliers)"), std::string::npos) << ErrorOf(dir_);
  WriteRun(dir_, SampleRun());
  ReplaceLine(RunExtrinsicsPath(dir_), 1, "frame,timestamp,camera,qw,qx,qy,qz,tx,ty,tz");
  EXPECT_NE(ErrorOf(dir_).find("extrinsics.csv:1: bad header"), std::string::npos) << ErrorOf(dir_);
  WriteRun(dir_, SampleRun());
  ReplaceLine(RunExtrinsicsPath(dir_), 4, "1,0.1,0,0,0,0,2,0,0,0");  // quaternion of norm 2
  EXPECT_NE(ErrorOf(dir_).find("extrinsics.csv:4: column 4 (qx)"), std::string::npos) << ErrorOf(dir_);
}

TEST_F(RunIoTest, MissingRunJsonFieldIsNamed) {
  RunData run = SampleRun();
  WriteRun(dir_, run);
  nlohmann::json info = run.info;
  info.erase("seed");
  WriteJsonFileAtomic(RunInfoPath(dir_), info);
  const std::string error = ErrorOf(dir_);
  EXPECT_NE(error.find("run.json"), std::string::npos) << error;
  EXPECT_NE(error.find("\"seed\""), std::string::npos) << error;
  info["seed"] = 1;
  info["mode"] = "fast";
  WriteJsonFileAtomic(RunInfoPath(dir_), info);
  EXPECT_NE(ErrorOf(dir_).find("\"mode\""), std::string::npos) << ErrorOf(dir_);
  // WriteRun refuses an incomplete run.json up front.
  run.info.erase("dataset");
  EXPECT_THROW(WriteRun(dir_ + "_x", run), std::runtime_error);
}

TEST_F(RunIoTest, MissingFileIsNamed) {
  WriteRun(dir_, SampleRun());
  fs::remove(RunExtrinsicsPath(dir_));
  EXPECT_NE(ErrorOf(dir_).find("extrinsics.csv"), std::string::npos) << ErrorOf(dir_);
  EXPECT_NE(ErrorOf(dir_ + "/nope").find("does not exist"), std::string::npos);
}

}  // namespace
}  // namespace rovo
