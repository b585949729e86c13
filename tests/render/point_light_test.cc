// Point and spot lights, emission and the Blinn-Phong highlight against the formula of
// render/tracer.h, on a plane seen from above with no sun, sky or ambient light.
#include <gtest/gtest.h>

#include "tests/render/light_scene.h"

namespace rovo {
namespace {

using testing::CompareWithFormula;
using testing::DarkPlaneScene;
using testing::Expected;
using testing::RedAt;
using testing::RenderDown;
using testing::Rendered;

TEST(PointLightTest, PointLightMatchesTheFormula) {
  Scene scene = DarkPlaneScene();
  const Light light = testing::Bulb();
  scene.lights.push_back(light);
  Tracer tracer(scene);
  const Rendered r = RenderDown(tracer);
  int worst = 0;
  const int compared = CompareWithFormula(
      r, [&](const Eigen::Vector3d& x) { return Expected(light, x, r.world_from_cam.translation, 0, 0); }, &worst);
  EXPECT_GT(compared, 20000);
  EXPECT_LE(worst, 1) << "8-bit levels";
  // Not vacuous: the pool of light is bright below the bulb and dark far away.
  const Eigen::Vector2d below = r.camera.Project(r.world_from_cam.Inverse() * Eigen::Vector3d(0.4, -0.3, 0)).value();
  const size_t i = static_cast<size_t>(std::lround(below.y())) * r.camera.width + std::lround(below.x());
  EXPECT_GT(r.image.rgb[3 * i], 100);  // 0.5 / pi * 2 / 1.2^2 = 0.22 linear, sRGB 130
}

TEST(PointLightTest, SpotConeRangeWindowAndHighlightMatchTheFormula) {
  Scene scene = DarkPlaneScene();
  scene.materials[0].specular = 0.3f;
  scene.materials[0].shininess = 40.0f;
  Light spot;
  spot.name = "spot";
  spot.position = Eigen::Vector3d(-0.5, 0.2, 1.5);
  spot.intensity = Eigen::Vector3f(3.0f, 3.0f, 2.0f);
  spot.range = 4.0;
  spot.spot = true;
  spot.spot_direction = Eigen::Vector3d(0.4, 0.0, -1.0);
  spot.spot_angle_deg = 70.0;
  spot.spot_blend = 0.3;
  scene.lights.push_back(spot);
  Tracer tracer(scene);
  const Rendered r = RenderDown(tracer);
  int worst = 0;
  const int compared = CompareWithFormula(
      r, [&](const Eigen::Vector3d& x) { return Expected(spot, x, r.world_from_cam.translation, 0.3, 40.0); }, &worst);
  EXPECT_GT(compared, 20000);
  EXPECT_LE(worst, 1) << "8-bit levels";
  // The cone and the range leave most of the plane black.
  int black = 0, hits = 0;
  for (size_t i = 0; i < r.image.depth.size(); ++i) {
    if (r.image.depth[i] <= 0.0f) continue;
    ++hits;
    black += r.image.rgb[3 * i] == 0;
  }
  EXPECT_GT(black, hits / 3);
  EXPECT_LT(black, hits - 1000);
}

TEST(PointLightTest, ShadowRaysOnlyForTheStrongestLights) {
  Scene scene = DarkPlaneScene();
  testing::AddOccluderCube(&scene);
  Light light;
  light.name = "bulb";
  light.position = Eigen::Vector3d(1.0, 0.0, 1.2);  // straight above the cube
  light.intensity = Eigen::Vector3f(1.0f, 1.0f, 1.0f);
  scene.lights.push_back(light);
  Tracer tracer(scene);
  // A plane point in the cube's shadow that the camera above the origin sees past the cube, and
  // one the light reaches.
  const Eigen::Vector3d shadowed(1.0, 0.55, 0.0), lit(0.0, -0.6, 0.0);
  const Rendered with_shadows = RenderDown(tracer, 4);
  EXPECT_EQ(RedAt(with_shadows, shadowed), 0);
  EXPECT_GT(RedAt(with_shadows, lit), 30);
  // max_shadowed_lights = 0: every light is added without a shadow ray (documented), so the
  // point under the cube is lit.
  const Rendered without = RenderDown(tracer, 0);
  EXPECT_GT(RedAt(without, shadowed), 30);
  EXPECT_EQ(RedAt(without, lit), RedAt(with_shadows, lit));
}

TEST(PointLightTest, LightOnAMovingObjectFollowsIt) {
  Scene scene = DarkPlaneScene(2);
  scene.meshes.push_back(testing::MakeCube("lamp_post", 0.05f, 0));
  Object post;
  post.name = "lamp_post";
  post.mesh = 1;
  post.id = 1;
  post.world_from_object_per_frame = {Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0, 0.0, 1.0)),
                                      Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1.0, 0.5, 1.0))};
  scene.objects.push_back(post);
  Light light;
  light.name = "lantern";
  light.position = Eigen::Vector3d(0.0, 0.0, -0.2);  // below the cube, in its frame
  light.intensity = Eigen::Vector3f(1.0f, 1.0f, 1.0f);
  light.object = 1;
  scene.lights.push_back(light);
  Tracer tracer(scene);
  for (int frame = 0; frame < 2; ++frame) {
    tracer.SetFrame(frame);
    const Rendered r = RenderDown(tracer);
    Light world_light = light;
    world_light.position = post.world_from_object_per_frame[frame] * light.position;
    int worst = 0;
    // Pixels whose line to the light passes the cube are shadowed: compare only those far enough
    // from the cube's footprint.
    const Eigen::Vector2d foot = world_light.position.head<2>();
    const int compared = CompareWithFormula(
        r,
        [&](const Eigen::Vector3d& x) {
          if ((x.head<2>() - foot).norm() < 0.3) return Eigen::Vector3d(-1, -1, -1);
          return Expected(world_light, x, r.world_from_cam.translation, 0, 0);
        },
        &worst);
    EXPECT_GT(compared, 20000) << "frame " << frame;
    EXPECT_LE(worst, 1) << "frame " << frame;
  }
}

TEST(PointLightTest, EmissionIsAddedToTheSurface) {
  Scene scene = DarkPlaneScene();
  scene.materials[0].emission = Eigen::Vector3f(0.2f, 0.05f, 0.0f);
  Tracer tracer(scene);
  const Rendered r = RenderDown(tracer);
  const int want_r = static_cast<int>(std::lround(LinearToSrgb(0.2f) * 255.0f));
  const int want_g = static_cast<int>(std::lround(LinearToSrgb(0.05f) * 255.0f));
  int hits = 0;
  for (size_t i = 0; i < r.image.depth.size(); ++i) {
    if (r.image.depth[i] <= 0.0f) continue;
    ++hits;
    ASSERT_EQ(r.image.rgb[3 * i], want_r);
    ASSERT_EQ(r.image.rgb[3 * i + 1], want_g);
    ASSERT_EQ(r.image.rgb[3 * i + 2], 0);
  }
  EXPECT_GT(hits, 10000);
}

}  // namespace
}  // namespace rovo
