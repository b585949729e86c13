// The start-up calibration on real frames of a real 4 x 220 deg rig (shared/data/itbt_real, its own
// calibration as the reference), from seeded sigma = 5 deg draws not used for tuning.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "datasets/dataset.h"
#include "datasets/exchange/omnimvs.h"
#include "tests/vo/extrinsic_error.h"
#include "vo/image_loader.h"
#include "vo/ring_calibration.h"
#include "vo/startup_calibration.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

class RealRigCalibration : public ::testing::Test {
 protected:
  // The capture imported with its static masks (tests/fixtures/itbt_real_masks: rig body, operator).
  static void SetUpTestSuite() {
    dir_ = (fs::temp_directory_path() / ("rovo_itbt_" + std::to_string(::getpid()))).string();
    const std::string capture = std::string(ROVO_SHARED_DIR) + "/data/itbt_real";
    ImportOmniMvsCapture(capture + "/config.yaml", capture, std::string(ROVO_TEST_DATA_DIR) + "/itbt_real_masks", dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  struct Outcome {
    int converged = 0;                                     // by the start-up calibration's own verdict
    int close = 0;                                         // of those, within the bound of the file's calibration
    double agreement_deg = 0.0;                            // largest difference between two converged results
    double min_angle_scale = 10.0, max_angle_scale = 0.0;  // the lenses' angle scale of the converged results
    int min_placements = 1000;                             // view placements averaged, fewest over the converged draws
    double max_placement_spread_deg = 0.0;
  };
  // Start-up calibration from draws first_seed..first_seed+n-1 on `shots` shots from `frame` on
  // (consecutive frames: three places of the same rig).
  static Outcome Run(int frame, int shots, uint64_t first_seed, int n, double bound_deg) {
    const DatasetInfo info = ReadDatasetInfo(dir_);
    auto load = [&](int f) { return LoadFrameImages(dir_, info.rig, f); };
    StartupCalibrationOptions options;
    options.shots = shots;
    options.shot_spacing = 1;
    Outcome out;
    std::vector<std::vector<Rigid3>> results;
    for (int k = 0; k < n; ++k) {
      const auto drawn = PerturbExtrinsics(info.rig, 5.0, 0.0, first_seed + k).cam_from_rig;
      const StartupCalibrationReport r =
          CalibrateAtStartup(info.rig, drawn, load, frame, frame + shots,
                             LoadStaticMasks(dir_, info.rig, info.has_static_masks), options, true);
      if (!r.converged) continue;
      ++out.converged;
      const double error = RelativeExtrinsicErrorDeg(r.cam_from_rig, info.rig.Extrinsics());
      out.close += error < bound_deg ? 1 : 0;
      out.min_angle_scale = std::min(out.min_angle_scale, r.ring.angle_scale);
      out.max_angle_scale = std::max(out.max_angle_scale, r.ring.angle_scale);
      out.min_placements = std::min(out.min_placements, r.placements_averaged);
      out.max_placement_spread_deg = std::max(out.max_placement_spread_deg, r.placement_spread_deg);
      for (const auto& other : results)
        out.agreement_deg = std::max(out.agreement_deg, RelativeExtrinsicErrorDeg(r.cam_from_rig, other));
      results.push_back(r.cam_from_rig);
      std::fprintf(stderr,
                   "frame %d shots %d draw %d: %.3f deg from the file's calibration, lens angle scale %.4f, %d view "
                   "placements within %.3f deg\n",
                   frame, shots, static_cast<int>(first_seed + k), error, r.ring.angle_scale, r.placements_averaged,
                   r.placement_spread_deg);
    }
    return out;
  }
  static std::string dir_;
};
std::string RealRigCalibration::dir_;

// One shot per frame, draws 7000-7009: no draw claims convergence beyond 1.0 deg from the file's
// calibration. Measured: frame 0 converges on 10 of 10 draws (0.49-0.56 deg), frame 1 on none (its
// plain-walled 0-1 overlap leaves the ring open), frame 2 on none (two pairs of 20-60 matches; the
// one draw whose ring closed, 1.04 deg from the file, has a pair 0.78 deg from the joint solution);
// they keep the drawn extrinsics and say why, instead of returning a wrong result.
TEST_F(RealRigCalibration, NoShotClaimsAWrongResult) {
  for (int frame : {0, 1, 2}) {
    const Outcome o = Run(frame, 1, 7000, 10, 1.0);
    EXPECT_EQ(o.close, o.converged) << "frame " << frame << ": a draw claimed convergence but is > 1.0 deg off";
  }
}

// Frame 0 (the textured hall) alone, draws 7100-7109: at least 9 converge within 1.0 deg of the file's
// calibration, agreeing with each other within 0.3 deg, and the lenses' angle scale comes out above 1
// on every one (the file's lenses understate angles near the rim). Measured: 10 of 10, 0.44-0.56 deg
// from the file, scale 1.015-1.017, agreeing within 0.14 deg (0.18 with one view placement; these draws
// were among those that chose the later passes' corner density; fresh draws 7500-7709 agree within
// 0.12-0.17 deg, docs/results.md).
TEST_F(RealRigCalibration, TexturedShotConvergesAlone) {
  const Outcome o = Run(0, 1, 7100, 10, 1.0);
  EXPECT_GE(o.close, 9);
  EXPECT_LE(o.agreement_deg, 0.3);
  EXPECT_GT(o.min_angle_scale, 1.008);
  EXPECT_LT(o.max_angle_scale, 1.025);
  // Every converged draw averages its three view placements, which agree within a few tenths.
  EXPECT_EQ(o.min_placements, 3);
  EXPECT_LT(o.max_placement_spread_deg, 0.3);
}

// The three shots pooled (three places, one rig), draws 7300-7309, which were not used for tuning:
// at least 9 converge within 1.0 deg of the file's calibration and agree with each other within 0.3 deg.
// Measured: 10 of 10, 0.32-0.42 deg from the file, agreeing within 0.16 deg (lens angle scale 1.008-1.009).
TEST_F(RealRigCalibration, ThreePooledShotsConvergeAndAgree) {
  const Outcome o = Run(0, 3, 7300, 10, 1.0);
  EXPECT_GE(o.close, 9);
  EXPECT_LE(o.agreement_deg, 0.3);
}

// The lens correction carries over to places that did not produce it: the angle scale estimated on
// frame 0 alone (draw 7150), applied to the file's own extrinsics, explains the overlap matches of
// frames 1 and 2 with smaller residuals than the lenses as given (RingCalibrator::Fit). Measured with
// the scale of draws 7100-7109 (median 1.0156): median residual 0.131 -> 0.118 deg on frame 1, 0.128 ->
// 0.097 deg on frame 2 (`rovo study calibration --fit-frames`).
TEST_F(RealRigCalibration, LensScaleOfOneFrameFitsTheOthers) {
  const DatasetInfo info = ReadDatasetInfo(dir_);
  const std::vector<cv::Mat> masks = LoadStaticMasks(dir_, info.rig, info.has_static_masks);
  auto load = [&](int f) { return LoadFrameImages(dir_, info.rig, f); };
  const StartupCalibrationOptions options;
  const StartupCalibrationReport r = CalibrateAtStartup(
      info.rig, PerturbExtrinsics(info.rig, 5.0, 0.0, 7150).cam_from_rig, load, 0, 1, masks, options, true);
  ASSERT_TRUE(r.converged) << r.status;
  const double scale = r.ring.angle_scale;
  EXPECT_GT(scale, 1.005);
  RingCalibrationOptions ring_options = options.ring;
  ring_options.refine_matches = options.refine_second_pass;
  for (int frame : {1, 2}) {
    RingCalibrator ring(info.rig, masks, ring_options);
    ring.AddFrame(load(frame).images);
    auto median = [](const std::vector<RingPairFit>& fits) {
      std::vector<double> v;
      for (const RingPairFit& f : fits) v.insert(v.end(), f.residuals_deg.begin(), f.residuals_deg.end());
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    const double as_given = median(ring.Fit(info.rig.Extrinsics(), 1.0));
    const double scaled = median(ring.Fit(info.rig.Extrinsics(), scale));
    std::fprintf(stderr, "frame %d: median overlap residual %.3f deg with the lenses as given, %.3f with scale %.4f\n",
                 frame, as_given, scaled, scale);
    EXPECT_LT(scaled, as_given) << "frame " << frame;
  }
}

}  // namespace
}  // namespace rovo
