#pragma once
// The rig of the image fuzz targets: one equidistant camera, 32x31 pixels.

#include "datasets/rig.h"

namespace rovo::fuzz {

inline RigCamera SmallFuzzCamera() {
  RigCamera camera;
  camera.name = "cam0";
  camera.camera.model = CameraModelId::kEquidistant;
  camera.camera.width = 32;
  camera.camera.height = 31;
  camera.camera.params = {10.0, 10.0, 15.5, 15.0, 0.0, 0.0, 0.0, 0.0};
  camera.camera.max_fov_deg = 180.0;
  return camera;
}

}  // namespace rovo::fuzz
