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
// plane); CamFromImg returns a unit bearing. Neither divides by z (except on the optical axis
// itself, where z > 0, to give Jets the right derivatives). The field-of-view limit is not a model
// parameter: `Camera` (camera.h) applies it.
//
// Pixel convention (all models, all of rovo): continuous coordinates, u along columns (right), v
// along rows (down), the centre of the top-left pixel at (0, 0), as in OpenCV.
// Camera frame: OpenCV (x right, y down, z along the optical axis).

#include <cmath>

namespace rovo {

// Degrees at the interfaces, radians inside.
inline constexpr double kDegToRad = M_PI / 180.0;

// The X-macro list of models: (enum id, struct, name on disk).
#define ROVO_CAMERA_MODELS(X)                          \
  X(kEquidistant, EquidistantModel, "equidistant")     \
  X(kDoubleSphere, DoubleSphereModel, "double_sphere") \
  X(kOcam, OcamModel, "ocam")                          \
  X(kExtendedUnified, ExtendedUnifiedModel, "extended_unified")

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
      // On the axis r(theta) = theta + O(theta^3) and theta = |(x, y)| / z + ...: the first-order
      // expansion has the exact value (the centre) and the right derivatives for Jets.
      uv[0] = params[0] * point_in_cam[0] / point_in_cam[2] + params[2];
      uv[1] = params[1] * point_in_cam[1] / point_in_cam[2] + params[3];
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
      const T df =
          T(1) + t2 * (T(3) * params[4] + t2 * (T(5) * params[5] + t2 * (T(7) * params[6] + t2 * T(9) * params[7])));
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

// Double sphere (Usenko, Demmel, Cremers: "The Double Sphere Camera Model", 3DV 2018).
//   params = [fx, fy, cx, cy, xi, alpha]
//   d1 = |p|,  d2 = sqrt(x^2 + y^2 + (xi d1 + z)^2),  s = alpha d2 + (1 - alpha)(xi d1 + z)
//   u = fx x / s + cx,  v = fy y / s + cy
// Valid set of the projection (where s > 0 and the map is injective):
//   z > -w2 d1,  w2 = (w1 + xi) / sqrt(2 w1 xi + xi^2 + 1),
//   w1 = alpha / (1 - alpha) if alpha <= 0.5 else (1 - alpha) / alpha,
// i.e. angles from the axis below acos(-w2) (e.g. xi = -0.2, alpha = 0.6: 122 degrees, so a
// 220-degree FOV fits). Unprojection (closed form, a unit vector by construction):
//   mx = (u - cx) / fx, my = (v - cy) / fy, r2 = mx^2 + my^2, valid if alpha <= 0.5 or
//   r2 <= 1 / (2 alpha - 1);
//   mz = (1 - alpha^2 r2) / (alpha sqrt(1 - (2 alpha - 1) r2) + 1 - alpha)
//   bearing = (mz xi + sqrt(mz^2 + (1 - xi^2) r2)) / (mz^2 + r2) * (mx, my, mz) - (0, 0, xi)
// CamFromImg also rejects bearings outside the valid set above (so it inverts ImgFromCam exactly).
// Parameter ranges: fx, fy > 0, alpha in [0, 1], xi in [-1, 1].
struct DoubleSphereModel {
  static constexpr int kNumParams = 6;
  static constexpr const char* kParamNames = "fx, fy, cx, cy, xi, alpha";

  // w2 of the valid set z > -w2 |p|.
  template <typename T>
  static T ValidW2(const T* params) {
    using namespace camera_internal;
    const T& xi = params[4];
    const T& alpha = params[5];
    const T w1 = alpha <= T(0.5) ? T(alpha / (T(1) - alpha)) : T((T(1) - alpha) / alpha);
    return (w1 + xi) / sqrt(T(2) * w1 * xi + xi * xi + T(1));
  }

  template <typename T>
  static bool ImgFromCam(const T* params, int num_params, const T* point_in_cam, T* uv) {
    using namespace camera_internal;
    const T& x = point_in_cam[0];
    const T& y = point_in_cam[1];
    const T& z = point_in_cam[2];
    const T& xi = params[4];
    const T& alpha = params[5];
    const T r2 = x * x + y * y;
    const T d1_sq = r2 + z * z;
    if (!(d1_sq > T(0))) return false;
    const T d1 = sqrt(d1_sq);
    if (!(z > -ValidW2(params) * d1)) return false;
    const T k = xi * d1 + z;
    const T d2 = sqrt(r2 + k * k);
    const T s = alpha * d2 + (T(1) - alpha) * k;
    if (!(s > T(0))) return false;
    uv[0] = params[0] * x / s + params[2];
    uv[1] = params[1] * y / s + params[3];
    return true;
  }

  template <typename T>
  static bool CamFromImg(const T* params, int num_params, const T* uv, T* bearing_in_cam) {
    using namespace camera_internal;
    const T& xi = params[4];
    const T& alpha = params[5];
    const T mx = (uv[0] - params[2]) / params[0];
    const T my = (uv[1] - params[3]) / params[1];
    const T r2 = mx * mx + my * my;
    const T root_arg = T(1) - (T(2) * alpha - T(1)) * r2;
    if (!(root_arg >= T(0))) return false;  // outside the image disc of alpha > 0.5
    const T mz = (T(1) - alpha * alpha * r2) / (alpha * sqrt(root_arg) + T(1) - alpha);
    const T disc = mz * mz + (T(1) - xi * xi) * r2;
    if (!(disc >= T(0))) return false;
    const T k = (mz * xi + sqrt(disc)) / (mz * mz + r2);
    bearing_in_cam[0] = k * mx;
    bearing_in_cam[1] = k * my;
    bearing_in_cam[2] = k * mz - xi;
    return bearing_in_cam[2] > -ValidW2(params);
  }
};

// Extended unified camera model (Khomutenko, Garcia, Martinet: "An Enhanced Unified Camera Model",
// RA-L 2016), as in Kalibr's `eucm` and Basalt's `eucm`.
//   params = [fx, fy, cx, cy, alpha, beta]
//   d = sqrt(beta (x^2 + y^2) + z^2),  s = alpha d + (1 - alpha) z
//   u = fx x / s + cx,  v = fy y / s + cy
// Valid set of the projection: z > -w d, w = alpha / (1 - alpha) if alpha <= 0.5 else
// (1 - alpha) / alpha (for alpha > 0.5 and beta = 1: angles from the axis below acos(-w)).
// Unprojection (closed form):
//   mx = (u - cx) / fx, my = (v - cy) / fy, r2 = mx^2 + my^2, valid if alpha <= 0.5 or
//   r2 <= 1 / (beta (2 alpha - 1));
//   mz = (1 - beta alpha^2 r2) / (alpha sqrt(1 - (2 alpha - 1) beta r2) + 1 - alpha)
//   bearing = (mx, my, mz) / |(mx, my, mz)|
// CamFromImg also rejects bearings outside the valid set above (so it inverts ImgFromCam exactly).
// Parameter ranges: fx, fy > 0, alpha in [0, 1], beta > 0.
struct ExtendedUnifiedModel {
  static constexpr int kNumParams = 6;
  static constexpr const char* kParamNames = "fx, fy, cx, cy, alpha, beta";

  // w of the valid set z > -w d.
  template <typename T>
  static T ValidW(const T* params) {
    const T& alpha = params[4];
    return alpha <= T(0.5) ? T(alpha / (T(1) - alpha)) : T((T(1) - alpha) / alpha);
  }

  template <typename T>
  static bool ImgFromCam(const T* params, int num_params, const T* point_in_cam, T* uv) {
    using namespace camera_internal;
    const T& x = point_in_cam[0];
    const T& y = point_in_cam[1];
    const T& z = point_in_cam[2];
    const T& alpha = params[4];
    const T& beta = params[5];
    const T d2 = beta * (x * x + y * y) + z * z;
    if (!(d2 > T(0))) return false;
    const T d = sqrt(d2);
    if (!(z > -ValidW(params) * d)) return false;
    const T s = alpha * d + (T(1) - alpha) * z;
    if (!(s > T(0))) return false;
    uv[0] = params[0] * x / s + params[2];
    uv[1] = params[1] * y / s + params[3];
    return true;
  }

  template <typename T>
  static bool CamFromImg(const T* params, int num_params, const T* uv, T* bearing_in_cam) {
    using namespace camera_internal;
    const T& alpha = params[4];
    const T& beta = params[5];
    const T mx = (uv[0] - params[2]) / params[0];
    const T my = (uv[1] - params[3]) / params[1];
    const T r2 = mx * mx + my * my;
    const T root_arg = T(1) - (T(2) * alpha - T(1)) * beta * r2;
    if (!(root_arg >= T(0))) return false;  // outside the image disc of alpha > 0.5
    const T mz = (T(1) - beta * alpha * alpha * r2) / (alpha * sqrt(root_arg) + T(1) - alpha);
    const T norm = sqrt(r2 + mz * mz);
    bearing_in_cam[0] = mx / norm;
    bearing_in_cam[1] = my / norm;
    bearing_in_cam[2] = mz / norm;
    const T d = sqrt(beta * r2 + mz * mz) / norm;
    return bearing_in_cam[2] > -ValidW(params) * d;
  }
};

// Scaramuzza's omnidirectional polynomial model (OCamCalib), in the interpretation of OmniMVS.
//   params = [cx, cy, c, d, e, a0, a1, a2, a3, a4, b0, b1, ..., b(K-1)],  num_params = 10 + K
//   (cx, cy): distortion centre in rovo pixels (column, row).
//   Affine from the undistorted sensor point (x along columns, y along rows) to the pixel:
//     u = c x + d y + cx,   v = e x + y + cy.
//   Unprojection (the forward polynomial a defines the lens):
//     (x, y) = A^-1 (u - cx, v - cy),  A = [c d; e 1],  rho = |(x, y)|,
//     bearing = normalize(x, y, -(a0 + a1 rho + a2 rho^2 + a3 rho^3 + a4 rho^4))   (a0 < 0)
//   Projection (the inverse polynomial b approximates the inverse of the above, fitted by
//   FitOcamInversePolynomial in ocam.h):
//     theta = atan2(-z, sqrt(x^2 + y^2))  (elevation from the image plane, -pi/2 on the axis),
//     rho = b0 + b1 theta + ... + b(K-1) theta^(K-1),
//     (x, y) = rho (X, Y) / sqrt(X^2 + Y^2), then the affine.
// Valid where rho(theta) is increasing (equivalently the elevation atan2(-poly(rho), rho) increases
// with rho); Camera::Check verifies this over the FOV and that b matches a (ocam.h).
// Mapping from OCamCalib's own calib_results.txt conventions: see ReadOcamCalibTxt in ocam.h.
struct OcamModel {
  static constexpr int kNumFixedParams = 10;  // cx, cy, c, d, e, a0..a4
  static constexpr int kMinNumParams = 11;    // at least one inverse coefficient
  static constexpr const char* kParamNames = "cx, cy, c, d, e, a0, a1, a2, a3, a4, b0, ..., b(K-1)";

  // z-component magnitude of the unnormalized ray: a0 + a1 rho + ... + a4 rho^4 (negative near the axis).
  template <typename T>
  static T ForwardPoly(const T* params, const T& rho) {
    return params[5] + rho * (params[6] + rho * (params[7] + rho * (params[8] + rho * params[9])));
  }

  // rho(theta) = sum b_i theta^i (Horner).
  template <typename T>
  static T InversePoly(const T* params, int num_params, const T& theta) {
    T rho = params[num_params - 1];
    for (int i = num_params - 2; i >= kNumFixedParams; --i) rho = rho * theta + params[i];
    return rho;
  }

  // d rho / d theta.
  template <typename T>
  static T InversePolyDerivative(const T* params, int num_params, const T& theta) {
    T derivative = T(0);
    for (int i = num_params - 1; i > kNumFixedParams; --i) {
      derivative = derivative * theta + T(i - kNumFixedParams) * params[i];
    }
    return derivative;
  }

  template <typename T>
  static bool ImgFromCam(const T* params, int num_params, const T* point_in_cam, T* uv) {
    using namespace camera_internal;
    if (num_params < kMinNumParams) return false;
    const T r2 = point_in_cam[0] * point_in_cam[0] + point_in_cam[1] * point_in_cam[1];
    if (r2 == T(0)) {
      if (!(point_in_cam[2] > T(0))) return false;  // the origin or straight behind
      // On the axis rho = rho'(-pi/2) |(x, y)| / z + ... (rho(-pi/2) = 0 for a fitted inverse): the
      // first-order expansion has the exact value (the centre) and the right derivatives for Jets.
      const T slope = InversePolyDerivative(params, num_params, T(-M_PI / 2)) / point_in_cam[2];
      const T x = slope * point_in_cam[0];
      const T y = slope * point_in_cam[1];
      uv[0] = params[2] * x + params[3] * y + params[0];
      uv[1] = params[4] * x + y + params[1];
      return true;
    }
    const T r = sqrt(r2);
    const T theta = atan2(-point_in_cam[2], r);
    const T rho = InversePoly(params, num_params, theta);
    const T x = rho * point_in_cam[0] / r;
    const T y = rho * point_in_cam[1] / r;
    uv[0] = params[2] * x + params[3] * y + params[0];
    uv[1] = params[4] * x + y + params[1];
    return true;
  }

  template <typename T>
  static bool CamFromImg(const T* params, int num_params, const T* uv, T* bearing_in_cam) {
    using namespace camera_internal;
    if (num_params < kNumFixedParams) return false;
    const T du = uv[0] - params[0];
    const T dv = uv[1] - params[1];
    const T det = params[2] - params[3] * params[4];  // c - d e
    if (det == T(0)) return false;
    const T x = (du - params[3] * dv) / det;
    const T y = (params[2] * dv - params[4] * du) / det;
    const T rho2 = x * x + y * y;
    // At the centre rho2 (zero, with zero derivative) stands in for rho (sqrt is not differentiable at 0).
    const T rho = rho2 > T(0) ? T(sqrt(rho2)) : rho2;
    const T z = -ForwardPoly(params, rho);
    const T norm2 = rho2 + z * z;
    if (!(norm2 > T(0))) return false;
    const T inv_norm = T(1) / sqrt(norm2);
    bearing_in_cam[0] = x * inv_norm;
    bearing_in_cam[1] = y * inv_norm;
    bearing_in_cam[2] = z * inv_norm;
    return true;
  }
};

}  // namespace rovo
