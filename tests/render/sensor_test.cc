// The sensor model (render/sensor.h) against its analytic expectations: noise statistics of flat
// patches, the response curves, grayscale, auto-exposure, the HDR sun; the default render unchanged;
// the dataset record and exposure.csv; `rovo render --sensor` end to end on small scenes.
#include "render/sensor.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "datasets/dataset.h"
#include "datasets/io.h"
#include "render/render.h"
#include "render/timing.h"
#include "render/tracer.h"
#include "tests/render/box_scene.h"
#include "tests/render/open_scene.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

struct Moments {
  double mean = 0.0, variance = 0.0;
};

template <typename T>
Moments MomentsOf(const std::vector<T>& values) {
  Moments m;
  for (T v : values) m.mean += v;
  m.mean /= values.size();
  for (T v : values) m.variance += (v - m.mean) * (v - m.mean);
  m.variance /= values.size() - 1;
  return m;
}

// A sensor with every effect under the test's control.
SensorSettings TestSensor() {
  SensorSettings s = SensorProfile("ideal");
  s.sensitivity_e_per_ms = 1000.0;
  s.full_well_e = 10000.0;
  s.read_noise_e = 0.0;
  s.dark_current_e_per_s = 0.0;
  s.shot_noise = true;
  s.adc_bits = 8;
  s.response = ResponseCurve::kLinear;
  return s;
}

// Apply() on a flat patch of `pixels` pixels of radiance `radiance` in every channel.
std::vector<uint8_t> FlatPatch(const SensorSettings& s, double radiance, const CameraExposure& exposure,
                               size_t pixels = 256 * 256, uint64_t seed = 1) {
  const std::vector<float> linear(3 * pixels, static_cast<float>(radiance));
  const std::vector<uint8_t> valid(pixels, 1);
  std::vector<uint8_t> out;
  SensorPipeline(s).Apply(linear, valid, exposure, 1.0, seed, &out);
  return out;
}

// ---- the noise model -------------------------------------------------------------------------------

TEST(SensorNoiseTest, NormalTableHasUnitVarianceAndZeroMean) {
  double sum = 0.0, sum2 = 0.0;
  for (int w = 0; w < 65536; ++w) {
    const double z = NormalQuantile(static_cast<uint16_t>(w));
    sum += z;
    sum2 += z * z;
  }
  EXPECT_NEAR(sum / 65536.0, 0.0, 1e-9);
  EXPECT_NEAR(sum2 / 65536.0, 1.0, 1e-3);  // the tails beyond 4.3 sigma are cut: -3e-4
  EXPECT_NEAR(NormalQuantile(32768), 0.5 / 65536.0 * std::sqrt(2.0 * M_PI), 1e-7);
  EXPECT_NEAR(NormalQuantile(static_cast<uint16_t>(0.8413447 * 65536.0)), 1.0, 1e-3);  // Phi(1)
}

// Var(DN) = g^2 (mu + sigma_r^2) + 1/12 with g = G (2^b - 1) / FWC (EMVA 1288), E[DN] = g mu.
TEST(SensorNoiseTest, FlatPatchVarianceIsShotPlusReadPlusQuantisation) {
  struct Case {
    double mu_e, read_e, gain;
  };
  for (const Case& c : {Case{600.0, 4.0, 8.0}, Case{2000.0, 2.0, 1.0}, Case{300.0, 0.0, 16.0}}) {
    SensorSettings s = TestSensor();
    s.read_noise_e = c.read_e;
    const CameraExposure exposure{c.mu_e / s.sensitivity_e_per_ms, c.gain};  // radiance 1
    const std::vector<uint8_t> out = FlatPatch(s, 1.0, exposure);
    const Moments m = MomentsOf(out);
    const double g = c.gain * 255.0 / s.full_well_e;
    const double expected_var = g * g * (c.mu_e + c.read_e * c.read_e) + 1.0 / 12.0;
    SCOPED_TRACE("mu " + std::to_string(c.mu_e) + " e-, read " + std::to_string(c.read_e) + " e-, gain " +
                 std::to_string(c.gain));
    EXPECT_NEAR(m.mean, g * c.mu_e, 4.0 * std::sqrt(expected_var / out.size()) + 0.01);
    // 196608 samples: the variance's relative standard error is 0.3 %.
    EXPECT_NEAR(m.variance / expected_var, 1.0, 0.02);
  }
  // Without the quantisation term the second case (g^2 mu = 1.30 DN^2) would be 6 % low: the term is seen.
}

// Below 16 electrons the shot noise is exactly Poisson: integer electrons with the Poisson pmf.
TEST(SensorNoiseTest, LowSignalsArePoissonDistributed) {
  SensorSettings s = TestSensor();
  s.adc_bits = 16;
  s.full_well_e = 65535.0;  // one electron = one code at gain 1
  const SensorPipeline pipeline(s);
  const double mu = 3.0;
  const int n = 200000;
  std::map<int, int> histogram;
  for (int i = 0; i < n; ++i) {
    const uint64_t h = SplitMix64(static_cast<uint64_t>(i));
    ++histogram[pipeline.Digitize(mu, 1.0, static_cast<uint16_t>(h), static_cast<uint16_t>(h >> 16))];
  }
  double pmf = std::exp(-mu);
  for (int k = 0; k <= 9; ++k) {
    if (k > 0) pmf *= mu / k;
    const double freq = static_cast<double>(histogram[k]) / n;
    EXPECT_NEAR(freq, pmf, 5.0 * std::sqrt(pmf * (1.0 - pmf) / n) + 2.0 / 65536.0) << "k = " << k;
  }
}

// Dark current adds D t electrons of mean and of Poisson variance: no light, 10 ms at 1000 e-/s,
// 10 electrons (the exact Poisson branch), gain 16 on a 1000 e- well: g = 4.08 codes per electron.
TEST(SensorNoiseTest, DarkCurrentAddsPoissonElectrons) {
  SensorSettings s = TestSensor();
  s.full_well_e = 1000.0;
  s.dark_current_e_per_s = 1000.0;
  const CameraExposure exposure{10.0, 16.0};
  const std::vector<uint8_t> out = FlatPatch(s, 0.0, exposure);
  const Moments m = MomentsOf(out);
  const double g = 16.0 * 255.0 / s.full_well_e;
  EXPECT_NEAR(m.mean / (g * 10.0), 1.0, 0.01);
  EXPECT_NEAR(m.variance / (g * g * 10.0 + 1.0 / 12.0), 1.0, 0.02);
}

TEST(SensorNoiseTest, FullWellAndAdcClip) {
  SensorSettings s = TestSensor();
  s.read_noise_e = 5.0;
  const SensorPipeline pipeline(s);
  EXPECT_EQ(pipeline.Digitize(1e9, 1.0, 123, 456), 255);     // full well = full scale at gain 1
  EXPECT_EQ(pipeline.Digitize(6000.0, 2.0, 123, 456), 255);  // the ADC saturates before the well
  EXPECT_EQ(pipeline.Digitize(0.0, 1.0, 0, 0), 0);           // negative read noise is clipped at code 0
  EXPECT_EQ(pipeline.Digitize(std::nan(""), 1.0, 10, 10), 0);
}

TEST(SensorNoiseTest, DeterministicPerSeedAndIdenticalForAnyThreadCount) {
  SensorSettings s = SensorProfile("realistic");
  const size_t pixels = 200 * 150;
  std::vector<float> linear(3 * pixels);
  for (size_t i = 0; i < linear.size(); ++i) linear[i] = 0.05f + 0.3f * static_cast<float>(i % 97) / 97.0f;
  const std::vector<uint8_t> valid(pixels, 1);
  const SensorPipeline pipeline(s);
  const CameraExposure exposure{0.02, 1.0};
  std::vector<uint8_t> out[2];
  for (int k = 0; k < 2; ++k) {
    tbb::task_arena arena(k + 1);
    arena.execute([&] { pipeline.Apply(linear, valid, exposure, 1.0, SensorNoiseSeed(3, 5, 1), &out[k]); });
  }
  EXPECT_EQ(out[0], out[1]);
  std::vector<uint8_t> other;
  pipeline.Apply(linear, valid, exposure, 1.0, SensorNoiseSeed(3, 6, 1), &other);
  EXPECT_NE(other, out[0]);
  EXPECT_NE(SensorNoiseSeed(3, 5, 1), SensorNoiseSeed(3, 5, 2));
  EXPECT_NE(SensorNoiseSeed(3, 5, 1), SensorNoiseSeed(4, 5, 1));
}

// ---- response curve and grayscale ----------------------------------------------------------------

TEST(SensorResponseTest, CurvesFollowTheirStandards) {
  EXPECT_NEAR(ApplyResponseCurve(ResponseCurve::kSrgb, 0.18), 1.055 * std::pow(0.18, 1 / 2.4) - 0.055, 1e-12);
  EXPECT_NEAR(ApplyResponseCurve(ResponseCurve::kSrgb, 0.002), 12.92 * 0.002, 1e-12);
  EXPECT_NEAR(ApplyResponseCurve(ResponseCurve::kBt709, 0.18), 1.099 * std::pow(0.18, 0.45) - 0.099, 1e-12);
  EXPECT_NEAR(ApplyResponseCurve(ResponseCurve::kBt709, 0.01), 0.045, 1e-12);
  for (ResponseCurve c : {ResponseCurve::kSrgb, ResponseCurve::kBt709, ResponseCurve::kLinear}) {
    EXPECT_NEAR(ApplyResponseCurve(c, 0.0), 0.0, 1e-12);
    EXPECT_NEAR(ApplyResponseCurve(c, 1.0), 1.0, 1e-3);
    EXPECT_EQ(ResponseCurveFromName(ResponseCurveName(c)), c);
  }
  // Continuous at the breakpoints.
  EXPECT_NEAR(ApplyResponseCurve(ResponseCurve::kBt709, 0.018 - 1e-12),
              ApplyResponseCurve(ResponseCurve::kBt709, 0.018), 1e-3);
  EXPECT_THROW(ResponseCurveFromName("gamma"), std::invalid_argument);
}

// Noise-free: out = round(255 CRF(round(G min(mu, FWC) (2^b - 1) / FWC) / (2^b - 1))) exactly; with
// noise the mean output follows the CRF of the mean signal.
TEST(SensorResponseTest, MeanResponseFollowsTheCrf) {
  for (ResponseCurve curve : {ResponseCurve::kBt709, ResponseCurve::kSrgb}) {
    SensorSettings s = SensorProfile("realistic");
    s.response = curve;
    s.dark_current_e_per_s = 0.0;
    const double fs = 4095.0;
    for (double level : {0.05, 0.18, 0.5}) {
      const double mu = level * s.full_well_e;
      const CameraExposure exposure{mu / s.sensitivity_e_per_ms, 1.0};  // radiance 1
      const std::vector<uint8_t> noisy = FlatPatch(s, 1.0, exposure);
      SCOPED_TRACE(ResponseCurveName(curve) + " at " + std::to_string(level));
      EXPECT_NEAR(MomentsOf(noisy).mean, 255.0 * ApplyResponseCurve(curve, level), 0.1);
      SensorSettings ideal = s;
      ideal.shot_noise = false;
      ideal.read_noise_e = 0.0;
      const std::vector<uint8_t> clean = FlatPatch(ideal, 1.0, exposure, 16);
      const double dn = std::floor(1.0 * std::min(mu, s.full_well_e) * fs / s.full_well_e + 0.5);
      EXPECT_EQ(clean[0], static_cast<uint8_t>(std::floor(255.0 * ApplyResponseCurve(curve, dn / fs) + 0.5)));
    }
  }
}

TEST(SensorResponseTest, GrayscaleIsOneChannelOfTheLuminance) {
  SensorSettings s = SensorProfile("ideal");
  s.grayscale = true;
  const size_t pixels = 4096;
  std::vector<float> linear(3 * pixels);
  for (size_t i = 0; i < linear.size(); ++i) linear[i] = static_cast<float>((SplitMix64(i) >> 40) * 0x1p-24);
  std::vector<uint8_t> valid(pixels, 1);
  valid[17] = 0;
  const CameraExposure exposure{0.05, 2.0};
  std::vector<uint8_t> out;
  SensorPipeline(s).Apply(linear, valid, exposure, 0.9, 11, &out);
  ASSERT_EQ(out.size(), pixels);
  const double fs = 65535.0;
  for (size_t i = 0; i < pixels; ++i) {
    if (!valid[i]) {
      EXPECT_EQ(out[i], 0);
      continue;
    }
    const double y = 0.2126 * linear[3 * i] + 0.7152 * linear[3 * i + 1] + 0.0722 * linear[3 * i + 2];
    const double mu = s.sensitivity_e_per_ms * 0.9 * exposure.exposure_ms * y;
    const double dn = std::min(std::floor(exposure.gain * std::min(mu, s.full_well_e) * fs / s.full_well_e + 0.5), fs);
    ASSERT_EQ(out[i], static_cast<uint8_t>(std::floor(255.0 * ApplyResponseCurve(s.response, dn / fs) + 0.5)))
        << "pixel " << i;
  }
}

// ---- settings, sensitivities ---------------------------------------------------------------------

TEST(SensorSettingsTest, ProfilesAndOverrides) {
  EXPECT_FALSE(SensorProfile("off").enabled);
  const SensorSettings realistic = SensorProfile("realistic");
  EXPECT_TRUE(realistic.enabled);
  EXPECT_EQ(realistic.adc_bits, 12);
  EXPECT_GT(realistic.read_noise_e, 0.0);
  EXPECT_NO_THROW(realistic.Check());
  EXPECT_THROW(SensorProfile("fancy"), std::invalid_argument);

  SensorOverrides o;
  o.exposure_ms = 2.0;
  o.read_noise = 5.0;
  o.grayscale = true;
  const SensorSettings s = MakeSensorSettings("realistic", o);
  EXPECT_FALSE(s.auto_exposure);  // a fixed exposure
  EXPECT_EQ(s.exposure_ms, 2.0);
  EXPECT_EQ(s.gain, 1.0);
  EXPECT_EQ(s.read_noise_e, 5.0);
  EXPECT_TRUE(s.grayscale);

  auto expect_error = [](const std::string& profile, const SensorOverrides& bad, const std::string& needle) {
    try {
      MakeSensorSettings(profile, bad);
      ADD_FAILURE() << "expected an error naming " << needle;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  SensorOverrides with_off;
  with_off.read_noise = 3.0;
  expect_error("off", with_off, "--sensor ideal");
  SensorOverrides both = o;
  both.auto_exposure = true;
  expect_error("ideal", both, "--auto-exposure");
  SensorOverrides bits;
  bits.adc_bits = 20;
  expect_error("ideal", bits, "--adc-bits");
  SensorOverrides gain;
  gain.gain = 0.5;
  expect_error("ideal", gain, "--gain");
  SensorOverrides well;
  well.full_well = -1.0;
  expect_error("realistic", well, "--full-well");
}

TEST(SensorSettingsTest, CameraSensitivitiesAreSeededAndSpread) {
  SensorSettings s = SensorProfile("realistic");
  const std::vector<double> a = CameraSensitivities(s, 4, 9), b = CameraSensitivities(s, 4, 9);
  EXPECT_EQ(a, b);
  EXPECT_NE(CameraSensitivities(s, 4, 10), a);
  for (double q : a) {
    EXPECT_GT(q, std::exp(-4.5 * s.sensitivity_spread));
    EXPECT_LT(q, std::exp(4.5 * s.sensitivity_spread));
  }
  EXPECT_NE(a[0], a[1]);
  s.sensitivity_spread = 0.0;
  for (double q : CameraSensitivities(s, 4, 9)) EXPECT_EQ(q, 1.0);
}

// ---- auto-exposure --------------------------------------------------------------------------------

TEST(AutoExposureTest, StartsAtTargetAndConvergesWithBoundedSteps) {
  const SensorSettings s = SensorProfile("ideal");
  // One camera: meter 0.03 for 10 frames, then 0.3 (the sun comes into view).
  std::vector<std::vector<double>> meter(60, std::vector<double>{0.03});
  for (int f = 10; f < 60; ++f) meter[f][0] = 0.3;
  const auto schedule = ExposureSchedule(s, meter, 10.0);
  auto total = [&](int f) { return schedule[f][0].exposure_ms * schedule[f][0].gain; };
  auto signal = [&](int f, double m) { return s.sensitivity_e_per_ms * total(f) * m / s.full_well_e; };
  EXPECT_NEAR(signal(0, 0.03), s.ae_target, 1e-9);  // the first frame starts converged
  EXPECT_NEAR(total(10), total(9), 1e-12);          // one frame of latency
  for (int f = 11; f < 60; ++f) {
    const double step = std::log2(total(f) / total(f - 1));
    EXPECT_LE(step, 1e-12) << f;
    EXPECT_GE(step, -s.ae_max_step_stops - 1e-12) << f;
  }
  EXPECT_NEAR(std::log2(total(11) / total(10)), -s.ae_max_step_stops, 1e-9);  // 0.25 x -3.3 stops, bounded
  EXPECT_NEAR(signal(59, 0.3) / s.ae_target, 1.0, 0.01);                      // converged to the new target
}

TEST(AutoExposureTest, TimeFirstThenGainWithinTheLimits) {
  SensorSettings s = SensorProfile("realistic");
  const CameraExposure dark = SplitExposure(s, TargetLog2Exposure(s, 1e-9, 10.0), 10.0);
  EXPECT_NEAR(dark.exposure_ms, s.max_exposure_ms, 1e-12);
  EXPECT_NEAR(dark.gain, s.max_gain, 1e-12);
  const CameraExposure bright = SplitExposure(s, TargetLog2Exposure(s, 1e9, 10.0), 10.0);
  EXPECT_NEAR(bright.exposure_ms, s.min_exposure_ms, 1e-15);
  EXPECT_EQ(bright.gain, 1.0);
  const CameraExposure mid = SplitExposure(s, std::log2(40.0), 10.0);  // 40 ms x gain: 20 ms, gain 2
  EXPECT_NEAR(mid.exposure_ms, 20.0, 1e-12);
  EXPECT_NEAR(mid.gain, 2.0, 1e-12);
  EXPECT_NEAR(SplitExposure(s, std::log2(40.0), 100.0).exposure_ms, 10.0, 1e-12);  // at most the frame period
  s.auto_exposure = false;
  s.exposure_ms = 3.0;
  s.gain = 2.0;
  const auto fixed = ExposureSchedule(s, {{0.1, 5.0}, {0.2, 7.0}}, 10.0);
  for (const auto& frame : fixed)
    for (const CameraExposure& e : frame) {
      EXPECT_EQ(e.exposure_ms, 3.0);
      EXPECT_EQ(e.gain, 2.0);
    }
}

TEST(AutoExposureTest, MeterIsCentreWeighted) {
  // Two valid pixels: on the axis (weight 1) and at 90 degrees (weight 1/2).
  const std::vector<Eigen::Vector3f> bearing = {Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(1, 0, 0),
                                                Eigen::Vector3f(0, 1, 0)};
  const std::vector<uint8_t> valid = {1, 1, 0};
  const std::vector<float> linear = {1, 1, 1, 4, 4, 4, 100, 100, 100};
  // Nothing saturates at the target: the centre-weighted mean luminance.
  EXPECT_NEAR(MeterLuminance(linear, bearing, valid, 0.18), (1.0 * 1.0 + 0.5 * 4.0) / 1.5, 1e-9);
  EXPECT_EQ(MeterLuminance(linear, bearing, {0, 0, 0}, 0.18), 0.0);
}

// A small highlight (a lamp, the sun disc) saturates and counts as full scale, not by its radiance:
// 99 pixels of luminance 1 and one of 10^6 meter about 1, not 10^4, and the exposure the meter asks
// for puts the mean of the clipped signal at the target.
TEST(AutoExposureTest, SaturatedHighlightsCountAsFullScale) {
  const int n = 100;
  std::vector<Eigen::Vector3f> bearing(n, Eigen::Vector3f(0, 0, 1));
  std::vector<uint8_t> valid(n, 1);
  std::vector<float> linear(3 * n, 1.0f);
  for (int k = 0; k < 3; ++k) linear[k] = 1e6f;
  const double target = 0.18;
  const double m = MeterLuminance(linear, bearing, valid, target);
  const double s = target / m;  // full scale per unit luminance
  double clipped = 0.0;
  for (int i = 0; i < n; ++i) clipped += std::min(1.0, s * linear[3 * i]) / n;
  EXPECT_NEAR(clipped, target, 1e-12);
  EXPECT_NEAR(m, 0.18 * 99.0 / 17.0, 1e-9);  // (1 + 99 s) / 100 = 0.18
  // Mostly black with a few lit pixels: the target is out of reach, the longest exposure.
  std::vector<float> dark(3 * n, 0.0f);
  for (int k = 0; k < 30; ++k) dark[k] = 5.0f;  // 10 lit pixels: at most 10 % of full scale
  EXPECT_EQ(MeterLuminance(dark, bearing, valid, target), 0.0);
}

// ---- the tracer's HDR sun and linear output -------------------------------------------------------

Rigid3 WorldFromCamLookingAt(const Eigen::Vector3d& z_axis, const Eigen::Vector3d& position) {
  const Eigen::Vector3d z = z_axis.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d world_from_cam_rot;
  world_from_cam_rot.col(0) = x;
  world_from_cam_rot.col(1) = z.cross(x);
  world_from_cam_rot.col(2) = z;
  return Rigid3(world_from_cam_rot, position);
}

// Over the sphere the sun integrates to its irradiance, at any image size and sample count:
// sum over pixels of (L_with_sun - L_sky) * solid angle = E_sun. Equidistant lens: a pixel at angle
// theta from the axis spans sin(theta) / (theta f^2) steradians.
TEST(SunDiscTest, IntegratesToTheSunIrradianceAtAnySize) {
  Scene scene;  // nothing but sky
  scene.lighting.direction_to_sun = Eigen::Vector3d(0.2, 0.3, 0.5);
  scene.rig_trajectory.push_back(StampedPose());
  Tracer tracer(scene);
  const Rigid3 world_from_cam = WorldFromCamLookingAt(scene.lighting.direction_to_sun, Eigen::Vector3d::Zero());
  for (double scale : {0.5, 0.0625}) {
    for (int spp : {1, 2}) {
      const Camera camera = MakeRigPreset("omnimvs4").Scaled(scale).cameras[0].camera;
      const CameraRays rays = CameraRays::Make(camera, 0, spp);
      ShadeSettings settings;
      settings.spp = spp;
      settings.linear_output = true;
      CameraImage sky, sun;
      tracer.Render(rays, world_from_cam, settings, &sky);
      settings.sun_disc = true;
      tracer.Render(rays, world_from_cam, settings, &sun);
      const double f = camera.params[0];
      Eigen::Vector3d integral = Eigen::Vector3d::Zero();
      double peak = 0.0;
      for (size_t i = 0; i < rays.valid.size(); ++i) {
        if (!rays.valid[i]) continue;
        const double theta = std::acos(std::clamp(static_cast<double>(rays.bearing[i].z()), -1.0, 1.0));
        const double solid_angle = theta > 1e-9 ? std::sin(theta) / (theta * f * f) : 1.0 / (f * f);
        for (int k = 0; k < 3; ++k) integral[k] += (sun.linear[3 * i + k] - sky.linear[3 * i + k]) * solid_angle;
        peak = std::max(peak, static_cast<double>(sun.linear[3 * i + 1]));
      }
      SCOPED_TRACE("scale " + std::to_string(scale) + ", spp " + std::to_string(spp));
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(integral[k] / scene.lighting.sun_radiance[k], 1.0, 0.03);
      EXPECT_GT(peak, 100.0 * scene.lighting.sky_horizon.maxCoeff());  // many times the sky's radiance
    }
  }
}

// The linear output is the default path's radiance: times the scene's exposure and sRGB-encoded it
// gives the default image within one code; without sun_disc the sky is unchanged.
TEST(SunDiscTest, LinearOutputIsTheDefaultPathsRadiance) {
  const Scene scene = testing::MakeOpenScene(2);
  const Rig rig = MakeRigPreset("omnimvs4").Scaled(0.1);
  Tracer tracer(scene);
  for (int c : {0, 2}) {
    const CameraRays rays = CameraRays::Make(rig.cameras[c].camera, 0, 2);
    const Rigid3 world_from_cam = scene.rig_trajectory[0].world_from_rig * rig.cameras[c].cam_from_rig.Inverse();
    ShadeSettings settings;
    settings.spp = 2;
    settings.vignetting = 0.2f;
    CameraImage srgb, linear;
    tracer.Render(rays, world_from_cam, settings, &srgb);
    settings.linear_output = true;
    tracer.Render(rays, world_from_cam, settings, &linear);
    ASSERT_EQ(linear.linear.size(), srgb.rgb.size());
    EXPECT_TRUE(linear.rgb.empty());
    for (size_t i = 0; i < srgb.rgb.size(); ++i) {
      const double v = linear.linear[i] * scene.lighting.exposure;
      const int expected = static_cast<int>(std::lround(255.0 * ApplyResponseCurve(ResponseCurve::kSrgb, v)));
      ASSERT_LE(std::abs(expected - srgb.rgb[i]), 1) << "camera " << c << " value " << i;
    }
  }
}

// ---- dataset.json record and exposure.csv ---------------------------------------------------------

class SensorDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("rovo_sensor_test_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    scene_dir_ = (root_ / "scene").string();
    SaveScene(testing::MakeOpenScene(kFrames), scene_dir_);
  }
  void TearDown() override { fs::remove_all(root_); }

  RenderOptions Options(const std::string& out, const std::string& profile = "realistic") const {
    RenderOptions options;
    options.scene_dir = scene_dir_;
    options.out_dir = (root_ / out).string();
    options.rig = "omnimvs4";
    options.scale = 0.1;  // 80x77 per view
    options.spp = 1;
    options.quiet = true;
    options.seed = 3;
    options.sensor = SensorProfile(profile);
    return options;
  }

  static std::map<std::string, std::string> Files(const std::string& dir) {
    std::map<std::string, std::string> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir))
      if (entry.is_regular_file()) files[fs::relative(entry.path(), dir).string()] = ReadFile(entry.path().string());
    return files;
  }

  static void ExpectValid(const std::string& dir) {
    for (const ValidationIssue& issue : ValidateDataset(dir))
      ADD_FAILURE() << issue.file << " " << issue.field << ": " << issue.message;
  }

  static int Channels(const std::string& path) {
    const cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
    return image.empty() ? -1 : image.channels();
  }

  static constexpr int kFrames = 10;
  fs::path root_;
  std::string scene_dir_;
};

// A camera facing the sun is much brighter in total and gets a shorter exposure than the camera
// facing away; everything is recorded and the dataset validates.
TEST_F(SensorDatasetTest, SunFacingCameraGetsAShorterExposure) {
  const RenderOptions options = Options("out");
  RenderDataset(options);
  ExpectValid(options.out_dir);
  const DatasetInfo info = ReadDatasetInfo(options.out_dir);
  ASSERT_TRUE(info.sensor.has_value());
  EXPECT_EQ(*info.sensor, MakeSensorRecord(options.sensor, CameraSensitivities(options.sensor, 4, options.seed)));
  const std::vector<ExposureRow> rows = ReadExposureCsv(ExposurePath(options.out_dir), kFrames, info.rig);
  ASSERT_EQ(rows.size(), 4u * kFrames);
  for (int f = 0; f < kFrames; ++f) {
    const ExposureRow& cam0 = rows[4 * f];
    const ExposureRow& cam2 = rows[4 * f + 2];
    EXPECT_EQ(cam0.camera, "cam0");
    EXPECT_GT(cam0.meter_luminance, 1.5 * cam2.meter_luminance) << "frame " << f;  // the sun in cam0's view
    EXPECT_LT(cam0.exposure_ms * cam0.gain, 0.7 * cam2.exposure_ms * cam2.gain) << "frame " << f;
    const double fs = 4095.0, q = info.sensor->camera_sensitivity[0];
    EXPECT_NEAR(cam0.dn_per_radiance,
                cam0.gain * fs / 10000.0 * options.sensor.sensitivity_e_per_ms * q * cam0.exposure_ms, 1e-9);
  }
  EXPECT_EQ(Channels(ImagePath(options.out_dir, "cam0", 0)), 3);
}

TEST_F(SensorDatasetTest, ShardsAndThreadCountsGiveIdenticalFiles) {
  RenderOptions full = Options("full");
  full.frame_begin = 1;
  full.frame_end = 10;  // 9 frames: shard 0 gets 8, shard 1 gets 1
  full.threads = 2;
  RenderDataset(full);
  RenderOptions shard = full;
  shard.out_dir = (root_ / "sharded").string();
  shard.threads = 1;
  shard.shard_count = 2;
  shard.shard_index = 1;
  RenderDataset(shard);
  // The exposure schedule covers the whole range after one shard.
  EXPECT_EQ(ReadFile(ExposurePath(shard.out_dir)), ReadFile(ExposurePath(full.out_dir)));
  shard.shard_index = 0;
  RenderDataset(shard);
  EXPECT_EQ(Files(shard.out_dir), Files(full.out_dir));
  // Resume: a missing frame is redone identically.
  const auto before = Files(full.out_dir);
  fs::remove(ImagePath(full.out_dir, "cam1", 4));
  EXPECT_EQ(RenderDataset(full).frames_rendered, 1);
  EXPECT_EQ(Files(full.out_dir), before);
}

TEST_F(SensorDatasetTest, GrayscaleSensorWritesOneChannelImages) {
  RenderOptions options = Options("gray");
  options.frame_end = 2;
  options.sensor.grayscale = true;
  RenderDataset(options);
  ExpectValid(options.out_dir);
  for (const char* cam : {"cam0", "cam1", "cam2", "cam3"}) EXPECT_EQ(Channels(ImagePath(options.out_dir, cam, 1)), 1);
  EXPECT_TRUE(ReadDatasetInfo(options.out_dir).sensor->grayscale);
}

TEST_F(SensorDatasetTest, ADifferentSensorIsRefusedInTheSameFolder) {
  RenderOptions options = Options("out", "off");
  options.frame_end = 1;
  RenderDataset(options);
  EXPECT_FALSE(ReadDatasetInfo(options.out_dir).sensor.has_value());
  EXPECT_FALSE(fs::exists(ExposurePath(options.out_dir)));
  options.sensor = SensorProfile("ideal");
  try {
    RenderDataset(options);
    ADD_FAILURE() << "expected a refusal";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("'sensor'"), std::string::npos) << e.what();
  }
}

TEST_F(SensorDatasetTest, BadRecordsAreReportedNamingFileAndField) {
  RenderOptions options = Options("out");
  options.frame_end = 2;
  RenderDataset(options);
  const std::string json_path = DatasetJsonPath(options.out_dir);
  const std::string csv_path = ExposurePath(options.out_dir);
  const std::string json_text = ReadFile(json_path), csv_text = ReadFile(csv_path);
  auto expect_issue = [&](const std::string& file, const std::string& field, const std::string& needle) {
    bool found = false;
    for (const ValidationIssue& issue : ValidateDataset(options.out_dir))
      found = found || (issue.file == file && issue.field == field && issue.message.find(needle) != std::string::npos);
    EXPECT_TRUE(found) << file << " " << field << " " << needle;
  };
  nlohmann::json j = nlohmann::json::parse(json_text);
  j["sensor"]["adc_bits"] = 20;
  j["sensor"]["response"] = "gamma";
  j["sensor"]["camera_sensitivity"] = {1.0, 1.0};
  WriteFileAtomic(json_path, j.dump());
  expect_issue(json_path, "/sensor/adc_bits", "out of range");
  expect_issue(json_path, "/sensor/response", "gamma");
  expect_issue(json_path, "/sensor/camera_sensitivity", "expected 4 numbers");
  EXPECT_THROW(ReadDatasetInfo(options.out_dir), std::runtime_error);
  WriteFileAtomic(json_path, json_text);

  std::string bad = csv_text;
  bad.replace(bad.find(",cam1,") + 6, 1, "x");  // exposure_ms of line 3
  WriteFileAtomic(csv_path, bad);
  expect_issue(csv_path, "line 3", "column exposure_ms");
  try {
    ReadExposureCsv(csv_path, 2, ReadDatasetInfo(options.out_dir).rig);
    ADD_FAILURE() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(csv_path + ": line 3: column exposure_ms"), std::string::npos) << e.what();
  }
  WriteFileAtomic(csv_path, csv_text.substr(0, csv_text.rfind("1,cam3")));
  expect_issue(csv_path, "lines", "7 rows");
  fs::remove(csv_path);
  expect_issue(csv_path, "file", "missing");
}

TEST_F(SensorDatasetTest, CommandLineNamesTheSensorOptions) {
  const std::string log = (root_ / "log.txt").string();
  auto run = [&](const std::string& args) {
    const int status = std::system((std::string(ROVO_BINARY) + " render --scene " + scene_dir_ + " --out " +
                                    (root_ / "cli").string() + " --quiet " + args + " > " + log + " 2>&1")
                                       .c_str());
    return std::make_pair(status, ReadFile(log));
  };
  auto [status, text] = run("--noise 2");
  EXPECT_NE(status, 0);
  EXPECT_NE(text.find("--noise was removed"), std::string::npos) << text;
  std::tie(status, text) = run("--read-noise 3");
  EXPECT_NE(status, 0);
  EXPECT_NE(text.find("--sensor ideal"), std::string::npos) << text;
  std::tie(status, text) = run("--sensor realistic --adc-bits 4");
  EXPECT_NE(status, 0);
  EXPECT_NE(text.find("--adc-bits"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(root_ / "cli" / "dataset.json"));
}

// --realistic turns on the realistic sensor and timing; an option given beside it wins.
TEST_F(SensorDatasetTest, RealisticProfileSetsSensorAndTimingUnlessOverridden) {
  const std::string out = (root_ / "realistic").string();
  const std::string command = std::string(ROVO_BINARY) + " render --scene " + scene_dir_ + " --out " + out +
                              " --rig omnimvs4 --scale 0.1 --spp 1 --frames 0:2 --quiet --realistic "
                              "--rolling-shutter-ms 5 > " +
                              (root_ / "log.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << ReadFile((root_ / "log.txt").string());
  const DatasetInfo info = ReadDatasetInfo(out);
  ASSERT_TRUE(info.sensor.has_value());
  EXPECT_EQ(info.sensor->profile, "realistic");
  ASSERT_TRUE(info.timing.has_value());
  EXPECT_EQ(info.timing->exposure, "sensor");
  EXPECT_EQ(info.timing->rolling_shutter_ms, 5.0);  // the override
  EXPECT_EQ(info.timing->trigger_offset_std_ms, RealisticTiming().trigger_offset_std_ms);
  EXPECT_EQ(info.timing->trigger_offset_ms.size(), 4u);
  ExpectValid(out);
}

}  // namespace
}  // namespace rovo
