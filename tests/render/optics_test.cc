// The lens model of image quality (render/optics.h) against its analytic expectations: the PSF's
// sigma from MTF50 and an edge's blur width on the axis and towards the rim, the vignetting law, the
// colour planes' offset at the rim, the veiling glare; the seeded per-camera spread; the profiles and
// the dataset record.
#include "render/optics.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "datasets/dataset.h"
#include "datasets/rig.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

constexpr int kSize = 201;
constexpr double kFocal = 52.0;  // equidistant: the 110-degree rim at 99.8 px from the centre (100, 100)

Camera TestCamera() {
  Camera cam;
  cam.model = CameraModelId::kEquidistant;
  cam.width = cam.height = kSize;
  cam.params = {kFocal, kFocal, 100.0, 100.0, 0.0, 0.0, 0.0, 0.0};
  cam.max_fov_deg = 220.0;
  cam.Check("optics test camera");
  return cam;
}

struct Rays {
  std::vector<Eigen::Vector3f> bearing;
  std::vector<uint8_t> valid;
};

Rays TestRays(const Camera& cam) {
  Rays r;
  r.bearing.assign(kSize * kSize, Eigen::Vector3f::Zero());
  r.valid.assign(kSize * kSize, 0);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const auto b = cam.Unproject(Eigen::Vector2d(x, y));
      if (!b || !cam.InFov(*b)) continue;
      r.bearing[y * kSize + x] = b->normalized().cast<float>();
      r.valid[y * kSize + x] = 1;
    }
  return r;
}

// An optics profile with every effect off, to switch on one at a time.
OpticsSettings NoEffects() {
  OpticsSettings s;
  s.enabled = true;
  s.profile = "test";
  return s;
}

// Field angle of pixel (x, y) of the equidistant test camera.
double ThetaAt(double x, double y) { return std::hypot(x - 100.0, y - 100.0) / kFocal; }

std::vector<float> Image(const std::function<float(int, int)>& f) {
  std::vector<float> im(kSize * kSize * 3);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (int k = 0; k < 3; ++k) im[(y * kSize + x) * 3 + k] = f(x, y);
  return im;
}

// Variance of the line-spread function (the derivative of an edge profile) along `profile`.
double LsfVariance(const std::vector<double>& profile) {
  double sum = 0.0, mean = 0.0, var = 0.0;
  std::vector<double> lsf(profile.size() - 1);
  for (size_t i = 0; i + 1 < profile.size(); ++i) {
    lsf[i] = profile[i + 1] - profile[i];
    sum += lsf[i];
    mean += lsf[i] * i;
  }
  mean /= sum;
  for (size_t i = 0; i < lsf.size(); ++i) var += lsf[i] * (i - mean) * (i - mean);
  return var / sum;
}

TEST(OpticsTest, GaussianSigmaHasHalfModulationAtMtf50) {
  for (double f50 : {0.1, 0.2, 0.35}) {
    const double sigma = GaussianSigmaFromMtf50(f50);
    EXPECT_NEAR(std::exp(-2.0 * M_PI * M_PI * sigma * sigma * f50 * f50), 0.5, 1e-12);
  }
}

TEST(OpticsTest, EdgeBlurWidthMatchesThePsfOnTheAxisAndTowardsTheRim) {
  const Camera cam = TestCamera();
  const Rays rays = TestRays(cam);
  OpticsSettings s = NoEffects();
  s.mtf50_centre = 0.25;
  s.mtf50_rim = 0.08;
  const LensOptics lens(s, cam, rays.bearing, rays.valid, 1.0);
  // A vertical edge through the centre: the row profile at the centre row.
  std::vector<float> vertical = Image([](int x, int) { return x > 100 ? 1.0f : 0.0f; });
  lens.Apply(&vertical);
  std::vector<double> row;
  for (int x = 85; x <= 116; ++x) row.push_back(vertical[(100 * kSize + x) * 3 + 1]);
  const double sigma_centre = PsfSigma(s, 1.0, ThetaAt(100, 100), M_PI * 110.0 / 180.0);
  EXPECT_NEAR(std::sqrt(LsfVariance(row)), sigma_centre, 0.03 * sigma_centre);
  // A horizontal edge seen at column 175 (75 px from the centre, u = 0.75): the column profile.
  std::vector<float> horizontal = Image([](int, int y) { return y > 100 ? 1.0f : 0.0f; });
  lens.Apply(&horizontal);
  std::vector<double> column;
  for (int y = 80; y <= 121; ++y) column.push_back(horizontal[(y * kSize + 175) * 3 + 1]);
  const double sigma_rim = PsfSigma(s, 1.0, ThetaAt(175, 100), M_PI * 110.0 / 180.0);
  EXPECT_GT(sigma_rim, 1.5 * sigma_centre);
  EXPECT_NEAR(std::sqrt(LsfVariance(column)), sigma_rim, 0.03 * sigma_rim);
  // The camera's MTF50 factor scales the PSF inversely.
  EXPECT_NEAR(PsfSigma(s, 0.5, 0.3, 1.9), 2.0 * PsfSigma(s, 1.0, 0.3, 1.9), 1e-12);
}

TEST(OpticsTest, VignettingFollowsTheFallOffLaw) {
  const Camera cam = TestCamera();
  const Rays rays = TestRays(cam);
  OpticsSettings s = NoEffects();
  s.falloff_angle_scale = 0.3;
  s.rim_illumination = 0.6;
  const LensOptics lens(s, cam, rays.bearing, rays.valid, 1.0);
  std::vector<float> flat = Image([](int, int) { return 2.0f; });
  lens.Apply(&flat);
  const double theta_max = M_PI * 110.0 / 180.0;
  for (const auto& [x, y] :
       std::vector<std::pair<int, int>>{{100, 100}, {150, 100}, {100, 30}, {170, 160}, {199, 100}}) {
    const double theta = ThetaAt(x, y), u = theta / theta_max;
    const double expected = std::pow(std::cos(0.3 * theta), 4) * (1.0 - 0.4 * u * u);
    EXPECT_NEAR(flat[(y * kSize + x) * 3] / 2.0, expected, 1e-5) << x << "," << y;
  }
  // The rim over the centre: cos^4(0.3 theta_max) * 0.6 at the edge of the field.
  EXPECT_NEAR(LensRelativeIllumination(s, theta_max, theta_max), std::pow(std::cos(0.3 * theta_max), 4) * 0.6, 1e-12);
  EXPECT_LT(flat[(100 * kSize + 199) * 3] / flat[(100 * kSize + 100) * 3], 0.45);
}

TEST(OpticsTest, LateralColourShiftsTheColourPlanesAtTheRim) {
  const Camera cam = TestCamera();
  const Rays rays = TestRays(cam);
  OpticsSettings s = NoEffects();
  s.lateral_ca_red = 0.01;
  s.lateral_ca_blue = -0.01;
  const LensOptics lens(s, cam, rays.bearing, rays.valid, 1.0);
  ASSERT_NEAR(lens.principal_point().x(), 100.0, 1e-9);
  // A smooth vertical line at x = 180, 80 px from the principal point.
  std::vector<float> line = Image([](int x, int) { return std::exp(-0.5f * (x - 180.0f) * (x - 180.0f) / 2.25f); });
  lens.Apply(&line);
  auto centroid = [&](int k) {
    double sum = 0.0, moment = 0.0;
    for (int x = 165; x <= 195; ++x) {
      const double v = line[(100 * kSize + x) * 3 + k];
      sum += v;
      moment += v * x;
    }
    return moment / sum;
  };
  EXPECT_NEAR(centroid(1), 180.0, 1e-3);
  EXPECT_NEAR(centroid(0), 100.0 + 80.0 * 1.01, 0.03);
  EXPECT_NEAR(centroid(2), 100.0 + 80.0 * 0.99, 0.03);
}

TEST(OpticsTest, VeilingGlareAddsAFractionOfTheMean) {
  const Camera cam = TestCamera();
  const Rays rays = TestRays(cam);
  OpticsSettings s = NoEffects();
  s.falloff_angle_scale = 0.2;
  s.veiling_glare = 0.05;
  const LensOptics lens(s, cam, rays.bearing, rays.valid, 1.0);
  std::vector<float> flat = Image([](int, int) { return 1.0f; });
  lens.Apply(&flat);
  double mean = 0.0;
  int n = 0;
  for (size_t i = 0; i < rays.valid.size(); ++i)
    if (rays.valid[i]) {
      mean += lens.illumination()[i];
      ++n;
    }
  mean /= n;
  const size_t centre = 100 * kSize + 100, rim = 100 * kSize + 195;
  EXPECT_NEAR(flat[centre * 3], 1.0 + 0.05 * mean, 1e-5);
  EXPECT_NEAR(flat[rim * 3], lens.illumination()[rim] + 0.05 * mean, 1e-5);
  EXPECT_EQ(flat[0], 1.0f);  // an invalid corner pixel stays as it is
}

TEST(OpticsTest, CameraMtf50FactorsAreSeededAndSpread) {
  OpticsSettings s = OpticsProfile("realistic");
  const std::vector<double> a = CameraMtf50Factors(s, 4, 7), b = CameraMtf50Factors(s, 4, 7);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, CameraMtf50Factors(s, 4, 8));
  EXPECT_NE(a[0], a[1]);
  for (double m : a) EXPECT_NEAR(m, 1.0, 5.0 * s.mtf50_spread);
  s.mtf50_spread = 0.0;
  for (double m : CameraMtf50Factors(s, 4, 7)) EXPECT_EQ(m, 1.0);
}

TEST(OpticsTest, ProfilesAndOverridesAreChecked) {
  EXPECT_FALSE(OpticsProfile("off").enabled);
  EXPECT_TRUE(OpticsProfile("realistic").enabled);
  EXPECT_THROW(OpticsProfile("sharp"), std::invalid_argument);
  OpticsOverrides o;
  o.veiling_glare = 0.1;
  EXPECT_THROW(MakeOpticsSettings("off", o), std::invalid_argument);
  const OpticsSettings custom = MakeOpticsSettings("realistic", o);
  EXPECT_EQ(custom.profile, "custom");
  EXPECT_EQ(custom.veiling_glare, 0.1);
  OpticsOverrides bad;
  bad.mtf50_centre = 0.0;  // the rim keeps its blur: both or neither
  EXPECT_THROW(MakeOpticsSettings("realistic", bad), std::invalid_argument);
  OpticsSettings steep = OpticsProfile("realistic");
  steep.falloff_angle_scale = 0.9;  // 0.9 * 110 degrees > 90
  const Camera cam = TestCamera();
  const Rays rays = TestRays(cam);
  EXPECT_THROW(LensOptics(steep, cam, rays.bearing, rays.valid, 1.0), std::invalid_argument);
}

TEST(OpticsTest, DatasetRecordRoundTrips) {
  const std::string dir = (fs::temp_directory_path() / ("rovo_optics_record_" + std::to_string(getpid()))).string();
  DatasetInfo info;
  info.frame_count = 1;
  info.rig = MakeRigPreset("rovo4");
  const OpticsSettings s = OpticsProfile("realistic");
  info.optics = MakeOpticsRecord(s, CameraMtf50Factors(s, 4, 3));
  WriteDatasetInfo(dir, info);
  const DatasetInfo back = ReadDatasetInfo(dir);
  ASSERT_TRUE(back.optics.has_value());
  EXPECT_EQ(*back.optics, *info.optics);
  // A bad field is named.
  info.optics->rim_illumination = 0.0;
  WriteDatasetInfo(dir, info);
  try {
    ReadDatasetInfo(dir);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/optics/rim_illumination"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rovo
