#pragma once
// A calibrated camera: model, image size, parameters and field-of-view limit. Run-time dispatch
// over the models of camera_models.h.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace rovo {

enum class CameraModelId { kEquidistant = 0, kDoubleSphere = 1, kOcam = 2, kExtendedUnified = 3 };

// "equidistant", "double_sphere", "ocam", "extended_unified". Throws std::invalid_argument for an unknown name.
CameraModelId CameraModelFromName(const std::string& name);
std::string CameraModelName(CameraModelId id);
// `value` with `significant_digits` digits, for the messages that name a bad parameter.
std::string FormatParam(double value, int significant_digits);

struct Camera {
  CameraModelId model = CameraModelId::kEquidistant;
  int width = 0;
  int height = 0;
  std::vector<double> params;  // layout per model, see camera_models.h
  double max_fov_deg = 220.0;  // full cone angle around the optical axis (+z) that is valid

  // Pixel of a point (any non-zero 3D point, or a bearing) in camera coordinates. nullopt when the
  // direction is outside the field of view or the model cannot project it. The pixel may lie
  // outside the image rectangle; use InImage() for that. J_uv_point, when given, receives
  // d(uv)/d(point_in_cam).
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& point_in_cam,
                                         Eigen::Matrix<double, 2, 3>* J_uv_point = nullptr) const;

  // Unit bearing of a pixel; nullopt outside the field of view or where the model is undefined.
  std::optional<Eigen::Vector3d> Unproject(const Eigen::Vector2d& uv) const;

  bool InImage(const Eigen::Vector2d& uv) const {
    return uv.x() >= -0.5 && uv.y() >= -0.5 && uv.x() < width - 0.5 && uv.y() < height - 0.5;
  }

  // True when the bearing's angle from the optical axis is within max_fov_deg / 2 (+1e-9 rad for rounding).
  bool InFov(const Eigen::Vector3d& point_in_cam) const;

  // Row-major width*height mask: 255 where the pixel centre unprojects to a valid bearing.
  std::vector<unsigned char> ValidPixelMask() const;

  // Checks parameter count and basic sanity; throws std::invalid_argument naming `what`.
  void Check(const std::string& what) const;
};

}  // namespace rovo
