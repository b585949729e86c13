#pragma once
// Inter-view feature matching between neighbouring views in their overlap (ROVO paper IV-B).
//
// For a pair of views (a, b) sharing the projection-plane normal m (both cameras' planes over this
// overlap are parallel to the baseline, hybrid_projection.h), a candidate pair of features passes
// when, with d_a, d_b the bearings rotated into the rig frame, c_a, c_b the camera centres, up the
// rig-plane normal and f the warped focal length:
//   1. y-distance:   f |y(d_a) - y(d_b)| <= max_y_distance_px, y(d) = -(d . up) / (d . m)
//                    (the rectified-like warped y; needs d . m > 0 for both),
//   2. descriptor:   Hamming(desc_a, desc_b) <= max_descriptor_distance,
//   3. orientation:  |angle_a - angle_b| (mod 360) <= max_orientation_diff_deg,
//   4. epipolar:     max(angle of d_b to the plane span(c_b - c_a, d_a), same for d_a) <= max_epipolar_angle_deg,
//   5. positive disparity: the rays c_a + la d_a and c_b + lb d_b converge with la > 0 and lb > 0
//                    (closest points; parallel rays fail),
// then the two nearest admissible candidates by descriptor distance (kNN, k = 2) are kept per feature
// in both directions, and the nearest one is accepted when
//   ratio:           best <= max_ratio * second best (when there is a second),
//   6. left-right:   a's best is b and b's best is a (mutual),
//   7. ZNCC:         zero-normalised cross-correlation of the square patches around both points in
//                    the warped images >= min_zncc,
//   8. uniqueness along the epipolar curve (repeated structure: identical windows of a facade lie
//                    on one epipolar line, and the true partner may not be among b's features):
//                    b's bearing is rotated within the plane n = (c_b - c_a) x d_b (the epipolar
//                    plane when the extrinsics are right; through the match itself when loosened
//                    filters accept a match off the assumed epipolar plane) by
//                    +-uniqueness_range_deg in steps of one warped pixel (1 / f rad), each
//                    direction with positive disparity is mapped into b's image, and a's patch is
//                    correlated there (ZNCC, nearest-pixel patches). The match is rejected when a
//                    local ZNCC maximum more than uniqueness_exclusion_px from the match (refined
//                    over its 3x3 pixels) reaches z0 - uniqueness_margin, z0 = the best ZNCC within
//                    that exclusion radius and the 3x3 pixels of the match. The same scan runs in the
//                    other direction (b's patch along a's curve). Needs pixel_from_direction_in_rig.

#include <Eigen/Core>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "datasets/rigid3.h"
#include "vo/tracking.h"

namespace rovo {

struct InterviewMatchOptions {
  double max_y_distance_px = 6.0;
  int max_descriptor_distance = 64;
  double max_orientation_diff_deg = 30.0;
  double max_epipolar_angle_deg = 0.5;
  double min_zncc = 0.7;
  int zncc_patch_px = 11;                // odd side of the ZNCC patch
  double max_ratio = 0.9;                // best / second-best descriptor distance (1 = off)
  double uniqueness_range_deg = 20.0;    // filter 8: scan half-range along the epipolar curve
  double uniqueness_margin = 0.02;       // filter 8: rival peak must stay below z0 - margin
  double uniqueness_exclusion_px = 4.0;  // filter 8: peaks this close to the match are the match
  bool use_zncc = true;                  // ablation switches (the projection study turns filters off)
  bool use_uniqueness = true;            // filter 8 (needs use_zncc and pixel_from_direction_in_rig)
  bool use_y_distance = true;
  bool use_mutual = true;
  bool use_positive_disparity = true;
  void Check() const;  // throws std::invalid_argument naming the field
};

// One view's features for matching.
struct MatchView {
  const std::vector<TrackedPoint>* points = nullptr;
  std::vector<Eigen::Vector3d> bearings_in_rig;  // rotation only (rig_from_cam rotation * bearing_in_cam)
  Eigen::Vector3d centre_in_rig = Eigen::Vector3d::Zero();
  const cv::Mat* image = nullptr;  // 8-bit gray image the points live in (for ZNCC)
  // Pixel in `image` of a direction given in the rig frame (rotation only); nullopt when it falls
  // outside the view. Empty: no uniqueness scan (filter 8) into this view.
  std::function<std::optional<Eigen::Vector2d>(const Eigen::Vector3d&)> pixel_from_direction_in_rig;
};

struct PairGeometry {
  Eigen::Vector3d up_in_rig = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d plane_normal_in_rig = Eigen::Vector3d::UnitX();  // shared plane normal m
  double focal_px = 400.0;
};

struct InterviewMatch {
  int index_a = -1, index_b = -1;
  int descriptor_distance = 0;
  double zncc = 0.0;
};

// Angle (radians) of `bearing_b` to the epipolar plane through the baseline and `bearing_a`, and
// vice versa; returns the larger. All in one frame. Returns pi/2 when a bearing is parallel to the
// baseline (no plane).
double EpipolarAngle(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& centre_b,
                     const Eigen::Vector3d& bearing_b);

// Ray parameters (la, lb) of the closest points of c_a + la d_a and c_b + lb d_b (unit bearings);
// nullopt for (nearly) parallel rays.
std::optional<Eigen::Vector2d> ClosestRayParameters(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& bearing_a,
                                                    const Eigen::Vector3d& centre_b, const Eigen::Vector3d& bearing_b);
bool PositiveDisparity(const Eigen::Vector3d& centre_a, const Eigen::Vector3d& bearing_a,
                       const Eigen::Vector3d& centre_b, const Eigen::Vector3d& bearing_b);

// Rectified-like y of a direction for a plane normal m: -(d . up) / (d . m); nullopt when d . m <= 0.
std::optional<double> RectifiedY(const Eigen::Vector3d& bearing, const Eigen::Vector3d& up, const Eigen::Vector3d& m);

// ZNCC of the patch_px x patch_px patches (bilinear) around a and b; nullopt when a patch leaves its
// image or is flat.
std::optional<double> Zncc(const cv::Mat& image_a, cv::Point2f a, const cv::Mat& image_b, cv::Point2f b, int patch_px);
// The same at whole pixels (odd patch_px <= 45, 8-bit images), the patch around a against the
// patches around each of b, in exact integer sums: the form filter 8's scan evaluates (SIMD rows for
// patches up to 16 px). Equals Zncc at those pixels up to rounding.
std::vector<std::optional<double>> ZnccAtPixels(const cv::Mat& image_a, cv::Point a, const cv::Mat& image_b,
                                                const std::vector<cv::Point>& b, int patch_px);

// Filter 8 for one direction: scans `patch_of` (a square patch of `patch_image` around
// `patch_centre`) along the epipolar curve of (centre_fixed, bearing_fixed) in `view`, around the
// matched bearing `bearing_moving` (view's camera centre `centre_moving`). Returns true when no
// rival peak reaches z0 - margin (see the header comment); false also when z0 cannot be measured.
bool UniqueAlongEpipolarCurve(const cv::Mat& patch_image, cv::Point2f patch_centre, const Eigen::Vector3d& centre_fixed,
                              const Eigen::Vector3d& bearing_fixed, const MatchView& view,
                              const Eigen::Vector3d& centre_moving, const Eigen::Vector3d& bearing_moving,
                              double focal_px, const InterviewMatchOptions& options);

// Smallest difference of two angles in degrees, in [0, 180].
double AngleDifferenceDeg(double a_deg, double b_deg);

std::vector<InterviewMatch> MatchViews(const PairGeometry& pair, const MatchView& a, const MatchView& b,
                                       const InterviewMatchOptions& options);

// Sub-pixel refinement of matched positions (our addition to the paper's matcher). A new feature
// sits where FAST found it, on the integer pixel grid, so a match of two fresh detections carries up
// to +-0.5 px of quantisation in each view. The front-end moves the fresh side of a new match to
// where KLT (translation only, from the other view's patch, starting at the detection) lands: for
// each k, `to[k]` in image_to is refined against the patch of image_from around `from[k]`. A result
// is kept when KLT converges within max_shift_px of the start and tracking it back lands within
// max_round_trip_px of from[k]; nullopt otherwise, also near an image border (the caller keeps the
// detection). 8-bit gray images, of any sizes.
struct SubpixelMatchOptions {
  int window_px = 15;  // KLT window side
  int max_iterations = 30;
  double epsilon_px = 0.01;
  double max_shift_px = 2.0;
  double max_round_trip_px = 0.3;
  void Check() const;  // throws std::invalid_argument naming the field
};
std::vector<std::optional<cv::Point2f>> RefineMatchPositions(const cv::Mat& image_from, const cv::Mat& image_to,
                                                             const std::vector<cv::Point2f>& from,
                                                             const std::vector<cv::Point2f>& to,
                                                             const SubpixelMatchOptions& options = {});

}  // namespace rovo
