#include "datasets/trajectory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <sstream>

#include "datasets/io.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

std::string TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rovo_trajectory_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

Trajectory RandomTrajectory(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Trajectory trajectory;
  double t = 1234.5678901234567;
  for (int i = 0; i < n; ++i) {
    t += 0.1 + 0.01 * u(rng);
    Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
    trajectory.push_back({t, Rigid3(q.normalized(), Eigen::Vector3d(100 * u(rng), 100 * u(rng), u(rng) / 3.0))});
  }
  return trajectory;
}

bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

TEST(Tum, RoundTripIsBitExact) {
  const std::string dir = TempDir("roundtrip");
  const Trajectory written = RandomTrajectory(200, 7);
  const std::string path = dir + "/t.tum";
  WriteTum(path, written);
  const Trajectory read = ReadTum(path);
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_TRUE(BitEqual(read[i].timestamp, written[i].timestamp));
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(BitEqual(read[i].world_from_rig.translation[k], written[i].world_from_rig.translation[k]));
    }
    for (int k = 0; k < 4; ++k) {
      EXPECT_TRUE(
          BitEqual(read[i].world_from_rig.rotation.coeffs()[k], written[i].world_from_rig.rotation.coeffs()[k]));
    }
  }
  // Writing again gives the same bytes (deterministic output).
  WriteTum(dir + "/t2.tum", read);
  EXPECT_EQ(ReadFile(path), ReadFile(dir + "/t2.tum"));
  fs::remove_all(dir);
}

TEST(Tum, SkipsCommentsAndBlankLinesAndNormalisesSmallRounding) {
  const std::string dir = TempDir("comments");
  const std::string path = dir + "/t.tum";
  WriteFileAtomic(path, "# header\n\n0 1 2 3 0 0 0 1\n  # indented comment\n0.1 4 5 6 0 0 0.7071068 0.7071068\n");
  const Trajectory t = ReadTum(path);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_DOUBLE_EQ(t[1].timestamp, 0.1);
  EXPECT_NEAR(t[1].world_from_rig.rotation.norm(), 1.0, 1e-15);
  EXPECT_TRUE((t[1].world_from_rig.rotation * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-6));
  fs::remove_all(dir);
}

void ExpectReadError(const std::string& content, const std::string& expected_fragment) {
  const std::string dir = TempDir("bad");
  const std::string path = dir + "/bad.tum";
  WriteFileAtomic(path, content);
  try {
    ReadTum(path);
    ADD_FAILURE() << "no error for: " << content;
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr(path));
    EXPECT_THAT(e.what(), ::testing::HasSubstr(expected_fragment));
  }
  fs::remove_all(dir);
}

TEST(Tum, ErrorsNameFileAndLine) {
  ExpectReadError("0 0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n", "line 2: expected 8 numbers");
  ExpectReadError("# c\n0 0 0 x 0 0 0 1\n", "line 2: not a number");
  ExpectReadError("0 0 0 0 0 0 0 1\n1 nan 0 0 0 0 0 1\n", "line 2: NaN or Inf");
  ExpectReadError("0 0 0 0 0 0 0 2\n", "line 1: quaternion");
  ExpectReadError("0 0 0 0 0 0 0 1\n0 0 0 0 0 0 0 1\n", "line 2: timestamp");
  ExpectReadError("0 0 0 0 0 0 0 1 9\n", "line 1: expected 8 numbers");
}

TEST(Tum, ParseCollectsAllErrorsWhenAsked) {
  std::vector<std::string> errors;
  const auto lines = ParseTumText("0 0 0 0 0 0 0 1\nbad\n2 0 0 0 0 0 0 1\n3 inf 0 0 0 0 0 1\n", "f.tum", &errors);
  EXPECT_EQ(lines.size(), 2u);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_THAT(errors[0], ::testing::HasSubstr("f.tum: line 2"));
  EXPECT_THAT(errors[1], ::testing::HasSubstr("f.tum: line 4"));
  EXPECT_EQ(lines[1].line_number, 3);
}

TEST(Kitti, WritesRowMajorThreeByFour) {
  const std::string dir = TempDir("kitti");
  const Trajectory trajectory = RandomTrajectory(3, 9);
  WriteKitti(dir + "/k.txt", trajectory);
  std::istringstream in(ReadFile(dir + "/k.txt"));
  for (const StampedPose& pose : trajectory) {
    const Eigen::Matrix<double, 3, 4> m = pose.world_from_rig.Matrix3x4();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        double v = 0;
        ASSERT_TRUE(in >> v);
        EXPECT_TRUE(BitEqual(v, m(r, c)));
      }
    }
  }
  double extra;
  EXPECT_FALSE(in >> extra);
  fs::remove_all(dir);
}

TEST(Trajectory, InterpolateAndClamp) {
  Trajectory trajectory = {{0.0, Rigid3(QuaternionFromRollPitchYawDeg(0, 0, 0), Eigen::Vector3d(0, 0, 0))},
                           {1.0, Rigid3(QuaternionFromRollPitchYawDeg(0, 0, 20), Eigen::Vector3d(1, 0, 0))},
                           {3.0, Rigid3(QuaternionFromRollPitchYawDeg(0, 0, 60), Eigen::Vector3d(1, 2, 0))}};
  const Rigid3 at_half = InterpolatePose(trajectory, 0.5);
  EXPECT_TRUE(at_half.translation.isApprox(Eigen::Vector3d(0.5, 0, 0), 1e-12));
  EXPECT_NEAR(RollPitchYawDegFromQuaternion(at_half.rotation)[2], 10.0, 1e-9);
  const Rigid3 at_two = InterpolatePose(trajectory, 2.0);
  EXPECT_TRUE(at_two.translation.isApprox(Eigen::Vector3d(1, 1, 0), 1e-12));
  EXPECT_NEAR(RollPitchYawDegFromQuaternion(at_two.rotation)[2], 40.0, 1e-9);
  // Exactly on a sample, and clamped outside the range.
  EXPECT_TRUE(InterpolatePose(trajectory, 1.0).translation.isApprox(Eigen::Vector3d(1, 0, 0), 1e-12));
  EXPECT_TRUE(InterpolatePose(trajectory, -5.0).translation.isApprox(Eigen::Vector3d(0, 0, 0), 1e-12));
  EXPECT_TRUE(InterpolatePose(trajectory, 50.0).translation.isApprox(Eigen::Vector3d(1, 2, 0), 1e-12));
  EXPECT_THROW(InterpolatePose({}, 0.0), std::invalid_argument);
  EXPECT_DOUBLE_EQ(PathLength(trajectory), 3.0);
  EXPECT_DOUBLE_EQ(PathLength({}), 0.0);
}

}  // namespace
}  // namespace rovo
