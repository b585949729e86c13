#include "vo/hybrid_projection.h"

#include <tbb/parallel_for.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "datasets/camera_models.h"
#include "vo/bilinear_remap.h"

namespace rovo {

void HybridProjectionOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("HybridProjectionOptions.") + what);
  };
  require(focal_px >= 0.0, "focal_px must be >= 0 (0: automatic)");
  require(focal_scale > 0.0, "focal_scale must be > 0");
  require(max_plane_angle_deg > 0.0 && max_plane_angle_deg < 90.0, "max_plane_angle_deg must be in (0, 90)");
  require(vertical_fov_above_deg > 0.0 && vertical_fov_above_deg < 90.0, "vertical_fov_above_deg must be in (0, 90)");
  require(vertical_fov_below_deg > 0.0 && vertical_fov_below_deg < 90.0, "vertical_fov_below_deg must be in (0, 90)");
  require(rebuild_threshold_deg >= 0.0, "rebuild_threshold_deg must be >= 0");
}
namespace {

Eigen::Vector3d CameraCentreInRig(const Rigid3& cam_from_rig) { return cam_from_rig.Inverse().translation; }

// Normal of the plane through the neighbour baseline, parallel to `up`, signed towards the camera's
// forward direction (or to the given side when the plane faces sideways).
Eigen::Vector3d PlaneNormal(const Eigen::Vector3d& baseline, const Eigen::Vector3d& up, const Eigen::Vector3d& forward,
                            const Eigen::Vector3d& right, double side, int camera) {
  Eigen::Vector3d m = baseline.cross(up);
  if (m.norm() < 1e-9 * std::max(1.0, baseline.norm())) {
    throw std::invalid_argument("hybrid projection: camera " + std::to_string(camera) +
                                ": baseline to its neighbour is parallel to the rig-plane normal");
  }
  m.normalize();
  const double along = m.dot(forward);
  if (along < -1e-9 || (std::abs(along) <= 1e-9 && side * m.dot(right) < 0)) m = -m;
  return m;
}

double SignedAngle(const Eigen::Vector3d& v, const Eigen::Vector3d& forward, const Eigen::Vector3d& right) {
  return std::atan2(v.dot(right), v.dot(forward));
}

}  // namespace

std::vector<HybridLayout> ComputeHybridLayouts(const std::vector<Camera>& cameras,
                                               const std::vector<Rigid3>& cam_from_rig) {
  const int n = static_cast<int>(cam_from_rig.size());
  if (n < 2) throw std::invalid_argument("hybrid projection: the rig needs at least 2 cameras");
  std::vector<Eigen::Vector3d> centres(n);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_up = Eigen::Vector3d::Zero();
  std::vector<Eigen::Matrix3d> rig_from_cam(n);
  for (int i = 0; i < n; ++i) {
    centres[i] = CameraCentreInRig(cam_from_rig[i]);
    centroid += centres[i] / n;
    rig_from_cam[i] = cam_from_rig[i].RotationMatrix().transpose();
    mean_up += rig_from_cam[i] * Eigen::Vector3d(0, -1, 0);
  }
  Eigen::MatrixXd centred(3, n);
  for (int i = 0; i < n; ++i) centred.col(i) = centres[i] - centroid;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullU);
  const Eigen::Vector3d sv = Eigen::Vector3d(svd.singularValues()(0), n > 1 ? svd.singularValues()(1) : 0.0,
                                             n > 2 ? svd.singularValues()(2) : 0.0);
  if (sv(0) < 1e-9) throw std::invalid_argument("hybrid projection: all camera centres coincide");
  Eigen::Vector3d up;
  if (sv(1) < 1e-6 * sv(0)) {
    // Collinear centres: the plane contains the line; take the mean camera up orthogonal to it.
    const Eigen::Vector3d line = svd.matrixU().col(0);
    up = mean_up - mean_up.dot(line) * line;
    if (up.norm() < 1e-9) throw std::invalid_argument("hybrid projection: cameras look along their baseline");
    up.normalize();
  } else {
    up = svd.matrixU().col(2);
    if (up.dot(mean_up) < 0) up = -up;
  }

  // Azimuth order of the centres around `up` (counter-clockwise seen from above).
  const Eigen::Vector3d e1 = svd.matrixU().col(0) - svd.matrixU().col(0).dot(up) * up;
  const Eigen::Vector3d axis1 = e1.normalized();
  const Eigen::Vector3d axis2 = up.cross(axis1);
  std::vector<double> azimuth(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = centres[i] - centroid;
    azimuth[i] = std::atan2(p.dot(axis2), p.dot(axis1));
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return azimuth[a] < azimuth[b]; });

  std::vector<HybridLayout> layouts(n);
  for (int k = 0; k < n; ++k) {
    const int i = order[k];
    HybridLayout& layout = layouts[i];
    layout.left_neighbour = order[(k + 1) % n];
    layout.right_neighbour = order[(k + n - 1) % n];
    const Eigen::Vector3d optical_axis = rig_from_cam[i] * Eigen::Vector3d::UnitZ();
    Eigen::Vector3d forward = optical_axis - optical_axis.dot(up) * up;
    if (forward.norm() < 1e-6) {
      throw std::invalid_argument("hybrid projection: camera " + std::to_string(i) +
                                  " looks along the rig-plane normal");
    }
    forward.normalize();
    const Eigen::Vector3d right = forward.cross(up);
    layout.up_in_rig = up;
    layout.forward_in_rig = forward;
    layout.left_normal_in_rig = PlaneNormal(centres[layout.left_neighbour] - centres[i], up, forward, right, -1.0, i);
    layout.right_normal_in_rig = PlaneNormal(centres[layout.right_neighbour] - centres[i], up, forward, right, +1.0, i);
    const double psi_left = SignedAngle(layout.left_normal_in_rig, forward, right);
    const double psi_right = SignedAngle(layout.right_normal_in_rig, forward, right);
    if (psi_left > psi_right + 1e-9) {
      throw std::invalid_argument(
          "hybrid projection: camera " + std::to_string(i) +
          ": left plane lies to the right of the right plane (rig not arranged around a centre)");
    }
  }
  return layouts;
}

std::vector<HybridLayout> ComputeHybridLayouts(const Rig& rig) {
  std::vector<Camera> cameras;
  for (const RigCamera& c : rig.cameras) cameras.push_back(c.camera);
  return ComputeHybridLayouts(cameras, rig.Extrinsics());
}

double HybridLayoutChangeDeg(const HybridLayout& a, const Rigid3& a_cam_from_rig, const HybridLayout& b,
                             const Rigid3& b_cam_from_rig) {
  const Eigen::Matrix3d ra = a_cam_from_rig.RotationMatrix();
  const Eigen::Matrix3d rb = b_cam_from_rig.RotationMatrix();
  double worst = 0.0;
  const auto check = [&](const Eigen::Vector3d& va, const Eigen::Vector3d& vb) {
    worst = std::max(worst, AngleBetween(ra * va, rb * vb));
  };
  check(a.up_in_rig, b.up_in_rig);
  check(a.forward_in_rig, b.forward_in_rig);
  check(a.left_normal_in_rig, b.left_normal_in_rig);
  check(a.right_normal_in_rig, b.right_normal_in_rig);
  return worst / kDegToRad;
}

std::vector<HybridProjection> HybridProjection::ForRig(const Rig& rig, const HybridProjectionOptions& options) {
  options.Check();
  const std::vector<HybridLayout> layouts = ComputeHybridLayouts(rig);
  std::vector<HybridProjection> projections;
  projections.reserve(layouts.size());
  for (int i = 0; i < rig.NumCameras(); ++i) {
    projections.emplace_back(rig.cameras[i].camera, rig.cameras[i].cam_from_rig, layouts[i], options);
  }
  return projections;
}

HybridProjection::HybridProjection(const Camera& camera, const Rigid3& cam_from_rig, const HybridLayout& layout,
                                   const HybridProjectionOptions& options)
    : camera_(camera), cam_from_rig_(cam_from_rig), layout_(layout), options_(options) {
  options_.Check();
  const Eigen::Matrix3d cam_from_rig_rotation = cam_from_rig.RotationMatrix();
  rig_from_cam_rotation_ = cam_from_rig_rotation.transpose();
  up_ = cam_from_rig_rotation * layout.up_in_rig;
  forward_ = cam_from_rig_rotation * layout.forward_in_rig;
  right_ = forward_.cross(up_);
  normal_left_ = cam_from_rig_rotation * layout.left_normal_in_rig;
  normal_right_ = cam_from_rig_rotation * layout.right_normal_in_rig;
  tangent_left_ = normal_left_.cross(up_);
  tangent_right_ = normal_right_.cross(up_);
  psi_left_ = SignedAngle(normal_left_, forward_, right_);
  psi_right_ = SignedAngle(normal_right_, forward_, right_);

  // Focal length: mean local fisheye resolution at the plane tangent directions.
  const auto resolution = [&](const Eigen::Vector3d& d) -> double {
    const Eigen::Vector3d a = d.unitOrthogonal();
    const Eigen::Vector3d b = d.cross(a);
    const double h = 1e-4;
    const auto p1 = camera_.Project(d + h * a), p2 = camera_.Project(d - h * a);
    const auto p3 = camera_.Project(d + h * b), p4 = camera_.Project(d - h * b);
    if (!p1 || !p2 || !p3 || !p4) return 0.0;
    Eigen::Matrix2d jac;
    jac.col(0) = (*p1 - *p2) / (2 * h);
    jac.col(1) = (*p3 - *p4) / (2 * h);
    return std::sqrt(std::abs(jac.determinant()));
  };
  focal_ = options.focal_px;
  if (focal_ <= 0) {
    double sum = 0;
    int count = 0;
    for (const Eigen::Vector3d& d : {normal_left_, normal_right_}) {
      const double r = resolution(d);
      if (r > 0) sum += r, ++count;
    }
    if (count == 0) sum = resolution(Eigen::Vector3d::UnitZ()), count = 1;
    if (!(sum > 0)) throw std::invalid_argument("hybrid projection: cannot measure the fisheye resolution");
    focal_ = options.focal_scale * sum / count;
  }

  // Horizontal extent of each plane: up to the max plane angle or the FOV edge along the horizon.
  const double max_angle = std::clamp(options.max_plane_angle_deg, 1.0, 89.0) * kDegToRad;
  const auto extent = [&](const Eigen::Vector3d& normal, const Eigen::Vector3d& tangent) {
    double last_ok = 0.0;
    for (double a = 0.0; a <= max_angle + 1e-12; a += 0.25 * kDegToRad) {
      if (!camera_.InFov(std::cos(a) * normal + std::sin(a) * tangent)) break;
      last_ok = a;
    }
    return std::tan(last_ok);
  };
  const double s_min = psi_left_ - extent(normal_left_, -tangent_left_);
  const double s_max = psi_right_ + extent(normal_right_, tangent_right_);
  const auto rows = [&](double angle_deg) {
    return static_cast<int>(std::ceil(std::tan(std::clamp(angle_deg, 1.0, 85.0) * kDegToRad) * focal_));
  };
  const int rows_above = rows(options.vertical_fov_above_deg), rows_below = rows(options.vertical_fov_below_deg);
  width_ = static_cast<int>(std::ceil((s_max - s_min) * focal_)) + 1;
  height_ = rows_above + rows_below + 1;
  cx_ = -s_min * focal_;
  cy_ = rows_above;
  BuildMaps();
}

std::optional<Eigen::Vector3d> HybridProjection::BearingFromWarped(const Eigen::Vector2d& warped_px) const {
  const double s = (warped_px.x() - cx_) / focal_;
  const double y = (warped_px.y() - cy_) / focal_;
  Eigen::Vector3d point;
  if (s > psi_right_) {
    point = normal_right_ + (s - psi_right_) * tangent_right_ - y * up_;
  } else if (s < psi_left_) {
    point = normal_left_ + (s - psi_left_) * tangent_left_ - y * up_;
  } else {
    point = std::cos(s) * forward_ + std::sin(s) * right_ - y * up_;
  }
  const Eigen::Vector3d bearing = point.normalized();
  if (!camera_.InFov(bearing)) return std::nullopt;
  return bearing;
}

std::optional<Eigen::Vector2d> HybridProjection::WarpedFromBearing(const Eigen::Vector3d& bearing_in_cam) const {
  if (!camera_.InFov(bearing_in_cam)) return std::nullopt;
  const double height = bearing_in_cam.dot(up_);
  const Eigen::Vector3d horizontal = bearing_in_cam - height * up_;
  const double horizontal_norm = horizontal.norm();
  if (horizontal_norm < 1e-12 * bearing_in_cam.norm()) return std::nullopt;
  const double psi = SignedAngle(horizontal, forward_, right_);
  double s, y;
  if (psi > psi_right_) {
    const double delta = psi - psi_right_;
    if (delta >= 0.5 * M_PI - 1e-9) return std::nullopt;
    s = psi_right_ + std::tan(delta);
    y = -height / bearing_in_cam.dot(normal_right_);
  } else if (psi < psi_left_) {
    const double delta = psi_left_ - psi;
    if (delta >= 0.5 * M_PI - 1e-9) return std::nullopt;
    s = psi_left_ - std::tan(delta);
    y = -height / bearing_in_cam.dot(normal_left_);
  } else {
    s = psi;
    y = -height / horizontal_norm;
  }
  return Eigen::Vector2d(cx_ + focal_ * s, cy_ + focal_ * y);
}

std::optional<Eigen::Vector2d> HybridProjection::FisheyeFromWarped(const Eigen::Vector2d& warped_px) const {
  const auto bearing = BearingFromWarped(warped_px);
  if (!bearing) return std::nullopt;
  return camera_.Project(*bearing);
}

std::optional<Eigen::Vector2d> HybridProjection::WarpedFromFisheye(const Eigen::Vector2d& fisheye_px) const {
  const auto bearing = camera_.Unproject(fisheye_px);
  if (!bearing) return std::nullopt;
  return WarpedFromBearing(*bearing);
}

void HybridProjection::BuildMaps() {
  // Exact fisheye pixel of a warped pixel, or nullopt when outside the FOV or (with one pixel of
  // margin for bilinear interpolation) outside the fisheye image.
  const auto exact = [&](int u, int v) -> std::optional<Eigen::Vector2d> {
    auto uv = FisheyeFromWarped(Eigen::Vector2d(u, v));
    if (!uv || uv->x() < 0 || uv->y() < 0 || uv->x() > camera_.width - 1 || uv->y() > camera_.height - 1) {
      return std::nullopt;
    }
    return uv;
  };
  // Nodes every kMapStep pixels (the last row/column included).
  const int node_cols = (width_ - 1 + kMapStep - 1) / kMapStep + 1;
  const int node_rows = (height_ - 1 + kMapStep - 1) / kMapStep + 1;
  const auto node_u = [&](int k) { return std::min(k * kMapStep, width_ - 1); };
  const auto node_v = [&](int k) { return std::min(k * kMapStep, height_ - 1); };
  std::vector<Eigen::Vector2d> node_uv(static_cast<size_t>(node_cols) * node_rows);
  std::vector<uint8_t> node_ok(node_uv.size(), 0);
  tbb::parallel_for(0, node_rows, [&](int r) {
    for (int c = 0; c < node_cols; ++c) {
      const auto uv = exact(node_u(c), node_v(r));
      const size_t i = static_cast<size_t>(r) * node_cols + c;
      if (uv) node_uv[i] = *uv, node_ok[i] = 1;
    }
  });
  // A cell is interpolated when the 4x4 nodes around it are valid (one cell of margin to the
  // valid area's border, which is then computed exactly).
  const auto interior = [&](int r, int c) {
    for (int y = std::max(0, r - 1); y <= std::min(node_rows - 1, r + 2); ++y) {
      for (int x = std::max(0, c - 1); x <= std::min(node_cols - 1, c + 2); ++x) {
        if (!node_ok[static_cast<size_t>(y) * node_cols + x]) return false;
      }
    }
    return r + 1 < node_rows && c + 1 < node_cols;
  };
  map_x_.create(height_, width_, CV_32FC1);
  map_y_.create(height_, width_, CV_32FC1);
  valid_mask_.create(height_, width_, CV_8UC1);
  tbb::parallel_for(0, height_, [&](int v) {
    float* mx = map_x_.ptr<float>(v);
    float* my = map_y_.ptr<float>(v);
    uint8_t* valid = valid_mask_.ptr<uint8_t>(v);
    const int r = std::min(v / kMapStep, node_rows - 2);
    const double ty = node_v(r + 1) > node_v(r) ? double(v - node_v(r)) / (node_v(r + 1) - node_v(r)) : 0.0;
    for (int u = 0; u < width_; ++u) {
      const int c = std::min(u / kMapStep, node_cols - 2);
      std::optional<Eigen::Vector2d> uv;
      if (interior(r, c)) {
        const double tx = node_u(c + 1) > node_u(c) ? double(u - node_u(c)) / (node_u(c + 1) - node_u(c)) : 0.0;
        const size_t i = static_cast<size_t>(r) * node_cols + c;
        uv = (1 - ty) * ((1 - tx) * node_uv[i] + tx * node_uv[i + 1]) +
             ty * ((1 - tx) * node_uv[i + node_cols] + tx * node_uv[i + node_cols + 1]);
      } else {
        uv = exact(u, v);
      }
      if (uv) {
        mx[u] = static_cast<float>(uv->x());
        my[u] = static_cast<float>(uv->y());
        valid[u] = 255;
      } else {
        mx[u] = my[u] = -1.0f;
        valid[u] = 0;
      }
    }
  });
  cv::convertMaps(map_x_, map_y_, map_fixed_, map_frac_, CV_16SC2);
}

namespace {

void CheckFisheyeSize(const cv::Mat& fisheye, const Camera& camera) {
  if (fisheye.cols != camera.width || fisheye.rows != camera.height) {
    throw std::invalid_argument("hybrid projection: image is " + std::to_string(fisheye.cols) + "x" +
                                std::to_string(fisheye.rows) + ", camera is " + std::to_string(camera.width) + "x" +
                                std::to_string(camera.height));
  }
}

}  // namespace

void HybridProjection::Warp(const cv::Mat& fisheye, cv::Mat* warped) const {
  CheckFisheyeSize(fisheye, camera_);
  RemapBilinearGray(fisheye, map_fixed_, map_frac_, warped);
}

void HybridProjection::WarpRows(const cv::Mat& fisheye, int first_row, int last_row, cv::Mat* warped) const {
  CheckFisheyeSize(fisheye, camera_);
  if (warped->rows != height_ || warped->cols != width_ || warped->type() != fisheye.type()) {
    throw std::invalid_argument(
        "hybrid projection: WarpRows needs a warped image of the projection's size and the "
        "fisheye's type");
  }
  first_row = std::max(first_row, 0);
  last_row = std::min(last_row, height_);
  if (first_row >= last_row) return;
  cv::Mat band = warped->rowRange(first_row, last_row);
  RemapBilinearGray(fisheye, map_fixed_.rowRange(first_row, last_row), map_frac_.rowRange(first_row, last_row), &band);
}

}  // namespace rovo
