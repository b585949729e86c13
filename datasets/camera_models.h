#pragma once
// Camera models valid beyond 180 degrees of field of view.
//
// Each model is a stateless struct with static functions templated on the scalar (double, float,
// ceres::Jet, Eigen::AutoDiffScalar), COLMAP-style:
//   template <typename T> static bool ImgFromCam(const T* params, int num_params,
//                                                const T point_in_cam[3], T uv[2]);
//   template <typename T> static bool CamFromImg(const T* params, int num_params,
//                                                const T uv[2], T bearing_in_cam[3]);
// ImgFromCam accepts any non-zero point (also z <= 0: a 220-degree lens sees behind its image
// plane); CamFromImg returns a unit bearing. Neither divides by z. The field-of-view limit is not a
// model parameter: `Camera` (camera.h) applies it.
//
// Pixel convention (all models, all of rovo): continuous coordinates, u along columns (right), v
// along rows (down), the centre of the top-left pixel at (0, 0), as in OpenCV.
// Camera frame: OpenCV (x right, y down, z along the optical axis).

#include <cmath>

namespace rovo {

// The X-macro list of models: (enum id, struct, name on disk).
#define ROVO_CAMERA_MODELS(X)                    \
  X(kEquidistant, EquidistantModel, "equidistant") \
  X(kDoubleSphere, DoubleSphereModel, "double_sphere") \
  X(kOcam, OcamModel, "ocam")

namespace camera_internal {
using std::abs;
using std::atan2;
using std::cos;
using std::sin;
using std::sqrt;
}  // namespace camera_internal

// Kannala-Brandt equidistant fisheye.
//   params = [fx, fy, cx, cy, k1, k2, k3, k4]
//   theta = atan2(sqrt(x^2 + y^2), z)           (0 on the axis, pi behind the camera)
//   r(theta) = theta + k1 theta^3 + k2 theta^5 + k3 theta^7 + k4 theta^9
//   u = fx r(theta) x / sqrt(x^2+y^2) + cx,  v = fy r(theta) y / sqrt(x^2+y^2) + cy
// Valid for theta in [0, pi) wherever r(theta) is increasing; Camera enforces max_fov.
struct EquidistantModel {
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamNames = "fx, fy, cx, cy, k1, k2, k3, k4";

  template <typename T>
  static T Distort(const T* params, const T& theta) {
    const T t2 = theta * theta;
    return theta * (T(1) + t2 * (params[4] + t2 * (params[5] + t2 * (params[6] + t2 * params[7]))));
  }

  template <typename T>
  static bool ImgFromCam(const T* params, int num_params, const T* point_in_cam, T* uv) {
    using namespace camera_internal;
    const T r_xy2 = point_in_cam[0] * point_in_cam[0] + point_in_cam[1] * point_in_cam[1];
    if (r_xy2 == T(0)) {
      if (!(point_in_cam[2] > T(0))) return false;  // the origin or straight behind
      uv[0] = params[2];
      uv[1] = params[3];
      return true;
    }
    const T r_xy = sqrt(r_xy2);
    const T theta = atan2(r_xy, point_in_cam[2]);
    const T r = Distort(params, theta);
    uv[0] = params[0] * r * point_in_cam[0] / r_xy + params[2];
    uv[1] = params[1] * r * point_in_cam[1] / r_xy + params[3];
    return true;
  }

  // Newton iteration on r(theta) = rho, started at theta = rho.
  template <typename T>
  static bool CamFromImg(const T* params, int num_params, const T* uv, T* bearing_in_cam) {
    using namespace camera_internal;
    const T mx = (uv[0] - params[2]) / params[0];
    const T my = (uv[1] - params[3]) / params[1];
    const T rho = sqrt(mx * mx + my * my);
    if (rho == T(0)) {
      bearing_in_cam[0] = T(0);
      bearing_in_cam[1] = T(0);
      bearing_in_cam[2] = T(1);
      return true;
    }
    T theta = rho;
    for (int i = 0; i < 20; ++i) {
      const T t2 = theta * theta;
      const T f = Distort(params, theta) - rho;
      const T df = T(1) + t2 * (T(3) * params[4] + t2 * (T(5) * params[5] + t2 * (T(7) * params[6] + t2 * T(9) * params[7])));
      if (!(df > T(0))) return false;
      const T step = f / df;
      theta -= step;
      if (abs(step) < T(1e-12)) break;
    }
    if (!(theta >= T(0)) || !(theta < T(M_PI))) return false;
    if (abs(Distort(params, theta) - rho) > T(1e-6)) return false;
    const T s = sin(theta) / rho;
    bearing_in_cam[0] = s * mx;
    bearing_in_cam[1] = s * my;
    bearing_in_cam[2] = cos(theta);
    return true;
  }
};

// Forward declarations; implemented in camera_models_*.h by the datasets owner.
struct DoubleSphereModel;
struct OcamModel;

}  // namespace rovo
