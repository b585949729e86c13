// The ring calibration's lens angle scale on a rendered shot (cloudy_urban, quick form, frame 0, the
// equidistant omnimvs4 rig):
// with the exact lenses it stays at 1, and with lenses declared with every off-axis angle 1.5 % too
// large (the equidistant focal lengths divided by 1.015) it finds the scale that undoes that and
// still calibrates the extrinsics from a sigma = 5 deg draw.
#include "datasets/dataset.h"
#include "tests/vo/extrinsic_error.h"
#include "vo/image_loader.h"
#include "vo/ring_calibration.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace rovo {
namespace {

class RingAngleScale : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = (std::filesystem::temp_directory_path() / ("rovo_ring_scale_" + std::to_string(::getpid()))).string();
    const std::string command =
        std::string(ROVO_BINARY) + " render --preset cloudy_urban --rig omnimvs4 --quick --quiet --frames 0:1 --out " + dir_;
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }

  // The ring calibration of frame 0 from draw `seed`, with the lenses' angles declared `declared_scale`
  // times their true value and the angle scale estimated when `angle_scale_sigma` > 0.
  static RingCalibrationReport Calibrate(double declared_scale, double angle_scale_sigma, uint64_t seed) {
    const DatasetInfo info = ReadDatasetInfo(dir_);
    Rig declared = info.rig;
    for (RigCamera& c : declared.cameras) {
      EXPECT_EQ(c.camera.model, CameraModelId::kEquidistant);
      c.camera.params[0] /= declared_scale;  // theta = r / f
      c.camera.params[1] /= declared_scale;
    }
    RingCalibrationOptions options;
    options.angle_scale_sigma = angle_scale_sigma;
    RingCalibrator ring(declared.WithExtrinsics(PerturbExtrinsics(info.rig, 5.0, 0.0, seed).cam_from_rig), {}, options);
    ring.AddFrame(LoadFrameImages(dir_, info.rig, 0).images);
    return ring.Solve();
  }
  static std::vector<Rigid3> Truth() { return ReadDatasetInfo(dir_).rig.Extrinsics(); }
  static std::string dir_;
};
std::string RingAngleScale::dir_;

TEST_F(RingAngleScale, ExactLensesKeepScaleOne) {
  const RingCalibrationReport r = Calibrate(1.0, 0.03, 8101);
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_NEAR(r.angle_scale, 1.0, 0.003);
  EXPECT_LT(RelativeExtrinsicErrorDeg(r.cam_from_rig, Truth()), 0.5);
}

TEST_F(RingAngleScale, FindsTheScaleOfLensesThatOverstateAngles) {
  const RingCalibrationReport r = Calibrate(1.015, 0.03, 8101);
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_NEAR(r.angle_scale, 1.0 / 1.015, 0.004);
  const double with_scale = RelativeExtrinsicErrorDeg(r.cam_from_rig, Truth());
  EXPECT_LT(with_scale, 0.5);
  // The lenses as given leave the ring open by degrees: the result is worse, or refused.
  const RingCalibrationReport fixed = Calibrate(1.015, 0.0, 8101);
  if (fixed.converged) {
    EXPECT_GT(RelativeExtrinsicErrorDeg(fixed.cam_from_rig, Truth()), with_scale);
  }
  std::fprintf(stderr, "declared 1.015: scale %.4f, error %.3f deg; lenses as given: %s, error %.3f deg\n",
               r.angle_scale, with_scale, fixed.converged ? "converged" : fixed.reason.c_str(),
               RelativeExtrinsicErrorDeg(fixed.cam_from_rig, Truth()));
}

}  // namespace
}  // namespace rovo
