#pragma once
// A dark plane seen from above and the point/spot light formula of render/tracer.h, for the light
// tests (point_light_test.cc, light_choice_test.cc).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "datasets/rig.h"
#include "render/texture.h"
#include "render/tracer.h"
#include "tests/render/box_scene.h"

namespace rovo {
namespace testing {

constexpr double kAlbedo = 0.5;

// A 100 m plane at z = 0 (material 0: matte grey; material 1 available for a glossy variant), an
// optional occluder cube (object 1), no sun, black sky, ambient 0; one frame unless `frames`.
inline Scene DarkPlaneScene(int frames = 1) {
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
inline Rigid3 LookingDown() {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(1, 0, 0);
  r.col(1) = Eigen::Vector3d(0, -1, 0);
  r.col(2) = Eigen::Vector3d(0, 0, -1);
  return Rigid3(r, Eigen::Vector3d(0, 0, 3));
}

inline Camera DownCamera() { return MakeRigPreset("omnimvs4").Scaled(0.25).cameras[0].camera; }

struct Rendered {
  Camera camera = DownCamera();
  CameraRays rays;
  CameraImage image;
  Rigid3 world_from_cam = LookingDown();
};

inline Rendered RenderDown(Tracer& tracer, int max_shadowed = 4) {
  Rendered r;
  r.rays = CameraRays::Make(r.camera, 1);
  ShadeSettings settings;
  settings.want_depth = true;
  settings.max_shadowed_lights = max_shadowed;
  tracer.Render(r.rays, r.world_from_cam, settings, &r.image);
  return r;
}

// The formula of render/tracer.h for one light at plane point x (normal +z, viewer at `eye`).
inline Eigen::Vector3d Expected(const Light& light, const Eigen::Vector3d& x, const Eigen::Vector3d& eye, double ks,
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

// Adds the occluder: a cube of half size 0.2 m centred at (1, 0, 0.6), object 1.
inline void AddOccluderCube(Scene* scene) {
  scene->meshes.push_back(MakeCube("occluder", 0.2f, 0));
  Object cube;
  cube.name = "occluder";
  cube.mesh = static_cast<int>(scene->meshes.size()) - 1;
  cube.world_from_object = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1.0, 0.0, 0.6));
  scene->objects.push_back(cube);
}

// The red value of the pixel that sees plane point p.
inline int RedAt(const Rendered& r, const Eigen::Vector3d& p) {
  const Eigen::Vector2d uv = r.camera.Project(r.world_from_cam.Inverse() * p).value();
  return r.image.rgb[3 * (static_cast<size_t>(std::lround(uv.y())) * r.camera.width + std::lround(uv.x()))];
}

// A coloured point light 1.2 m above the plane, near the middle of the view.
inline Light Bulb() {
  Light light;
  light.name = "bulb";
  light.position = Eigen::Vector3d(0.4, -0.3, 1.2);
  light.intensity = Eigen::Vector3f(2.0f, 1.0f, 0.4f);
  return light;
}

}  // namespace testing
}  // namespace rovo
