#pragma once
// The lens models of other systems' calibration files, and least-squares fits of them to a rovo
// camera over its whole field of view (rovo's ocam lenses have no exact counterpart elsewhere).
//
// Models (parameter layouts, all with fx, fy, cx, cy first; pixel centre of the top-left pixel at
// (0, 0), camera frame OpenCV):
//   ds    double sphere, [fx, fy, cx, cy, xi, alpha]           (DoubleSphereModel, camera_models.h)
//   eucm  extended unified, [fx, fy, cx, cy, alpha, beta]     (ExtendedUnifiedModel)
//   kb4   Kannala-Brandt on the angle, [fx, fy, cx, cy, k1..k4] (EquidistantModel; Basalt's kb4)
//   omni  unified (Mei) with radial-tangential distortion, [fx, fy, cx, cy, xi, k1, k2, p1, p2]
//         (Kalibr's `omni` + `radtan`; OmniRadtanModel below, export only: rovo has no such lens)
// A fit samples bearings on a dense grid (angle from the axis in 0.5-degree steps up to half the
// FOV, azimuth in 5-degree steps), keeps those the source camera projects into its image, and
// minimises the sum of squared pixel differences with Levenberg-Marquardt (Jacobians by forward
// automatic differentiation). An ocam lens whose affine turns the image axes (d != -e) is fitted in a camera frame
// turned about the optical axis by that angle (`roll_deg`); the exported extrinsics include the turn. A source camera
// of the same kind (double sphere -> ds, equidistant -> kb4, extended unified -> eucm) exports exactly (its parameters,
// zero error).

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "datasets/camera.h"
#include "datasets/camera_models.h"

namespace rovo {

// Unified camera model (Mei and Rives, ICRA 2007) with radial-tangential distortion on its
// normalised plane, as Kalibr's `omni` camera with `radtan` distortion:
//   s = z + xi |p|,  (mx, my) = (x, y) / s,  r2 = mx^2 + my^2,
//   mx' = mx (1 + k1 r2 + k2 r2^2) + 2 p1 mx my + p2 (r2 + 2 mx^2),
//   my' = my (1 + k1 r2 + k2 r2^2) + p1 (r2 + 2 my^2) + 2 p2 mx my,
//   u = fx mx' + cx,  v = fy my' + cy.
// Valid where z > -|p| / xi for xi > 1 (else z > -xi |p|), Kalibr's test.
struct OmniRadtanModel {
  static constexpr int kNumParams = 9;
  template <typename T>
  static bool ImgFromCam(const T* params, int /*num_params*/, const T* point_in_cam, T* uv) {
    using std::sqrt;
    const T& x = point_in_cam[0];
    const T& y = point_in_cam[1];
    const T& z = point_in_cam[2];
    const T norm = sqrt(x * x + y * y + z * z);
    const T& xi = params[4];
    const T limit = xi > T(1) ? T(T(1) / xi) : xi;
    if (!(z > -limit * norm)) return false;
    const T s = z + xi * norm;
    if (!(s > T(0))) return false;
    const T mx = x / s, my = y / s;
    const T r2 = mx * mx + my * my;
    const T radial = T(1) + r2 * (params[5] + r2 * params[6]);
    const T dx = mx * radial + T(2) * params[7] * mx * my + params[8] * (r2 + T(2) * mx * mx);
    const T dy = my * radial + params[7] * (r2 + T(2) * my * my) + T(2) * params[8] * mx * my;
    uv[0] = params[0] * dx + params[2];
    uv[1] = params[1] * dy + params[3];
    return true;
  }
};

// The exchange lens models, each registered once: (enum id, name in exported files and on the
// command line, the model struct, the rovo camera model it equals (CameraModelId of
// ROVO_CAMERA_MODELS) or std::nullopt for omni, which rovo exports only).
#define ROVO_EXCHANGE_LENS_MODELS(X)                                                 \
  X(kDoubleSphere, "ds", DoubleSphereModel, CameraModelId::kDoubleSphere)            \
  X(kExtendedUnified, "eucm", ExtendedUnifiedModel, CameraModelId::kExtendedUnified) \
  X(kKannalaBrandt4, "kb4", EquidistantModel, CameraModelId::kEquidistant)           \
  X(kOmniRadtan, "omni", OmniRadtanModel, std::nullopt)

enum class ExchangeLensModel {
#define ROVO_EXCHANGE_LENS_ID(id, name, model, camera_model) id,
  ROVO_EXCHANGE_LENS_MODELS(ROVO_EXCHANGE_LENS_ID)
#undef ROVO_EXCHANGE_LENS_ID
};

// "ds", "eucm", "kb4", "omni"; FromName throws std::invalid_argument naming the known ones.
std::string ExchangeLensModelName(ExchangeLensModel model);
ExchangeLensModel ExchangeLensModelFromName(const std::string& name);
int ExchangeLensNumParams(ExchangeLensModel model);
// The rovo camera model an exchange lens is (ds -> double_sphere, eucm -> extended_unified,
// kb4 -> equidistant); none for omni.
std::optional<CameraModelId> ExchangeLensCameraModel(ExchangeLensModel model);

struct LensFit {
  ExchangeLensModel model = ExchangeLensModel::kDoubleSphere;
  std::vector<double> params;  // layout above
  bool exact = false;          // the source camera is this model: parameters copied
  // The exported camera frame is turned about the optical axis: exported_from_cam = Rz(roll_deg)
  // (0 unless an ocam affine turns the image axes); exported cam_from_rig = Rz(roll) cam_from_rig.
  double roll_deg = 0.0;
  double max_error_px = 0.0;  // over the grid bearings that land in the image
  double rms_error_px = 0.0;
  double half_px_angle_deg = 0.0;  // every grid bearing up to this angle from the axis errs < 0.5 px
  double max_angle_deg = 0.0;      // largest angle from the axis of a grid bearing in the image
  int num_samples = 0;
};

// Pixel of `point_in_cam` under an exchange model; false outside its valid set.
bool ProjectExchangeLens(ExchangeLensModel model, const std::vector<double>& params,
                         const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* uv);

// Fits `model` to `camera` (see the header comment). Throws std::invalid_argument when the camera
// has no bearing in its image or the fitted lens is not a valid camera over the FOV.
LensFit FitExchangeLens(const Camera& camera, ExchangeLensModel model);

// The rovo camera of an exchange lens (ds -> double_sphere, eucm -> extended_unified, kb4 ->
// equidistant); throws std::invalid_argument for omni (no rovo model) naming `what`.
Camera CameraFromExchangeLens(ExchangeLensModel model, const std::vector<double>& params, int width, int height,
                              double max_fov_deg, const std::string& what);

}  // namespace rovo
