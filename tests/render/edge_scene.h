#pragma once
// A wall with one vertical edge seen by a moving fisheye, for the timing and sampling tests.

#include <Eigen/Core>

#include "datasets/continuous_trajectory.h"
#include "render/timing.h"
#include "render/tracer.h"
#include "scenes/scene.h"
#include "tests/render/box_scene.h"

namespace rovo::testing {

// A wall at x = kWallX: dark for y > 0, bright for y < 0 (the edge is the vertical line y = 0),
// lit by ambient light only. The rig moves along +y at kSpeed m/s (frames at 10 Hz), one
// equidistant camera of kF px/rad looking along +x (the rig's forward axis).
inline constexpr double kWallX = 5.0, kSpeed = 10.0, kF = 200.0;
inline constexpr int kSize = 256;

inline Scene MakeEdgeScene() {
  Scene scene;
  scene.metadata.preset = "test_edge";
  Material bright, dark;
  bright.name = "bright";
  bright.base_color = Eigen::Vector3f(0.9f, 0.9f, 0.9f);
  dark.name = "dark";
  dark.base_color = Eigen::Vector3f(0.1f, 0.1f, 0.1f);
  scene.materials = {bright, dark};
  const float x = static_cast<float>(kWallX);
  scene.meshes.push_back(MakeQuad("bright", Eigen::Vector3f(x, -50, -50), Eigen::Vector3f(x, 0, -50),
                                  Eigen::Vector3f(x, 0, 50), Eigen::Vector3f(x, -50, 50), 0));
  scene.meshes.push_back(MakeQuad("dark", Eigen::Vector3f(x, 0, -50), Eigen::Vector3f(x, 50, -50),
                                  Eigen::Vector3f(x, 50, 50), Eigen::Vector3f(x, 0, 50), 1));
  for (int m = 0; m < 2; ++m) {
    scene.meshes[m].uvs.clear();
    Object o;
    o.name = scene.meshes[m].name;
    o.mesh = m;
    scene.objects.push_back(o);
  }
  scene.lighting.sun_radiance = Eigen::Vector3f::Zero();
  scene.lighting.ambient = 1.0f;
  scene.frame_rate = 10.0;
  for (int i = 0; i < 3; ++i) {
    StampedPose p;
    p.timestamp = i / scene.frame_rate;
    p.world_from_rig = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, kSpeed * p.timestamp, 0.0));
    scene.rig_trajectory.push_back(p);
  }
  return scene;
}

inline Camera EdgeCamera() {
  Camera cam;
  cam.model = CameraModelId::kEquidistant;
  cam.width = kSize;
  cam.height = kSize;
  cam.params = {kF, kF, (kSize - 1) / 2.0, (kSize - 1) / 2.0, 0, 0, 0, 0};
  cam.max_fov_deg = 180.0;
  cam.Check("edge test camera");
  return cam;
}

// Looking along the rig's +x: camera x (right) = rig -y, camera y (down) = rig -z.
inline Rigid3 CamFromRig() {
  Eigen::Matrix3d r;
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  return Rigid3(r, Eigen::Vector3d::Zero());
}

struct EdgeRender {
  Scene scene = MakeEdgeScene();
  Tracer tracer{scene};
  CameraRays rays = CameraRays::Make(EdgeCamera(), 0, 1);
  ShadeSettings settings;
  EdgeRender(int spp) {
    settings.spp = spp;
    settings.linear_output = true;
    settings.shadows = false;
  }
  // Camera image at trajectory frame 1 with the given timing (ms).
  CameraImage Render(double offset_ms, double shutter_ms, double readout_ms) {
    const double h = HalfWindowSeconds({offset_ms}, readout_ms, {shutter_ms});
    tracer.SetFrameWindow(1, h);
    Rigid3 world_from_cam;
    const CameraMotion motion =
        MakeCameraMotion(ContinuousTrajectory(scene.rig_trajectory), 1, CamFromRig(), h > 0 ? h : 1.0, offset_ms,
                         shutter_ms, readout_ms, kSize, &world_from_cam);
    CameraImage image;
    tracer.Render(rays, world_from_cam, settings, &image, &motion);
    return image;
  }
};

}  // namespace rovo::testing
