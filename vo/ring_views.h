#pragma once
// The ring calibration's overlap views (ring_calibration.h, step 1 and 2): each neighbouring pair's
// images resampled onto one longitude/latitude grid around its overlap, ORB matches between the two
// views, and the matches' bearings pooled per pair. Internal to the ring calibration.

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opengv/types.hpp>
#include <vector>

#include "datasets/rig.h"
#include "vo/ring_calibration.h"

namespace rovo::ring {

inline constexpr double kDeg = M_PI / 180.0;

// The longitude/latitude grid around a pair's overlap: view frame x = m (horizontal), z = rig up.
struct ViewGeometry {
  Eigen::Matrix3d rig_from_view = Eigen::Matrix3d::Identity();
  double focal = 1.0;  // pixels per radian
  int width = 0, height = 0;
  double Longitude(double u) const { return -(u - 0.5 * (width - 1)) / focal; }
  double Latitude(double v) const { return -(v - 0.5 * (height - 1)) / focal; }
  Eigen::Vector3d DirectionInRig(double u, double v) const {
    const double lon = Longitude(u), lat = Latitude(v);
    return rig_from_view * Eigen::Vector3d(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
  }
};

ViewGeometry MakeViewGeometry(const Rig& rig, int a, int b, const RingCalibrationOptions& options);

// One camera's resampling into a pair's view, its validity mask and the bearing of every view pixel.
struct ViewSide {
  int camera = 0;
  cv::Mat map_x, map_y;  // CV_32F; -1 outside the lens
  cv::Mat valid;         // CV_8U, 255 where the view pixel comes from the lens (and the static mask)
  Eigen::Matrix3d cam_from_rig_nominal = Eigen::Matrix3d::Identity();
};

// Camera `camera`'s side of the view `g`; `static_mask` empty or 8-bit of the image size (0 = invalid).
ViewSide MakeViewSide(const RigCamera& cam, int camera, const ViewGeometry& g, const cv::Mat& static_mask);

// A ring pair: its view grid, both cameras' sides, the views of the last frame and the pooled matches.
struct OverlapPair {
  int a = 0, b = 0;
  ViewGeometry geometry;
  ViewSide side[2];
  cv::Mat last_view[2];
  opengv::bearingVectors_t bearings_a, bearings_b;  // pooled matches, in each camera's frame
};

// The overlap of ring pair (a, b): its view grid and both sides. `static_masks`: empty or one per camera.
OverlapPair MakeOverlapPair(const Rig& rig, int a, int b, const std::vector<cv::Mat>& static_masks,
                            const RingCalibrationOptions& options);

// `image` as 8-bit gray (8-bit gray, BGR or BGRA in).
cv::Mat Gray(const cv::Mat& image);

// One frame's overlap matches of pair `p` (`gray`: the frame's images, one per camera), pooled into
// its bearings after the ratio, mutual and prior checks; the views are kept as p->last_view.
void MatchOverlap(const std::vector<cv::Mat>& gray, cv::ORB& orb, const RingCalibrationOptions& o, OverlapPair* p);

}  // namespace rovo::ring
