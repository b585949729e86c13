// The back-end adds no scale bias of its own: on synthetic front-end output with zero-mean bearing
// noise and outliers, over a 100 m drive with near and far points, the estimated trajectory has the
// true length to 0.1 %. (A systematic slide of KLT tracks along the image motion does shorten it:
// see max_forward_backward_px in vo/frontend.h.) Integration label: ~15 s CPU, too slow under ASan.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "../synthetic_rig.h"
#include "vo/pipeline.h"

namespace rovo {
namespace {

TEST(BackendScale, ZeroMeanNoiseGivesTheTrueLength) {
  const int frames = 100;
  const test::World w = test::MakeWorld(frames, 3, /*far_per_metre=*/5);
  for (const double noise_rad : {0.0005, 0.0015}) {  // 0.03 and 0.09 deg
    std::mt19937_64 rng(4);
    VoBackend backend(w.cam_from_rig, w.world_from_rig[0], test::SyntheticBackendOptions());
    std::vector<Eigen::Vector3d> estimated;
    for (int f = 0; f < frames; ++f) {
      const BackendFrameResult r = backend.ProcessFrame(f, test::Observe(w, f, rng, noise_rad, 0.1, 100.0));
      ASSERT_NE(r.record.status, FrameStatus::kLost) << "frame " << f;
      estimated.push_back(r.world_from_rig.translation);
    }
    // Chord lengths over 25-frame segments (free of the noise that inflates a sum of steps).
    double length = 0.0, true_length = 0.0;
    for (int f = 0; f + 25 < frames; f += 25) {
      length += (estimated[f + 25] - estimated[f]).norm();
      true_length += (w.world_from_rig[f + 25].translation - w.world_from_rig[f].translation).norm();
    }
    std::printf("noise %.4f rad: length ratio %.5f\n", noise_rad, length / true_length);
    EXPECT_NEAR(length / true_length, 1.0, 0.001) << "noise " << noise_rad << " rad";
  }
}

}  // namespace
}  // namespace rovo
