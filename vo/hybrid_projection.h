#pragma once
// Hybrid projection (ROVO paper IV-A, Fig. 4): per camera, two perspective planes over the overlaps
// with the left and right neighbours, joined by a cylinder, so that the overlaps are rectified-like
// and the warped image stays continuous and smooth.
//
// Geometry (all built from the rig, any N >= 2 cameras around the rig):
//  * Rig plane: least-squares plane through the camera centres c_i (SVD of the centred centres; the
//    singular vector of the smallest singular value is its normal). `up` = that normal, oriented to
//    agree with the mean camera up direction (-y of the cameras). With collinear centres (N = 2) the
//    normal is the mean camera up made orthogonal to the baseline.
//  * Neighbours: cameras sorted by the azimuth of their centres around `up` (counter-clockwise seen
//    from above); the next camera counter-clockwise is the LEFT neighbour, the previous the RIGHT one.
//  * For camera i and neighbour j, the projection plane normal is m = normalize((c_j - c_i) x up),
//    signed so that m . forward > 0 (forward = camera's optical axis projected on the rig plane). The
//    plane {p : p . m = 1} (camera-centred, unit distance) is parallel to the baseline and to `up`.
//    Neighbours i and j get parallel planes with the same normal, hence (when both centres lie in the
//    rig plane) the same y-coordinate for a scene point, like stereo rectification.
//  * Horizontal angle psi of a direction d (rig frame, around `up`, positive to the camera's right
//    r0 = forward x up): psi = atan2(d . r0, d . forward). The plane normals sit at psi_L <= psi_R.
//    The unit cylinder around `up` through the camera centre is tangent to both planes.
//
// Warped coordinates (s, y), pixel u = cx + f s, v = cy + f y:
//   cylinder (psi_L <= psi <= psi_R):  s = psi,                     y = -(d . up) / |d_h|
//   right plane (psi > psi_R):         s = psi_R + tan(psi - psi_R), y = -(d . up) / (d . m_R)
//   left plane (psi < psi_L):          s = psi_L - tan(psi_L - psi), y = -(d . up) / (d . m_L)
// with d_h the component of d orthogonal to `up`. s is arc length on the cylinder and the
// perspective coordinate on each plane; both s and y are C1-continuous across the seams (the
// planes are tangent to the cylinder). y grows downwards (image convention).
//
// Size and focal length: f = focal_scale x the fisheye's local resolution (pixels per radian,
// sqrt|det| of the Jacobian of the fisheye projection w.r.t. two orthogonal angles) averaged over the
// two plane-tangent directions, i.e. the centres of the overlaps; so the warped image samples the
// overlaps at the fisheye's own density. Horizontally each plane extends to min(max_plane_angle,
// the camera's FOV edge along the horizon); vertically -tan(vertical_fov_above) <= y <=
// tan(vertical_fov_below) (y > 0 is below the rig plane).
//
// Online extrinsics: the virtual frame (up, forward, plane normals) is stored in the CAMERA frame;
// the warp maps depend only on it and the intrinsics. When cam_from_rig changes, the front-end
// recomputes the ideal frame and rebuilds a camera's maps only when one of its axes moves by more
// than `rebuild_threshold_deg` (default 1 deg: at f ~ 400 px/rad that is ~7 px of y-misalignment);
// tracked features are then carried over exactly through their bearings:
// new.WarpedFromBearing(old.BearingFromWarped(px)).

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "datasets/camera.h"
#include "datasets/rig.h"
#include "datasets/rigid3.h"

namespace rovo {

struct HybridProjectionOptions {
  double focal_px = 0.0;                 // warped focal length; 0 = automatic (see above)
  double focal_scale = 1.0;              // multiplies the automatic focal length
  double max_plane_angle_deg = 65.0;     // each plane spans at most this far beyond its tangent point
  double vertical_fov_above_deg = 50.0;  // the warp reaches this far above the rig plane
  double vertical_fov_below_deg = 50.0;  // and this far below it
  double rebuild_threshold_deg = 1.0;    // see "Online extrinsics" above
  void Check() const;                    // throws std::invalid_argument naming the field
};

// The rig-level layout of one camera's hybrid projection, in the RIG frame.
struct HybridLayout {
  Eigen::Vector3d up_in_rig;                                // rig-plane normal
  Eigen::Vector3d forward_in_rig;                           // unit, orthogonal to up (psi = 0)
  Eigen::Vector3d left_normal_in_rig, right_normal_in_rig;  // plane normals m_L, m_R
  int left_neighbour = -1, right_neighbour = -1;
};

// Layouts for all cameras of a rig with the given extrinsics (see the geometry above). Throws
// std::invalid_argument when the rig cannot carry the model (fewer than 2 cameras, coincident
// centres, a camera looking along `up`, or psi_L > psi_R).
std::vector<HybridLayout> ComputeHybridLayouts(const std::vector<Camera>& cameras,
                                               const std::vector<Rigid3>& cam_from_rig);
std::vector<HybridLayout> ComputeHybridLayouts(const Rig& rig);

// Largest angle (degrees) between corresponding axes of two layouts of one camera, both expressed in
// that camera's frame (the measure compared against rebuild_threshold_deg).
double HybridLayoutChangeDeg(const HybridLayout& a, const Rigid3& a_cam_from_rig, const HybridLayout& b,
                             const Rigid3& b_cam_from_rig);

class HybridProjection {
 public:
  HybridProjection() = default;
  // Builds the geometry and the warp maps (parallel; see map_x() for the cost).
  HybridProjection(const Camera& camera, const Rigid3& cam_from_rig, const HybridLayout& layout,
                   const HybridProjectionOptions& options = {});

  // All cameras of a rig.
  static std::vector<HybridProjection> ForRig(const Rig& rig, const HybridProjectionOptions& options = {});

  int width() const { return width_; }
  int height() const { return height_; }
  double focal_px() const { return focal_; }
  const Camera& camera() const { return camera_; }
  const HybridLayout& layout() const { return layout_; }
  const Rigid3& cam_from_rig() const { return cam_from_rig_; }
  // Seam positions in warped pixels (u of the left and right plane tangent lines).
  double left_seam_u() const { return cx_ + focal_ * psi_left_; }
  double right_seam_u() const { return cx_ + focal_ * psi_right_; }

  // Unit bearing in the camera frame of a warped pixel; nullopt outside the camera's FOV. Defined
  // also outside the warped rectangle.
  std::optional<Eigen::Vector3d> BearingFromWarped(const Eigen::Vector2d& warped_px) const;
  // Warped pixel of a direction (any non-zero vector) in the camera frame; nullopt outside the FOV,
  // when the direction is along `up`, or 90 deg or more away from the plane normal in a plane
  // region. The pixel may lie outside the warped rectangle (check InWarpedImage).
  std::optional<Eigen::Vector2d> WarpedFromBearing(const Eigen::Vector3d& bearing_in_cam) const;
  // WarpedFromBearing, nullopt also when the pixel lies outside the warped rectangle.
  std::optional<Eigen::Vector2d> WarpedInImageFromBearing(const Eigen::Vector3d& bearing_in_cam) const {
    auto px = WarpedFromBearing(bearing_in_cam);
    if (px && !InWarpedImage(*px)) px.reset();
    return px;
  }
  // Fisheye pixel of a warped pixel (BearingFromWarped then Camera::Project).
  std::optional<Eigen::Vector2d> FisheyeFromWarped(const Eigen::Vector2d& warped_px) const;
  // Warped pixel of a fisheye pixel.
  std::optional<Eigen::Vector2d> WarpedFromFisheye(const Eigen::Vector2d& fisheye_px) const;
  bool InWarpedImage(const Eigen::Vector2d& uv) const {
    return uv.x() >= -0.5 && uv.y() >= -0.5 && uv.x() < width_ - 0.5 && uv.y() < height_ - 0.5;
  }

  // Bearing in the rig frame (rotation only).
  Eigen::Vector3d RigFromCamRotate(const Eigen::Vector3d& v) const { return rig_from_cam_rotation_ * v; }

  // Warps a fisheye image (8-bit, 1 or 3 channels) into `warped` (same type) with the fixed-point
  // maps: cv::remap's pixels (bilinear, 0 outside the valid area), gray ones by RemapBilinearGray.
  void Warp(const cv::Mat& fisheye, cv::Mat* warped) const;
  // Warp of the rows [first_row, last_row) (clipped to the image) only, into `warped` (allocated:
  // height() x width(), the fisheye's type): the same pixels as Warp there, so bands can be warped in
  // parallel.
  void WarpRows(const cv::Mat& fisheye, int first_row, int last_row, cv::Mat* warped) const;
  // Rows per band for WarpRows: tasks an idle thread can take from another view. RemapBilinearGray
  // costs about the same in bands of any height (BM_HybridWarpOneViewInBands); cv::remap (the floor's
  // warp) is cheapest in 8-row bands, where its blocks are 8 x 2048 (docs/design-notes.md).
  static constexpr int kWarpBandRows = 8;
  // CV_8U, 255 where the warped pixel maps into the fisheye's valid area.
  const cv::Mat& valid_mask() const { return valid_mask_; }
  // Float maps warped -> fisheye (CV_32FC1 each; -1 where invalid). Exact at nodes every kMapStep
  // pixels and within one cell of the valid area's border, bilinear between nodes elsewhere
  // (error < 0.02 px, tested; cv::remap's fixed-point maps quantise to 1/32 px anyway; a step of
  // 8 px gave 0.11 px). A rebuild after an extrinsic update needs ~1/kMapStep^2 of the exact
  // evaluations.
  static constexpr int kMapStep = 2;
  const cv::Mat& map_x() const { return map_x_; }
  const cv::Mat& map_y() const { return map_y_; }
  // The fixed-point maps Warp uses (cv::convertMaps: CV_16SC2 + CV_16UC1).
  const cv::Mat& map_fixed() const { return map_fixed_; }
  const cv::Mat& map_frac() const { return map_frac_; }

 private:
  void BuildMaps();

  Camera camera_;
  Rigid3 cam_from_rig_;
  HybridLayout layout_;
  HybridProjectionOptions options_;
  // Virtual frame in the camera frame.
  Eigen::Matrix3d rig_from_cam_rotation_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d up_, forward_, right_;          // right = forward x up
  Eigen::Vector3d normal_left_, normal_right_;    // plane normals m_L, m_R
  Eigen::Vector3d tangent_left_, tangent_right_;  // in-plane horizontal axes (m x up)
  double psi_left_ = 0, psi_right_ = 0;
  double focal_ = 0, cx_ = 0, cy_ = 0;
  int width_ = 0, height_ = 0;
  cv::Mat map_x_, map_y_;         // CV_32FC1
  cv::Mat map_fixed_, map_frac_;  // CV_16SC2 + CV_16UC1 (cv::convertMaps)
  cv::Mat valid_mask_;
};

}  // namespace rovo
