#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "vo/frontend.h"
#include "vo/hybrid_projection.h"
#include "vo/interview_matching.h"
#include "vo/ransac.h"
#include "vo/startup_calibration.h"
#include "vo/tracking.h"
#include "vo/triangulation.h"

namespace rovo {
namespace {

// The message of the std::invalid_argument that `check` throws; empty when it does not throw.
template <typename F>
std::string CheckMessage(F check) {
  try {
    check();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(OptionsCheck, DefaultsPass) {
  EXPECT_NO_THROW(FrontendOptions{}.Check());
  EXPECT_NO_THROW(TrackerOptions{}.Check());
  EXPECT_NO_THROW(HybridProjectionOptions{}.Check());
  EXPECT_NO_THROW(InterviewMatchOptions{}.Check());
  EXPECT_NO_THROW(SubpixelMatchOptions{}.Check());
  EXPECT_NO_THROW(TriangulationOptions{}.Check());
  EXPECT_NO_THROW(StartupCalibrationOptions{}.Check());
  EXPECT_NO_THROW(RansacLoopOptions{}.Check());
  EXPECT_NO_THROW(TrackerOptionsFrom(FrontendOptions{}).Check());
}

TEST(OptionsCheck, InvalidFieldIsNamed) {
  FrontendOptions frontend;
  frontend.klt_max_iterations = 0;
  EXPECT_NE(CheckMessage([&] { frontend.Check(); }).find("klt_max_iterations"), std::string::npos);
  FrontendOptions nested;
  nested.projection.focal_scale = 0.0;
  EXPECT_NE(CheckMessage([&] { nested.Check(); }).find("focal_scale"), std::string::npos);
  TrackerOptions tracker;
  tracker.border_px = -1;
  EXPECT_NE(CheckMessage([&] { tracker.Check(); }).find("border_px"), std::string::npos);
  InterviewMatchOptions matching;
  matching.max_ratio = 1.5;
  EXPECT_NE(CheckMessage([&] { matching.Check(); }).find("max_ratio"), std::string::npos);
  TriangulationOptions triangulation;
  triangulation.max_error_deg = 0.0;
  EXPECT_NE(CheckMessage([&] { triangulation.Check(); }).find("max_error_deg"), std::string::npos);
  StartupCalibrationOptions startup;
  startup.shots = 0;
  EXPECT_NE(CheckMessage([&] { startup.Check(); }).find("shots"), std::string::npos);
  startup = StartupCalibrationOptions{};
  startup.min_pair_inliers = -1;
  EXPECT_NE(CheckMessage([&] { startup.Check(); }).find("min_pair_inliers"), std::string::npos);
  RansacLoopOptions loop;
  loop.confidence = 0.0;
  EXPECT_NE(CheckMessage([&] { loop.Check(); }).find("confidence"), std::string::npos);
}

}  // namespace
}  // namespace rovo
