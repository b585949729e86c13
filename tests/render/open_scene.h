#pragma once
// An open scene for the sensor tests: a textured ground plane, four blocks and open sky, the sun
// low in front of the rig (+x, 20 degrees up). The omnimvs4 rig (cam0 looks along +x, cam2 along
// -x) stands at 1.5 m and moves 0.5 m per frame along +y: cam0 sees the sun, cam2 does not.

#include <cmath>

#include "tests/render/box_scene.h"

namespace rovo::testing {

inline Eigen::Vector3d OpenSceneSunDirection() {
  const double elevation = 20.0 * M_PI / 180.0;
  return Eigen::Vector3d(std::cos(elevation), 0.0, std::sin(elevation));
}

inline Scene MakeOpenScene(int frames) {
  Scene scene;
  scene.metadata.preset = "test_open";
  scene.metadata.generator_version = "test";
  scene.rig_preset = "omnimvs4";
  scene.textures.push_back(MakeChecker("ground_checker", 1));
  Material ground;
  ground.name = "ground";
  ground.base_color = Eigen::Vector3f(0.6f, 0.6f, 0.6f);
  ground.texture = 0;
  scene.materials.push_back(ground);
  Material block;
  block.name = "block";
  block.base_color = Eigen::Vector3f(0.5f, 0.45f, 0.4f);
  scene.materials.push_back(block);
  scene.meshes.push_back(MakeQuad("ground", Eigen::Vector3f(-60, -60, 0), Eigen::Vector3f(60, -60, 0),
                                  Eigen::Vector3f(60, 60, 0), Eigen::Vector3f(-60, 60, 0), 0));
  scene.meshes.push_back(MakeCube("block", 2.0f, 1));
  Object g;
  g.name = "ground";
  g.mesh = 0;
  scene.objects.push_back(g);
  const double block_centres[4][2] = {{-12.0, 6.0}, {-10.0, -7.0}, {0.0, 9.0}, {1.0, -9.0}};
  for (int b = 0; b < 4; ++b) {
    Object o;
    o.name = "block" + std::to_string(b);
    o.mesh = 1;
    o.world_from_object =
        Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(block_centres[b][0], block_centres[b][1], 2.0));
    scene.objects.push_back(o);
  }
  scene.lighting.direction_to_sun = OpenSceneSunDirection();
  scene.frame_rate = 10.0;
  for (int i = 0; i < frames; ++i) {
    StampedPose pose;
    pose.timestamp = i / scene.frame_rate;
    pose.world_from_rig = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.5 * i, 1.5));
    scene.rig_trajectory.push_back(pose);
  }
  return scene;
}

}  // namespace rovo::testing
