#include "datasets/camera.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unsupported/Eigen/AutoDiff>

#include "datasets/camera_models.h"
#include "datasets/ocam.h"

namespace rovo {
namespace {

// Unproject rejects ocam pixels whose bearing does not project back within this distance: beyond
// the FOV edge the forward polynomial may fold back, and the inverse fit is only valid inside.
constexpr double kOcamRoundTripTolerancePx = 0.1;
// InFov tolerance: rounding noise of an unprojected edge pixel must not reject it.
constexpr double kFovSlackRad = 1e-9;
// InFov's fast path decides only this far (in cosine) from the limit.
constexpr double kFovCosMargin = 1e-12;
// Check() accepts an ocam inverse polynomial that is this close to the forward one over the FOV.
constexpr double kOcamCheckInverseTolerancePx = 0.05;

// Calls f(Model{}) for the model struct of `id`.
template <typename F>
auto DispatchModel(CameraModelId id, F&& f) {
  switch (id) {
#define ROVO_CAMERA_CASE(enum_id, Model, name) \
  case CameraModelId::enum_id:                 \
    return f(Model{});  // NOLINT(bugprone-macro-parentheses): Model is a type name
    ROVO_CAMERA_MODELS(ROVO_CAMERA_CASE)
#undef ROVO_CAMERA_CASE
  }
  throw std::invalid_argument("camera model id " + std::to_string(static_cast<int>(id)) + " is unknown");
}

template <typename Model>
bool NumParamsOk(int num_params) {
  if constexpr (std::is_same_v<Model, OcamModel>) {
    return num_params >= OcamModel::kMinNumParams;
  } else {
    return num_params == Model::kNumParams;
  }
}

template <typename Model>
std::string ExpectedNumParamsText() {
  if constexpr (std::is_same_v<Model, OcamModel>) {
    return "at least " + std::to_string(OcamModel::kMinNumParams) + " values (" + Model::kParamNames + ")";
  } else {
    return std::to_string(Model::kNumParams) + " values (" + Model::kParamNames + ")";
  }
}

// Projection with d(uv)/d(point) by forward-mode automatic differentiation through the templated
// model (three derivative directions, no heap allocation for up to kMaxInline parameters).
template <typename Model>
bool ProjectWithJacobian(const std::vector<double>& params, const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* uv,
                         Eigen::Matrix<double, 2, 3>* J_uv_point) {
  using Ad = Eigen::AutoDiffScalar<Eigen::Vector3d>;
  constexpr int kMaxInline = 48;
  const int n = static_cast<int>(params.size());
  Ad inline_params[kMaxInline];
  std::vector<Ad> heap_params;
  Ad* ad_params = inline_params;
  if (n > kMaxInline) {
    heap_params.resize(n);
    ad_params = heap_params.data();
  }
  for (int i = 0; i < n; ++i) ad_params[i] = Ad(params[i]);  // zero derivatives
  const Ad ad_point[3] = {Ad(point_in_cam.x(), 3, 0), Ad(point_in_cam.y(), 3, 1), Ad(point_in_cam.z(), 3, 2)};
  Ad ad_uv[2];
  if (!Model::ImgFromCam(ad_params, n, ad_point, ad_uv)) return false;
  for (int r = 0; r < 2; ++r) {
    (*uv)(r) = ad_uv[r].value();
    // A result that does not depend on the point (the optical axis) has an empty derivative.
    if (ad_uv[r].derivatives().size() == 3) {
      J_uv_point->row(r) = ad_uv[r].derivatives().transpose();
    } else {
      J_uv_point->row(r).setZero();
    }
  }
  return true;
}

[[noreturn]] void Fail(const std::string& what, const std::string& field, const std::string& message) {
  throw std::invalid_argument(what + ": " + field + ": " + message);
}

void CheckEquidistant(const Camera& camera, const std::string& what) {
  const double* p = camera.params.data();
  if (!(p[0] > 0)) Fail(what, "params[0] (fx)", "must be positive, got " + FormatParam(p[0], 10));
  if (!(p[1] > 0)) Fail(what, "params[1] (fy)", "must be positive, got " + FormatParam(p[1], 10));
  const double half_fov = 0.5 * camera.max_fov_deg * kDegToRad;
  if (!(half_fov < M_PI)) {
    Fail(what, "max_fov_deg", "equidistant needs a FOV below 360 degrees, got " + FormatParam(camera.max_fov_deg, 10));
  }
  // r(theta) must increase over the FOV so that every pixel has one bearing.
  constexpr int kSteps = 2000;
  double previous = 0.0;
  for (int i = 1; i <= kSteps; ++i) {
    const double theta = half_fov * i / kSteps;
    const double r = EquidistantModel::Distort(p, theta);
    if (!(r > previous)) {
      Fail(what, "params[4..7] (k1..k4)",
           "r(theta) is not increasing at theta = " + FormatParam(theta / kDegToRad, 10) + " deg, inside the FOV of " +
               FormatParam(camera.max_fov_deg, 10) + " deg");
    }
    previous = r;
  }
}

void CheckDoubleSphere(const Camera& camera, const std::string& what) {
  const double* p = camera.params.data();
  if (!(p[0] > 0)) Fail(what, "params[0] (fx)", "must be positive, got " + FormatParam(p[0], 10));
  if (!(p[1] > 0)) Fail(what, "params[1] (fy)", "must be positive, got " + FormatParam(p[1], 10));
  if (!(p[4] >= -1 && p[4] <= 1)) Fail(what, "params[4] (xi)", "must be in [-1, 1], got " + FormatParam(p[4], 10));
  if (!(p[5] >= 0 && p[5] <= 1)) Fail(what, "params[5] (alpha)", "must be in [0, 1], got " + FormatParam(p[5], 10));
  const double max_angle_deg = std::acos(-DoubleSphereModel::ValidW2(p)) / kDegToRad;
  if (!(0.5 * camera.max_fov_deg < max_angle_deg)) {
    Fail(what, "max_fov_deg",
         FormatParam(camera.max_fov_deg, 10) + " deg exceeds the valid set of these double-sphere parameters (" +
             FormatParam(2 * max_angle_deg, 10) + " deg)");
  }
}

void CheckExtendedUnified(const Camera& camera, const std::string& what) {
  const double* p = camera.params.data();
  if (!(p[0] > 0)) Fail(what, "params[0] (fx)", "must be positive, got " + FormatParam(p[0], 10));
  if (!(p[1] > 0)) Fail(what, "params[1] (fy)", "must be positive, got " + FormatParam(p[1], 10));
  if (!(p[4] >= 0 && p[4] <= 1)) Fail(what, "params[4] (alpha)", "must be in [0, 1], got " + FormatParam(p[4], 10));
  if (!(p[5] > 0)) Fail(what, "params[5] (beta)", "must be positive, got " + FormatParam(p[5], 10));
  // The FOV edge direction (sin a, 0, cos a) must satisfy cos a > -w sqrt(beta sin^2 a + cos^2 a).
  const double half_fov = 0.5 * camera.max_fov_deg * kDegToRad;
  const double s = std::sin(half_fov), c = std::cos(half_fov);
  if (!(c > -ExtendedUnifiedModel::ValidW(p) * std::sqrt(p[5] * s * s + c * c))) {
    Fail(what, "max_fov_deg",
         FormatParam(camera.max_fov_deg, 10) + " deg exceeds the valid set of these extended-unified parameters");
  }
}

void CheckOcam(const Camera& camera, const std::string& what) {
  const double* p = camera.params.data();
  if (!(p[2] > 0)) Fail(what, "params[2] (c)", "must be positive, got " + FormatParam(p[2], 10));
  if (!(std::abs(p[2] - p[3] * p[4]) > 1e-9)) Fail(what, "params[2..4] (c, d, e)", "the affine is singular");
  if (!(p[5] < 0)) Fail(what, "params[5] (a0)", "must be negative (z forward), got " + FormatParam(p[5], 10));
  std::string problem;
  if (!OcamForwardMonotonic(camera.params, camera.max_fov_deg, nullptr, &problem)) {
    Fail(what, "params[5..9] (a0..a4)", problem);
  }
  const double error_px = OcamInverseMaxErrorPx(camera.params, camera.max_fov_deg);
  if (!(error_px <= kOcamCheckInverseTolerancePx)) {
    Fail(what, "params[10..] (inverse polynomial b)",
         "disagrees with the forward polynomial by " + FormatParam(error_px, 10) + " px over the FOV (more than " +
             FormatParam(kOcamCheckInverseTolerancePx, 10) + " px); refit it with FitOcamInversePolynomial");
  }
}

}  // namespace

std::string FormatParam(double value, int significant_digits) {
  std::ostringstream out;
  out.precision(significant_digits);
  out << value;
  return out.str();
}

CameraModelId CameraModelFromName(const std::string& name) {
#define ROVO_CAMERA_FROM_NAME(enum_id, Model, model_name) \
  if (name == (model_name)) return CameraModelId::enum_id;
  ROVO_CAMERA_MODELS(ROVO_CAMERA_FROM_NAME)
#undef ROVO_CAMERA_FROM_NAME
  throw std::invalid_argument("unknown camera model \"" + name +
                              "\" (known: equidistant, double_sphere, ocam, extended_unified)");
}

std::string CameraModelName(CameraModelId id) {
  return DispatchModel(id, [id](auto model) -> std::string {
    using Model = decltype(model);
#define ROVO_CAMERA_NAME(enum_id, ModelType, model_name) \
  if (std::is_same_v<Model, ModelType>) return model_name;
    ROVO_CAMERA_MODELS(ROVO_CAMERA_NAME)
#undef ROVO_CAMERA_NAME
    throw std::invalid_argument("camera model id " + std::to_string(static_cast<int>(id)) + " has no name");
  });
}

std::optional<Eigen::Vector2d> Camera::Project(const Eigen::Vector3d& point_in_cam,
                                               Eigen::Matrix<double, 2, 3>* J_uv_point) const {
  if (!InFov(point_in_cam)) return std::nullopt;
  return DispatchModel(model, [&](auto model_struct) -> std::optional<Eigen::Vector2d> {
    using Model = decltype(model_struct);
    const int n = static_cast<int>(params.size());
    if (!NumParamsOk<Model>(n)) return std::nullopt;
    Eigen::Vector2d uv;
    if (J_uv_point == nullptr) {
      if (!Model::ImgFromCam(params.data(), n, point_in_cam.data(), uv.data())) return std::nullopt;
    } else {
      if (!ProjectWithJacobian<Model>(params, point_in_cam, &uv, J_uv_point)) return std::nullopt;
    }
    if (!uv.allFinite()) return std::nullopt;
    return uv;
  });
}

std::optional<Eigen::Vector3d> Camera::Unproject(const Eigen::Vector2d& uv) const {
  return DispatchModel(model, [&](auto model_struct) -> std::optional<Eigen::Vector3d> {
    using Model = decltype(model_struct);
    const int n = static_cast<int>(params.size());
    if (!NumParamsOk<Model>(n)) return std::nullopt;
    Eigen::Vector3d bearing;
    if (!Model::CamFromImg(params.data(), n, uv.data(), bearing.data())) return std::nullopt;
    if (!bearing.allFinite() || !InFov(bearing)) return std::nullopt;
    if constexpr (std::is_same_v<Model, OcamModel>) {
      Eigen::Vector2d uv_back;
      if (!Model::ImgFromCam(params.data(), n, bearing.data(), uv_back.data())) return std::nullopt;
      if (!((uv_back - uv).norm() <= kOcamRoundTripTolerancePx)) return std::nullopt;
    }
    return bearing;
  });
}

bool Camera::InFov(const Eigen::Vector3d& point_in_cam) const {
  // Fast path: the cosine of the angle from the axis against the cosine of the limit, decided only
  // when it is more than kFovCosMargin away from it. Then the angle is more than kFovCosMargin rad
  // from the limit (|d cos / d angle| <= 1), far beyond the rounding of either test, so the answer is
  // the exact test's below; within the margin the exact test decides.
  thread_local double cached_fov_deg = std::numeric_limits<double>::quiet_NaN(), cos_limit = 0.0;
  if (max_fov_deg != cached_fov_deg) {
    cached_fov_deg = max_fov_deg;
    cos_limit = std::cos(0.5 * max_fov_deg * kDegToRad + kFovSlackRad);
  }
  const double norm2 = point_in_cam.squaredNorm();
  // Normal (not subnormal) squared lengths only, and limits that Check() accepts (cos is monotone there).
  if (norm2 >= std::numeric_limits<double>::min() && std::isfinite(norm2) && max_fov_deg > 0.0 &&
      max_fov_deg <= 360.0) {
    const double cos_angle = point_in_cam.z() / std::sqrt(norm2);
    if (cos_angle > cos_limit + kFovCosMargin) return true;
    if (cos_angle < cos_limit - kFovCosMargin) return false;
  }
  const double r_xy = std::hypot(point_in_cam.x(), point_in_cam.y());
  if (r_xy == 0.0 && point_in_cam.z() == 0.0) return false;
  const double angle_from_axis = std::atan2(r_xy, point_in_cam.z());
  return angle_from_axis <= 0.5 * max_fov_deg * kDegToRad + kFovSlackRad;
}

std::vector<unsigned char> Camera::ValidPixelMask() const {
  std::vector<unsigned char> mask(static_cast<size_t>(std::max(width, 0)) * std::max(height, 0), 0);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (Unproject(Eigen::Vector2d(u, v))) mask[static_cast<size_t>(v) * width + u] = 255;
    }
  }
  return mask;
}

void Camera::Check(const std::string& what) const {
  if (width <= 0) Fail(what, "width", "must be positive, got " + std::to_string(width));
  if (height <= 0) Fail(what, "height", "must be positive, got " + std::to_string(height));
  if (!(max_fov_deg > 0 && max_fov_deg <= 360)) {
    Fail(what, "max_fov_deg", "must be in (0, 360], got " + FormatParam(max_fov_deg, 10));
  }
  for (size_t i = 0; i < params.size(); ++i) {
    if (!std::isfinite(params[i])) Fail(what, "params[" + std::to_string(i) + "]", "is not finite");
  }
  DispatchModel(model, [&](auto model_struct) {
    using Model = decltype(model_struct);
    if (!NumParamsOk<Model>(static_cast<int>(params.size()))) {
      Fail(what, "params",
           CameraModelName(model) + " needs " + ExpectedNumParamsText<Model>() + ", got " +
               std::to_string(params.size()));
    }
    if constexpr (std::is_same_v<Model, EquidistantModel>) CheckEquidistant(*this, what);
    if constexpr (std::is_same_v<Model, DoubleSphereModel>) CheckDoubleSphere(*this, what);
    if constexpr (std::is_same_v<Model, OcamModel>) CheckOcam(*this, what);
    if constexpr (std::is_same_v<Model, ExtendedUnifiedModel>) CheckExtendedUnified(*this, what);
    return 0;
  });
}

}  // namespace rovo
