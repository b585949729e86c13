#include "datasets/rig.h"

#include <cmath>
#include <random>
#include <set>
#include <stdexcept>

#include "datasets/camera_models.h"
#include "datasets/ocam.h"
#include "datasets/omnimvs_rig.h"

namespace rovo {
namespace {

// Pixel coordinate under a change of image size by `scale`, with pixel centres at integers:
// the image edge -0.5 stays at the edge, so u' = (u + 0.5) * scale - 0.5.
double ScalePixel(double u, double scale) { return (u + 0.5) * scale - 0.5; }

Camera ScaledCamera(const Camera& camera, double scale) {
  Camera out = camera;
  out.width = std::max(1, static_cast<int>(std::lround(camera.width * scale)));
  out.height = std::max(1, static_cast<int>(std::lround(camera.height * scale)));
  std::vector<double>& p = out.params;
  switch (camera.model) {
    case CameraModelId::kEquidistant:      // fx fy cx cy k1..k4
    case CameraModelId::kDoubleSphere:     // fx fy cx cy xi alpha
    case CameraModelId::kExtendedUnified:  // fx fy cx cy alpha beta
      if (p.size() < 4) throw std::invalid_argument("Rig::Scaled: camera has too few parameters");
      p[0] *= scale;
      p[1] *= scale;
      p[2] = ScalePixel(p[2], scale);
      p[3] = ScalePixel(p[3], scale);
      break;
    case CameraModelId::kOcam: {
      // [cx, cy, c, d, e, a0..a4, b0..]. The ray (x, y, -poly(rho)) is defined up to scale, so with
      // rho' = s rho the same ray is (x', y', -s poly(rho'/s)): a_i' = a_i s^(1-i). The inverse
      // polynomial gives rho directly: b_i' = s b_i.
      if (p.size() < 10) throw std::invalid_argument("Rig::Scaled: ocam camera has too few parameters");
      p[0] = ScalePixel(p[0], scale);
      p[1] = ScalePixel(p[1], scale);
      for (int i = 0; i < 5; ++i) p[5 + i] *= std::pow(scale, 1 - i);
      for (size_t i = 10; i < p.size(); ++i) p[i] *= scale;
      break;
    }
  }
  return out;
}

// Zero-mean unit Gaussian samples by the Box-Muller transform on std::mt19937_64 output (whose
// sequence is fixed by the standard, unlike std::normal_distribution's), so perturbed sets are
// identical across standard libraries.
class Gaussian {
 public:
  explicit Gaussian(uint64_t seed) : engine_(seed) {}
  double Next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    // u1 in (0, 1], u2 in [0, 1), 53 random bits each.
    const double u1 = (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53;
    const double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
    const double radius = std::sqrt(-2.0 * std::log(u1));
    spare_ = radius * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return radius * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

// The paper's synthetic rig: four 220-degree ocam lenses of the real rig's kind at the corners of a
// 1.0 m x 0.9 m rooftop rectangle (rig origin at its centre, z = 0), optical axes horizontal.
Rig MakeRovo4() {
  // Lens: a0..a4 close to the real rig's camera 1 (datasets/PRESETS.md), ideal affine (c=1, d=e=0).
  const std::vector<double> forward = {811.7, 756.2, 1.0, 0.0, 0.0, -392.2, 0.0, 0.00127, -1.746e-6, 2.258e-9};
  Camera camera;
  camera.model = CameraModelId::kOcam;
  camera.width = 1600;
  camera.height = 1532;
  camera.max_fov_deg = 220.0;
  camera.params = OcamParamsWithFittedInverse(forward, camera.max_fov_deg, nullptr);
  const double half_length = 0.5, half_width = 0.45;
  struct Mount {
    double x, y, yaw_deg;
  };
  const Mount mounts[4] = {{half_length, half_width, 45.0},
                           {half_length, -half_width, -45.0},
                           {-half_length, -half_width, -135.0},
                           {-half_length, half_width, 135.0}};
  Rig rig;
  for (int i = 0; i < 4; ++i) {
    RigCamera rc;
    rc.name = "cam" + std::to_string(i);
    rc.camera = camera;
    rc.cam_from_rig = CamFromRigFromMount(mounts[i].yaw_deg, 0.0, Eigen::Vector3d(mounts[i].x, mounts[i].y, 0.0));
    rig.cameras.push_back(rc);
  }
  return rig;
}

// OmniMVS synthetic rig: four ideal equidistant 220-degree lenses, 800x768 (width x height, as the
// OmniMVS synthetic config.yaml's image_size [768, 800]), centre (col 399, row 383) as in that file,
// f = 191.5 px (its ocam polynomial maps 30/60/90 degrees to 191.4-191.6 px per radian), on a
// circle of radius 0.6 m facing 0, 90, 180 and -90 degrees of yaw.
Rig MakeOmniMvs4() {
  Camera camera;
  camera.model = CameraModelId::kEquidistant;
  camera.width = 800;
  camera.height = 768;
  camera.max_fov_deg = 220.0;
  camera.params = {191.5, 191.5, 399.0, 383.0, 0.0, 0.0, 0.0, 0.0};
  const double yaws_deg[4] = {0.0, 90.0, 180.0, -90.0};
  Rig rig;
  for (int i = 0; i < 4; ++i) {
    RigCamera rc;
    rc.name = "cam" + std::to_string(i);
    rc.camera = camera;
    const double yaw = yaws_deg[i] * kDegToRad;
    const Eigen::Vector3d position(0.6 * std::cos(yaw), 0.6 * std::sin(yaw), 0.0);
    rc.cam_from_rig = CamFromRigFromMount(yaws_deg[i], 0.0, position);
    rig.cameras.push_back(rc);
  }
  return rig;
}

// A forward camera that stereo and monocular systems can model: an equidistant (Kannala-Brandt
// with k1..k4 = 0) lens, 1024 x 768 px, 100 degrees across the width (f = 512 px / 50 deg), 75
// degrees across the height, 125 degrees across the diagonal; max_fov_deg bounds the corners.
Camera ForwardCamera() {
  Camera camera;
  camera.model = CameraModelId::kEquidistant;
  camera.width = 1024;
  camera.height = 768;
  const double f = 512.0 / (50.0 * kDegToRad);
  camera.params = {f, f, 511.5, 383.5, 0.0, 0.0, 0.0, 0.0};
  camera.max_fov_deg = 2.0 * std::hypot(512.0, 384.0) / f / kDegToRad + 1.0;
  return camera;
}

// rovo4 plus forward cameras looking along +x from the front edge of the roof (x = 0.5 m), 0.1 m
// above the ring: at y = +-0.2 m (a 0.4 m stereo baseline, cam4 left, cam5 right) or one at y = 0.
Rig MakeRovo4WithForward(bool stereo) {
  Rig rig = MakeRovo4();
  const std::vector<std::pair<std::string, double>> mounts =
      stereo ? std::vector<std::pair<std::string, double>>{{"cam4", 0.2}, {"cam5", -0.2}}
             : std::vector<std::pair<std::string, double>>{{"cam4", 0.0}};
  for (const auto& [name, y] : mounts) {
    RigCamera rc;
    rc.name = name;
    rc.camera = ForwardCamera();
    rc.cam_from_rig = CamFromRigFromMount(0.0, 0.0, Eigen::Vector3d(0.5, y, 0.1));
    rig.cameras.push_back(rc);
  }
  return rig;
}

}  // namespace

Rigid3 CamFromRigFromMount(double yaw_deg, double pitch_deg, const Eigen::Vector3d& position_in_rig) {
  // rig_from_cam maps the camera axes (OpenCV) to rig directions: z (optical axis) to the direction
  // of yaw/pitch, x (image right) to the horizontal right of it, y (image down) completing the frame.
  const double yaw = yaw_deg * kDegToRad, pitch = pitch_deg * kDegToRad;
  const Eigen::Vector3d z_cam(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
  const Eigen::Vector3d x_cam(std::sin(yaw), -std::cos(yaw), 0.0);
  const Eigen::Vector3d y_cam = z_cam.cross(x_cam);
  Eigen::Matrix3d rig_from_cam_rotation;
  rig_from_cam_rotation << x_cam, y_cam, z_cam;
  return Rigid3(rig_from_cam_rotation, position_in_rig).Inverse();
}

Eigen::Vector3d CameraPositionInRig(const Rigid3& cam_from_rig) { return cam_from_rig.Inverse().translation; }

Eigen::Vector3d CameraAxisInRig(const Rigid3& cam_from_rig) {
  return cam_from_rig.rotation.conjugate() * Eigen::Vector3d::UnitZ();
}

double CameraYawDeg(const Rigid3& cam_from_rig) {
  const Eigen::Vector3d axis = CameraAxisInRig(cam_from_rig);
  return std::atan2(axis.y(), axis.x()) / kDegToRad;
}

double CameraPitchDeg(const Rigid3& cam_from_rig) {
  const Eigen::Vector3d axis = CameraAxisInRig(cam_from_rig);
  return std::atan2(axis.z(), axis.head<2>().norm()) / kDegToRad;
}

Rig Rig::Scaled(double scale) const {
  if (!(scale > 0.0) || !std::isfinite(scale)) throw std::invalid_argument("Rig::Scaled: scale must be positive");
  Rig out = *this;
  for (RigCamera& rc : out.cameras) rc.camera = ScaledCamera(rc.camera, scale);
  return out;
}

Rig Rig::WithExtrinsics(const std::vector<Rigid3>& cam_from_rig) const {
  if (cam_from_rig.size() != cameras.size()) {
    throw std::invalid_argument("Rig::WithExtrinsics: " + std::to_string(cam_from_rig.size()) + " extrinsics for " +
                                std::to_string(cameras.size()) + " cameras");
  }
  Rig out = *this;
  for (size_t i = 0; i < cameras.size(); ++i) out.cameras[i].cam_from_rig = cam_from_rig[i];
  return out;
}

std::vector<Rigid3> Rig::Extrinsics() const {
  std::vector<Rigid3> out;
  out.reserve(cameras.size());
  for (const RigCamera& rc : cameras) out.push_back(rc.cam_from_rig);
  return out;
}

void Rig::Check(const std::string& what) const {
  if (cameras.empty()) throw std::invalid_argument(what + ": rig has no cameras");
  std::set<std::string> names;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const RigCamera& rc = cameras[i];
    const std::string where = what + ": cameras[" + std::to_string(i) + "]";
    if (rc.name.empty() || rc.name.find('/') != std::string::npos || rc.name == "." || rc.name == "..") {
      throw std::invalid_argument(where + ".name: `" + rc.name + "` is not a valid folder name");
    }
    if (!names.insert(rc.name).second) throw std::invalid_argument(where + ".name: duplicate name " + rc.name);
    rc.camera.Check(where);
    const Eigen::Quaterniond& q = rc.cam_from_rig.rotation;
    if (!q.coeffs().allFinite() || !rc.cam_from_rig.translation.allFinite()) {
      throw std::invalid_argument(where + ".cam_from_rig: NaN or Inf");
    }
    if (std::abs(q.norm() - 1.0) > 1e-6) throw std::invalid_argument(where + ".cam_from_rig: non-unit quaternion");
  }
  if (imu_from_rig) {
    const Eigen::Quaterniond& q = imu_from_rig->rotation;
    if (!q.coeffs().allFinite() || !imu_from_rig->translation.allFinite())
      throw std::invalid_argument(what + ": imu_from_rig: NaN or Inf");
    if (std::abs(q.norm() - 1.0) > 1e-6) throw std::invalid_argument(what + ": imu_from_rig: non-unit quaternion");
  }
}

Rigid3 PresetImuFromRig() {
  const Eigen::Quaterniond imu_from_rig_rotation(Eigen::AngleAxisd(-M_PI / 2.0, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d imu_in_rig(0.03, -0.02, -0.05);
  return Rigid3(imu_from_rig_rotation, -(imu_from_rig_rotation * imu_in_rig));
}

std::vector<std::string> RigPresetNames() { return {"rovo4", "omnimvs4", "rovo4_real", "rovo4_stereo", "rovo4_mono"}; }

Rig MakeRigPreset(const std::string& name) {
  if (name == "rovo4") return MakeRovo4();
  if (name == "rovo4_stereo") return MakeRovo4WithForward(/*stereo=*/true);
  if (name == "rovo4_mono") return MakeRovo4WithForward(/*stereo=*/false);
  if (name == "omnimvs4") return MakeOmniMvs4();
  if (name == "rovo4_real") return MakeRovo4RealRig();
  std::string known;
  for (const std::string& n : RigPresetNames()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown rig preset `" + name + "` (known: " + known + ")");
}

PerturbedExtrinsics PerturbExtrinsics(const Rig& rig, double sigma_rotation_deg, double sigma_translation_m,
                                      uint64_t seed) {
  if (!(sigma_rotation_deg >= 0.0) || !(sigma_translation_m >= 0.0)) {
    throw std::invalid_argument("PerturbExtrinsics: sigmas must be non-negative");
  }
  PerturbedExtrinsics out;
  out.sigma_rotation_deg = sigma_rotation_deg;
  out.sigma_translation_m = sigma_translation_m;
  out.seed = seed;
  Gaussian gaussian(seed);
  const double sigma_rad = sigma_rotation_deg * kDegToRad;
  for (const RigCamera& rc : rig.cameras) {
    // Per camera, in this order: roll (about the optical axis z), pitch (about x), yaw (about y),
    // then the position offset in the rig frame (x, y, z).
    const double roll = sigma_rad * gaussian.Next();
    const double pitch = sigma_rad * gaussian.Next();
    const double yaw = sigma_rad * gaussian.Next();
    Eigen::Vector3d offset_in_rig;
    for (int k = 0; k < 3; ++k) offset_in_rig[k] = sigma_translation_m * gaussian.Next();
    const Eigen::Quaterniond delta(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()) *
                                   Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()));
    // cam_from_rig' = delta * cam_from_rig turns the camera about its own centre; the centre then
    // moves by offset_in_rig: t' = -R' (c + offset).
    const Eigen::Quaterniond rotation = (delta * rc.cam_from_rig.rotation).normalized();
    const Eigen::Vector3d centre_in_rig = CameraPositionInRig(rc.cam_from_rig) + offset_in_rig;
    out.cam_from_rig.emplace_back(rotation, -(rotation * centre_in_rig));
  }
  return out;
}

}  // namespace rovo
