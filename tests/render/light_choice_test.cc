// The light choice of render/tracer.h: many lights through the 3-D light grid against the sum of the
// formula, the strongest lights' share floor, and the drawn-light estimator (ShadeSettings::
// sample_lights) against the exact sum.
#include <gtest/gtest.h>

#include <random>

#include "render/tracer_internal.h"
#include "tests/render/light_scene.h"

namespace rovo {
namespace {

using testing::CompareWithFormula;
using testing::DarkPlaneScene;
using testing::Expected;
using testing::RedAt;
using testing::Rendered;

constexpr double kKs = 0.3, kShininess = 40.0;

// 40 seeded lights over the plane: points with and without a range and spots of 50 to 180 degrees
// pointing mostly down.
std::vector<Light> ManyLights() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Light> lights;
  for (int i = 0; i < 40; ++i) {
    Light l;
    l.name = "light_" + std::to_string(i);
    l.position = Eigen::Vector3d(-5.0 + 10.0 * unit(rng), -5.0 + 10.0 * unit(rng), 0.4 + 2.5 * unit(rng));
    l.intensity = Eigen::Vector3f(0.16f, 0.12f, 0.08f) * static_cast<float>(0.5 + unit(rng));
    const int kind = i % 4;
    if (kind >= 1) l.range = 2.0 + 5.0 * unit(rng);
    if (kind >= 2) {
      l.spot = true;
      l.spot_angle_deg = kind == 2 ? 50.0 + 100.0 * unit(rng) : 180.0;
      l.spot_blend = unit(rng);
      l.spot_direction = Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, -1.0);
    }
    lights.push_back(l);
  }
  return lights;
}

Rendered Render(Tracer& tracer, const ShadeSettings& settings) {
  Rendered r;
  r.rays = CameraRays::Make(r.camera, 1, settings.spp);
  tracer.Render(r.rays, r.world_from_cam, settings, &r.image);
  return r;
}

TEST(LightChoiceTest, ManyLightsThroughTheGridMatchTheSumOfTheFormula) {
  for (const bool glossy : {false, true}) {
    Scene scene = DarkPlaneScene();
    if (glossy) {
      scene.materials[0].specular = static_cast<float>(kKs);
      scene.materials[0].shininess = static_cast<float>(kShininess);
    }
    scene.lights = ManyLights();
    Tracer tracer(scene);
    ShadeSettings settings;
    settings.want_depth = true;
    settings.max_shadowed_lights = 0;  // every light without a shadow ray: the plain sum
    const Rendered r = Render(tracer, settings);
    int worst = 0, many_lit = 0, spot_lit = 0;
    const int compared = CompareWithFormula(
        r,
        [&](const Eigen::Vector3d& x) {
          Eigen::Vector3d sum = Eigen::Vector3d::Zero();
          int lit = 0;
          bool spot = false;
          for (const Light& l : scene.lights) {
            const Eigen::Vector3d e =
                Expected(l, x, r.world_from_cam.translation, glossy ? kKs : 0.0, glossy ? kShininess : 0.0);
            sum += e;
            lit += e.sum() > 1e-3;
            spot = spot || (l.spot && e.sum() > 0.01);
          }
          many_lit += lit >= 5;
          spot_lit += spot;
          return sum;
        },
        &worst);
    EXPECT_GT(compared, 20000) << "glossy " << glossy;
    EXPECT_LE(worst, 1) << "8-bit levels, glossy " << glossy;
    EXPECT_GT(many_lit, 5000) << "pixels lit by five or more lights";
    EXPECT_GT(spot_lit, 1500) << "pixels where a spot light adds a tenth of a code or more";
  }
}

// A strong light far to the side and a weak one straight above a small cube: the weak light's share
// of the light under the cube is below 10 %.
struct FloorScene {
  Scene scene = DarkPlaneScene();
  FloorScene() {
    testing::AddOccluderCube(&scene);
    Light strong, weak;
    strong.name = "strong";
    strong.position = Eigen::Vector3d(-1.0, 0.0, 1.5);
    strong.intensity = Eigen::Vector3f(2.0f, 2.0f, 2.0f);
    weak.name = "weak";
    weak.position = Eigen::Vector3d(1.0, 0.0, 1.2);
    weak.intensity = Eigen::Vector3f(0.03f, 0.03f, 0.03f);
    scene.lights = {strong, weak};
  }
};

// 300 narrow spots without a range (every hit looks at all of them, 76 blocks, more than the lanes a
// hit holds) and, last, a bright bulb straight above the occluder: the blocks that light nothing make
// room, so the bulb is still ranked and its shadow cast.
TEST(LightChoiceTest, ManyUnlitBlocksLeaveRoomForTheStrongestLight) {
  Scene scene = DarkPlaneScene();
  testing::AddOccluderCube(&scene);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 300; ++i) {
    Light spot;
    spot.name = "spot_" + std::to_string(i);
    spot.position = Eigen::Vector3d(-5.0 + 10.0 * unit(rng), -5.0 + 10.0 * unit(rng), 2.0);
    spot.intensity = Eigen::Vector3f(0.01f, 0.01f, 0.01f);
    spot.spot = true;
    spot.spot_angle_deg = 10.0;
    spot.spot_direction = Eigen::Vector3d(0.0, 0.0, -1.0);
    scene.lights.push_back(spot);
  }
  Light bulb;
  bulb.name = "bulb";
  bulb.position = Eigen::Vector3d(1.0, 0.0, 1.2);
  bulb.intensity = Eigen::Vector3f(1.0f, 1.0f, 1.0f);
  scene.lights.push_back(bulb);
  ASSERT_GT(scene.lights.size(), static_cast<size_t>(tracer_internal::kMaxLightLanes));
  Tracer tracer(scene);
  ShadeSettings settings;
  const Rendered shadowed = Render(tracer, settings);
  settings.max_shadowed_lights = 0;
  const Rendered unshadowed = Render(tracer, settings);
  const Eigen::Vector3d in_shadow(1.0, 0.55, 0.0);
  EXPECT_GT(RedAt(unshadowed, in_shadow), 30);
  EXPECT_LT(RedAt(shadowed, in_shadow), RedAt(unshadowed, in_shadow) - 20) << "the bulb's shadow is cast";
}

TEST(LightChoiceTest, LightsBelowTheShareFloorGetNoShadowRay) {
  FloorScene f;
  Tracer tracer(f.scene);
  ShadeSettings settings;
  settings.min_shadowed_share = 0.0f;
  const Rendered all = Render(tracer, settings);
  settings.min_shadowed_share = 0.1f;
  const Rendered floored = Render(tracer, settings);
  // In the weak light's shadow only (the strong light reaches it past the cube, the camera sees it
  // past the cube), where the weak light has about 9 % of the light.
  const Eigen::Vector3d under(1.0, 0.45, 0.0);
  EXPECT_GT(RedAt(floored, under), RedAt(all, under)) << "the weak light is added without its shadow";
  // Where the weak light is not shadowed, the floor changes nothing.
  const Eigen::Vector3d open(-0.5, -0.8, 0.0);
  EXPECT_EQ(RedAt(floored, open), RedAt(all, open));
}

// Mean linear radiance over the hit pixels.
double MeanRadiance(const Rendered& r) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < r.image.depth.size(); ++i) {
    if (r.image.depth[i] <= 0.0f) continue;
    for (int c = 0; c < 3; ++c) sum += r.image.linear[3 * i + c];
    n += 3;
  }
  return n ? sum / n : 0.0;
}

TEST(LightChoiceTest, DrawnLightEstimatesTheShadowedSumWithoutBias) {
  FloorScene f;
  f.scene.lights[1].intensity = Eigen::Vector3f(1.0f, 1.0f, 1.0f);  // both lights matter: both are drawn
  Tracer tracer(f.scene);
  ShadeSettings settings;
  settings.spp = 2;
  settings.want_depth = true;
  settings.linear_output = true;
  const Rendered exact = Render(tracer, settings);  // two lights, two shadow rays: the exact sum
  settings.sample_lights = true;
  const Rendered drawn = Render(tracer, settings);
  const double mean_exact = MeanRadiance(exact), mean_drawn = MeanRadiance(drawn);
  ASSERT_GT(mean_exact, 0.01);
  EXPECT_NEAR(mean_drawn / mean_exact, 1.0, 0.01);
  // It is an estimate: some pixels differ from the exact sum (in a shadow of one light only).
  int differ = 0;
  for (size_t i = 0; i < exact.image.linear.size(); ++i)
    differ += std::abs(exact.image.linear[i] - drawn.image.linear[i]) > 1e-3f * (1.0f + exact.image.linear[i]);
  EXPECT_GT(differ, 100);
}

TEST(LightChoiceTest, DrawingFromOneLightIsExact) {
  Scene scene = DarkPlaneScene();
  const Light light = testing::Bulb();
  scene.lights.push_back(light);
  Tracer tracer(scene);
  ShadeSettings settings;
  settings.spp = 2;
  const Rendered strongest = Render(tracer, settings);
  settings.sample_lights = true;
  const Rendered drawn = Render(tracer, settings);
  EXPECT_EQ(strongest.image.rgb, drawn.image.rgb);
}

}  // namespace
}  // namespace rovo
