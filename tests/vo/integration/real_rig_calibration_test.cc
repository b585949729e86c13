// The start-up calibration on real frames of a real 4 x 220 deg rig (shared/data/itbt_real, its own
// calibration as the reference), from seeded sigma = 5 deg draws not used for tuning.
#include "datasets/dataset.h"
#include "datasets/omnimvs.h"
#include "vo/image_loader.h"
#include "vo/startup_calibration.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace rovo {
namespace {
namespace fs = std::filesystem;

double ErrorDeg(const std::vector<Rigid3>& est, const std::vector<Rigid3>& truth) {
  double worst = 0.0;
  for (size_t i = 1; i < est.size(); ++i) {
    worst = std::max(worst, RotationDistanceDeg(est[i].rotation * est[0].rotation.inverse(),
                                                truth[i].rotation * truth[0].rotation.inverse()));
  }
  return worst;
}

class RealRigCalibration : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = (fs::temp_directory_path() / ("rovo_itbt_" + std::to_string(::getpid()))).string();
    const std::string capture = std::string(ROVO_SHARED_DIR) + "/data/itbt_real";
    ImportOmniMvsCapture(capture + "/config.yaml", capture, "", dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  // Start-up calibration of `frame` from draws 7000..7000+n-1: (converged draws, converged within
  // `bound_deg` of the file's calibration).
  static std::pair<int, int> Run(int frame, int n, double bound_deg) {
    const DatasetInfo info = ReadDatasetInfo(dir_);
    auto load = [&](int f) { return LoadFrameImages(dir_, info.rig, f); };
    int converged = 0, close = 0;
    for (int k = 0; k < n; ++k) {
      const auto drawn = PerturbExtrinsics(info.rig, 5.0, 0.0, 7000 + k).cam_from_rig;
      const StartupCalibrationReport r = CalibrateAtStartup(info.rig, drawn, load, frame, frame + 1, {}, {}, true);
      if (!r.converged) continue;
      ++converged;
      const double error = ErrorDeg(r.cam_from_rig, info.rig.Extrinsics());
      close += error < bound_deg ? 1 : 0;
      std::fprintf(stderr, "frame %d draw %d: %.3f deg from the file's calibration\n", frame, 7000 + k, error);
    }
    return {converged, close};
  }
  static std::string dir_;
};
std::string RealRigCalibration::dir_;

// What holds on the three real frames, from draws 7000-7009: no draw claims convergence beyond 1.0 deg
// from the file's calibration. Measured: none claims convergence at all (the textured corridor's pairs
// leave the joint solution by 1.0-1.8 deg; the plain-walled rooms leave the ring open), so the start-up
// keeps the drawn extrinsics and says why, instead of returning a wrong result.
TEST_F(RealRigCalibration, NoShotClaimsAWrongResult) {
  for (int frame : {0, 1, 2}) {
    const auto [converged, close] = Run(frame, 10, 1.0);
    EXPECT_EQ(close, converged) << "frame " << frame << ": a draw claimed convergence but is > 1.0 deg off";
  }
}

}  // namespace
}  // namespace rovo
