// Point and spot lights, emission and the Blinn-Phong highlight against the formula of
// render/tracer.h, on a plane seen from above with no sun, sky or ambient light.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "datasets/rig.h"
#include "render/texture.h"
#include "render/tracer.h"
#include "tests/render/box_scene.h"

namespace rovo {
namespace {

constexpr double kAlbedo = 0.5;

// A 100 m plane at z = 0 (material 0: matte grey; material 1 available for a glossy variant), an
// optional occluder cube (object 1), no sun, black sky, ambient 0; one frame unless `frames`.
Scene DarkPlaneScene(int frames = 1) {
  Scene scene;
  Material plane;
  plane.name = "plane";
  plane.base_color = Eigen::Vector3f::Constant(static_cast<float>(kAlbedo));
  scene.materials.push_back(plane);
  scene.meshes.push_back(testing::MakeQuad("plane", Eigen::Vector3f(-50, -50, 0), Eigen::Vector3f(50, -50, 0),
                                           Eigen::Vector3f(50, 50, 0), Eigen::Vector3f(-50, 50, 0), 0));
  scene.meshes[0].uvs.clear();
  Object o;
  o.name = "plane";
  o.mesh = 0;
  scene.objects.push_back(o);
  Lighting& l = scene.lighting;
  l.sun_radiance.setZero();
  l.sky_zenith.setZero();
  l.sky_horizon.setZero();
  l.ambient = 0.0f;
  l.exposure = 1.0f;
  for (int f = 0; f < frames; ++f) {
    StampedPose pose;
    pose.timestamp = 0.1 * f;
    scene.rig_trajectory.push_back(pose);
  }
  return scene;
}

// A camera 3 m above the origin looking straight down (image x along world +x).
Rigid3 LookingDown() {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(1, 0, 0);
  r.col(1) = Eigen::Vector3d(0, -1, 0);
  r.col(2) = Eigen::Vector3d(0, 0, -1);
  return Rigid3(r, Eigen::Vector3d(0, 0, 3));
}

Camera DownCamera() { return MakeRigPreset("omnimvs4").Scaled(0.25).cameras[0].camera; }

struct Rendered {
  Camera camera = DownCamera();
  CameraRays rays;
  CameraImage image;
  Rigid3 world_from_cam = LookingDown();
};

Rendered RenderDown(Tracer& tracer, int max_shadowed = 4) {
  Rendered r;
  r.rays = CameraRays::Make(r.camera, 1);
  ShadeSettings settings;
  settings.want_depth = true;
  settings.max_shadowed_lights = max_shadowed;
  tracer.Render(r.rays, r.world_from_cam, settings, &r.image);
  return r;
}

// The formula of render/tracer.h for one light at plane point x (normal +z, viewer at `eye`).
Eigen::Vector3d Expected(const Light& light, const Eigen::Vector3d& x, const Eigen::Vector3d& eye, double ks,
                         double shininess) {
  const Eigen::Vector3d to = light.position - x;
  const double d = to.norm();
  const Eigen::Vector3d l = to / d, n(0, 0, 1), v = (eye - x).normalized();
  const double cos_l = std::max(0.0, n.dot(l));
  double a = 1.0;
  if (light.spot) {
    const double c = -l.dot(light.spot_direction.normalized());
    const double c0 = std::cos(0.5 * light.spot_angle_deg * M_PI / 180.0), smooth = (1.0 - c0) * light.spot_blend;
    if (c <= c0) return Eigen::Vector3d::Zero();
    const double u = (c - c0) / smooth;
    a = c * (c - c0 < smooth ? u * u * (3.0 - 2.0 * u) : 1.0);
  }
  double w = 1.0;
  if (light.range > 0.0) {
    if (d >= light.range) return Eigen::Vector3d::Zero();
    const double q = std::pow(d / light.range, 4.0);
    w = (1.0 - q) * (1.0 - q);
  }
  const double nh = std::max(0.0, n.dot((l + v).normalized()));
  const double brdf = kAlbedo / M_PI + ks * (shininess + 8.0) / (8.0 * M_PI) * std::pow(nh, shininess);
  return brdf * light.intensity.cast<double>() * cos_l / (d * d) * a * w;
}

// Compares every hit pixel with the 8-bit sRGB encoding of `expected(x)`; returns the number of
// pixels compared (those whose expected value is not clipped).
template <typename F>
int CompareWithFormula(const Rendered& r, F&& expected, int* worst_out) {
  int compared = 0, worst = 0;
  for (size_t i = 0; i < r.image.depth.size(); ++i) {
    if (!r.rays.valid[i] || r.image.depth[i] <= 0.0f) continue;
    const Eigen::Vector3d dir = r.world_from_cam.rotation * r.rays.bearing[i].cast<double>();
    const Eigen::Vector3d x = r.world_from_cam.translation + r.image.depth[i] * dir;
    const Eigen::Vector3d e = expected(x);
    for (int c = 0; c < 3; ++c) {
      if (e[c] < 0.0 || e[c] >= 1.0) continue;
      const int want = static_cast<int>(std::lround(LinearToSrgb(static_cast<float>(e[c])) * 255.0f));
      worst = std::max(worst, std::abs(want - static_cast<int>(r.image.rgb[3 * i + c])));
      ++compared;
    }
  }
  *worst_out = worst;
  return compared;
}

TEST(PointLightTest, PointLightMatchesTheFormula) {
  Scene scene = DarkPlaneScene();
  Light light;
  light.name = "bulb";
  light.position = Eigen::Vector3d(0.4, -0.3, 1.2);
  light.intensity = Eigen::Vector3f(2.0f, 1.0f, 0.4f);
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
  scene.meshes.push_back(testing::MakeCube("occluder", 0.2f, 0));
  Object cube;
  cube.name = "occluder";
  cube.mesh = 1;
  cube.world_from_object = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1.0, 0.0, 0.6));
  scene.objects.push_back(cube);
  Light light;
  light.name = "bulb";
  light.position = Eigen::Vector3d(1.0, 0.0, 1.2);  // straight above the cube
  light.intensity = Eigen::Vector3f(1.0f, 1.0f, 1.0f);
  scene.lights.push_back(light);
  Tracer tracer(scene);
  auto red_at = [](const Rendered& r, const Eigen::Vector3d& p) {
    const Eigen::Vector2d uv = r.camera.Project(r.world_from_cam.Inverse() * p).value();
    return static_cast<int>(
        r.image.rgb[3 * (static_cast<size_t>(std::lround(uv.y())) * r.camera.width + std::lround(uv.x()))]);
  };
  // A plane point in the cube's shadow that the camera above the origin sees past the cube, and
  // one the light reaches.
  const Eigen::Vector3d shadowed(1.0, 0.55, 0.0), lit(0.0, -0.6, 0.0);
  const Rendered with_shadows = RenderDown(tracer, 4);
  EXPECT_EQ(red_at(with_shadows, shadowed), 0);
  EXPECT_GT(red_at(with_shadows, lit), 30);
  // max_shadowed_lights = 0: every light is added without a shadow ray (documented), so the
  // point under the cube is lit.
  const Rendered without = RenderDown(tracer, 0);
  EXPECT_GT(red_at(without, shadowed), 30);
  EXPECT_EQ(red_at(without, lit), red_at(with_shadows, lit));
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
