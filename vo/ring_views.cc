#include "vo/ring_views.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>
#include <string>

#include "vo/orb_matching.h"

namespace rovo::ring {
namespace {

// Pixels per radian of a lens at 90 deg off its axis (where ring overlaps lie), measured along the
// image x axis: the overlap views sample at this density.
double PixelsPerRadianAt90(const Camera& camera) {
  auto pixel_at = [&](double theta_deg) {
    const double t = theta_deg * kDeg;
    return camera.Project(Eigen::Vector3d(std::sin(t), 0.0, std::cos(t)));
  };
  const auto a = pixel_at(80.0), b = pixel_at(100.0);
  if (!a || !b) throw std::invalid_argument("ring calibration: the lens does not reach 100 deg off its axis");
  return (*b - *a).norm() / (20.0 * kDeg);
}

// Local contrast normalisation for KLT: (v - mean) / std over a Gaussian window of `sigma_px`,
// mapped to 8 bits. Two cameras of a real rig see a surface with different exposure, gain and
// vignetting, which biases KLT's brightness-constancy fit; ORB's descriptors are invariant to both.
cv::Mat ContrastNormalized(const cv::Mat& view, double sigma_px) {
  cv::Mat f, mean, var;
  view.convertTo(f, CV_32F);
  cv::GaussianBlur(f, mean, cv::Size(0, 0), sigma_px);
  const cv::Mat centred = f - mean;
  cv::GaussianBlur(centred.mul(centred), var, cv::Size(0, 0), sigma_px);
  cv::sqrt(var, var);
  const cv::Mat z = centred / (var + 2.0f);
  cv::Mat out;
  z.convertTo(out, CV_8U, 40.0, 128.0);
  return out;
}

// Sub-pixel positions in view b of matches found by descriptors: pyramidal KLT from each point of
// view a, started at its ORB match, kept when tracking back lands within 0.3 px of the start and the
// refined point stays within 3 px of the ORB one (on ContrastNormalized views when `normalize_sigma_px`
// > 0). KLT's translation model holds only when the two views are aligned (a second ring pass, whose
// views are placed by the first pass's result).
void RefineMatchesKlt(const cv::Mat& view_a_in, const cv::Mat& view_b_in, double normalize_sigma_px,
                      std::vector<cv::Point2f>* points_a, std::vector<cv::Point2f>* points_b) {
  if (points_a->empty()) return;
  const bool normalize = normalize_sigma_px > 0.0;
  const cv::Mat view_a = normalize ? ContrastNormalized(view_a_in, normalize_sigma_px) : view_a_in;
  const cv::Mat view_b = normalize ? ContrastNormalized(view_b_in, normalize_sigma_px) : view_b_in;
  std::vector<cv::Point2f> forward = *points_b, backward = *points_a;
  std::vector<uint8_t> status_fw, status_bw;
  std::vector<float> error;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  cv::calcOpticalFlowPyrLK(view_a, view_b, *points_a, forward, status_fw, error, cv::Size(15, 15), 2, criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  cv::calcOpticalFlowPyrLK(view_b, view_a, forward, backward, status_bw, error, cv::Size(15, 15), 2, criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point2f> kept_a, kept_b;
  for (size_t k = 0; k < points_a->size(); ++k) {
    if (!status_fw[k] || !status_bw[k]) continue;
    if (cv::norm(backward[k] - (*points_a)[k]) > 0.3 || cv::norm(forward[k] - (*points_b)[k]) > 3.0) continue;
    kept_a.push_back((*points_a)[k]);
    kept_b.push_back(forward[k]);
  }
  points_a->swap(kept_a);
  points_b->swap(kept_b);
}

}  // namespace

ViewGeometry MakeViewGeometry(const Rig& rig, int a, int b, const RingCalibrationOptions& options) {
  Eigen::Vector3d m = CameraAxisInRig(rig.cameras[a].cam_from_rig) + CameraAxisInRig(rig.cameras[b].cam_from_rig);
  m.z() = 0.0;
  if (m.norm() < 1e-6)
    throw std::invalid_argument("ring calibration: cameras " + std::to_string(a) + " and " + std::to_string(b) +
                                " face opposite ways (no overlap direction)");
  m.normalize();
  ViewGeometry g;
  g.rig_from_view.col(0) = m;
  g.rig_from_view.col(2) = Eigen::Vector3d::UnitZ();
  g.rig_from_view.col(1) = Eigen::Vector3d::UnitZ().cross(m);
  const double native =
      std::min(PixelsPerRadianAt90(rig.cameras[a].camera), PixelsPerRadianAt90(rig.cameras[b].camera));
  g.focal = std::max(options.min_view_focal_px, native);
  if (options.dense_view_focal_px > 0.0) {
    g.focal = std::max(g.focal, std::min(options.dense_view_focal_px, options.dense_view_max_upsampling * native));
  }
  g.width = static_cast<int>(std::lround(2.0 * options.view_half_width_deg * kDeg * g.focal));
  g.height = static_cast<int>(std::lround(2.0 * options.view_half_height_deg * kDeg * g.focal));
  return g;
}

ViewSide MakeViewSide(const RigCamera& cam, int camera, const ViewGeometry& g, const cv::Mat& static_mask) {
  ViewSide s;
  s.camera = camera;
  s.cam_from_rig_nominal = cam.cam_from_rig.RotationMatrix();
  s.map_x.create(g.height, g.width, CV_32F);
  s.map_y.create(g.height, g.width, CV_32F);
  s.valid = cv::Mat::zeros(g.height, g.width, CV_8U);
  // DirectionInRig with the sines and cosines of every column's longitude computed once.
  std::vector<double> cos_lon(g.width), sin_lon(g.width);
  for (int u = 0; u < g.width; ++u) {
    cos_lon[u] = std::cos(g.Longitude(u));
    sin_lon[u] = std::sin(g.Longitude(u));
  }
  const Eigen::Matrix3d cam_from_view = s.cam_from_rig_nominal * g.rig_from_view;
  for (int v = 0; v < g.height; ++v) {
    const double lat = g.Latitude(v), cos_lat = std::cos(lat), sin_lat = std::sin(lat);
    for (int u = 0; u < g.width; ++u) {
      const Eigen::Vector3d d_cam =
          cam_from_view * Eigen::Vector3d(cos_lat * cos_lon[u], cos_lat * sin_lon[u], sin_lat);
      const auto px = cam.camera.Project(d_cam);  // nullopt outside the field of view
      const bool inside = px && px->x() >= 1.0 && px->y() >= 1.0 && px->x() <= cam.camera.width - 2.0 &&
                          px->y() <= cam.camera.height - 2.0;
      s.map_x.at<float>(v, u) = inside ? static_cast<float>(px->x()) : -1.0f;
      s.map_y.at<float>(v, u) = inside ? static_cast<float>(px->y()) : -1.0f;
      if (!inside) continue;
      const bool masked_out =
          !static_mask.empty() &&
          static_mask.at<uint8_t>(static_cast<int>(std::lround(px->y())), static_cast<int>(std::lround(px->x()))) == 0;
      s.valid.at<uint8_t>(v, u) = masked_out ? 0 : 255;
    }
  }
  // Keep ORB's 31-px patches off the lens rim and the mask's edges.
  cv::erode(s.valid, s.valid, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(17, 17)));
  return s;
}

OverlapPair MakeOverlapPair(const Rig& rig, int a, int b, const std::vector<cv::Mat>& static_masks,
                            const RingCalibrationOptions& options) {
  OverlapPair p;
  p.a = a;
  p.b = b;
  p.geometry = MakeViewGeometry(rig, a, b, options);
  const int cams[2] = {a, b};
  for (int s = 0; s < 2; ++s) {
    const cv::Mat mask = static_masks.empty() ? cv::Mat() : static_masks[cams[s]];
    p.side[s] = MakeViewSide(rig.cameras[cams[s]], cams[s], p.geometry, mask);
  }
  return p;
}

cv::Mat Gray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return gray;
}

void MatchOverlap(const std::vector<cv::Mat>& gray, cv::ORB& orb, const RingCalibrationOptions& o, OverlapPair* p) {
  std::vector<cv::KeyPoint> keypoints[2];
  cv::Mat descriptors[2];
  for (int s = 0; s < 2; ++s) {
    cv::remap(gray[p->side[s].camera], p->last_view[s], p->side[s].map_x, p->side[s].map_y, cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, 0);
    orb.detectAndCompute(p->last_view[s], p->side[s].valid, keypoints[s], descriptors[s]);
  }
  const double max_prior = std::cos(o.max_prior_angle_deg * kDeg);
  std::vector<cv::Point2f> points_a, points_b;
  for (const auto& [i, j] :
       MutualRatioOrbMatches(descriptors[0], descriptors[1], o.max_ratio, o.max_descriptor_distance)) {
    points_a.push_back(keypoints[0][i].pt);
    points_b.push_back(keypoints[1][j].pt);
  }
  if (o.refine_matches)
    RefineMatchesKlt(p->last_view[0], p->last_view[1], o.klt_normalize_sigma_px, &points_a, &points_b);
  for (size_t k = 0; k < points_a.size(); ++k) {
    const Eigen::Vector3d d_a = p->geometry.DirectionInRig(points_a[k].x, points_a[k].y);
    const Eigen::Vector3d d_b = p->geometry.DirectionInRig(points_b[k].x, points_b[k].y);
    if (d_a.dot(d_b) < max_prior) continue;
    p->bearings_a.push_back((p->side[0].cam_from_rig_nominal * d_a).normalized());
    p->bearings_b.push_back((p->side[1].cam_from_rig_nominal * d_b).normalized());
  }
}

}  // namespace rovo::ring

namespace rovo {

std::vector<std::pair<int, int>> RingPairs(const Rig& rig) {
  const int n = rig.NumCameras();
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int i, int j) {
    return CameraYawDeg(rig.cameras[i].cam_from_rig) < CameraYawDeg(rig.cameras[j].cam_from_rig);
  });
  std::vector<std::pair<int, int>> pairs;
  const int count = n >= 3 ? n : n - 1;
  for (int k = 0; k < count; ++k) {
    const int a = order[k], b = order[(k + 1) % n];
    const double apart =
        AngleBetween(CameraAxisInRig(rig.cameras[a].cam_from_rig), CameraAxisInRig(rig.cameras[b].cam_from_rig)) /
        ring::kDeg;
    const double reach = 0.5 * (rig.cameras[a].camera.max_fov_deg + rig.cameras[b].camera.max_fov_deg);
    if (apart < reach - 10.0) pairs.emplace_back(std::min(a, b), std::max(a, b));
  }
  return pairs;
}

}  // namespace rovo
