#pragma once
// A rig of N >= 1 cameras rigidly mounted on a body frame (REP-103: x forward, y left, z up).
// Gauge: camera 0 is the reference for online extrinsics; its cam_from_rig is held fixed and the
// other cameras are estimated relative to it (the paper's Fig. 8).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "datasets/camera.h"
#include "datasets/rigid3.h"

namespace rovo {

struct RigCamera {
  std::string name;  // also the image folder name, e.g. "cam0"
  Camera camera;
  Rigid3 cam_from_rig;
};

struct Rig {
  std::vector<RigCamera> cameras;
  // The IMU's mount (datasets/imu.h), present when the rig carries an IMU: x_in_imu = imu_from_rig *
  // x_in_rig. The rig presets' IMU sits at PresetImuFromRig().
  std::optional<Rigid3> imu_from_rig;

  int NumCameras() const { return static_cast<int>(cameras.size()); }
  // Rig with `scale` times the image size (intrinsics scaled accordingly), same lenses.
  Rig Scaled(double scale) const;
  // Replaces every camera's cam_from_rig (sizes must match).
  Rig WithExtrinsics(const std::vector<Rigid3>& cam_from_rig) const;
  std::vector<Rigid3> Extrinsics() const;
  void Check(const std::string& what) const;
};

// Named rigs: "rovo4" (the paper's synthetic rig), "omnimvs4" (OmniMVS synthetic rig),
// "rovo4_real" (the paper lab's calibrated rig, imported from OmniMVS config.yaml).
std::vector<std::string> RigPresetNames();
Rig MakeRigPreset(const std::string& name);  // throws std::invalid_argument for an unknown name

// The IMU mount of the rig presets (datasets/FORMAT.md, "IMU"): the IMU 3 cm forward, 2 cm right
// and 5 cm below the rig origin, its x axis along the rig's y (left), y along the rig's -x
// (backward), z up (a -90 deg yaw): neither the identity nor at a camera, so that a frame mix-up
// shows in the data.
Rigid3 PresetImuFromRig();

// Mounting helpers (rig frame REP-103: x forward, y left, z up; camera frame OpenCV).
// CamFromRigFromMount: a camera whose optical axis (+z) points at yaw (about rig +z, 0 = forward,
// +90 = left) and pitch (up positive), image x horizontal (right of the axis), image y completing
// the right-handed frame (down for pitch 0), centre at position_in_rig.
Rigid3 CamFromRigFromMount(double yaw_deg, double pitch_deg, const Eigen::Vector3d& position_in_rig);
// Camera centre in the rig frame: rig_from_cam's translation = -R^T t.
Eigen::Vector3d CameraPositionInRig(const Rigid3& cam_from_rig);
// Optical axis (+z of the camera) in the rig frame, and its yaw atan2(y, x) / pitch in degrees.
Eigen::Vector3d CameraAxisInRig(const Rigid3& cam_from_rig);
double CameraYawDeg(const Rigid3& cam_from_rig);
double CameraPitchDeg(const Rigid3& cam_from_rig);

// One perturbed set of extrinsics (the NoisyExt / OnlineExt starting point).
struct PerturbedExtrinsics {
  double sigma_rotation_deg = 5.0;
  double sigma_translation_m = 0.0;
  uint64_t seed = 0;
  std::vector<Rigid3> cam_from_rig;  // one per camera
};

// Perturbs roll, pitch and yaw of each camera's cam_from_rig (rotation about the camera's own axes)
// by independent zero-mean Gaussian noise, and the translation by isotropic Gaussian noise.
PerturbedExtrinsics PerturbExtrinsics(const Rig& rig, double sigma_rotation_deg, double sigma_translation_m,
                                      uint64_t seed);

}  // namespace rovo
