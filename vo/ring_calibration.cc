#include "vo/ring_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/relative_pose/RotationOnlySacProblem.hpp>
#include <stdexcept>

#include "vo/orb_matching.h"

namespace rovo {
namespace {

constexpr double kDeg = M_PI / 180.0;

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

// One camera's resampling into a pair's view, its validity mask and the bearing of every view pixel.
struct ViewSide {
  int camera = 0;
  cv::Mat map_x, map_y;  // CV_32F; -1 outside the lens
  cv::Mat valid;         // CV_8U, 255 where the view pixel comes from the lens (and the static mask)
  Eigen::Matrix3d cam_from_rig_nominal = Eigen::Matrix3d::Identity();
};

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

struct PairState {
  int a = 0, b = 0;
  ViewGeometry geometry;
  ViewSide side[2];
  cv::Mat last_view[2];
  opengv::bearingVectors_t bearings_a, bearings_b;  // pooled matches, in each camera's frame
};

cv::Mat Gray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return gray;
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

// Averages the pair rotations into cam_j_from_cam0 (see the header); `rotations[0]` stays fixed.
struct PairRotationError {
  explicit PairRotationError(const Eigen::Quaterniond& camb_from_cama) : measured_inverse(camb_from_cama.inverse()) {}
  template <typename T>
  bool operator()(const T* q_a, const T* q_b, T* residual) const {
    // Quaternions stored x, y, z, w (Eigen); R_b R_a^T R_ba^T as a quaternion, then its angle-axis.
    const Eigen::Quaternion<T> qa(q_a[3], q_a[0], q_a[1], q_a[2]);
    const Eigen::Quaternion<T> qb(q_b[3], q_b[0], q_b[1], q_b[2]);
    const Eigen::Quaternion<T> e = qb * qa.conjugate() * measured_inverse.cast<T>();
    const T wxyz[4] = {e.w(), e.x(), e.y(), e.z()};
    ceres::QuaternionToAngleAxis(wxyz, residual);
    return true;
  }
  Eigen::Quaterniond measured_inverse;
};

std::vector<Eigen::Quaterniond> AverageRing(const std::vector<RingPairEstimate>& pairs, int num_cams,
                                            std::vector<Eigen::Quaterniond> rotations) {
  ceres::Problem problem;
  for (auto& q : rotations) problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  problem.SetParameterBlockConstant(rotations[0].coeffs().data());
  for (const RingPairEstimate& p : pairs) {
    if (!p.usable) continue;
    auto* cost = new ceres::AutoDiffCostFunction<PairRotationError, 3, 4, 4>(new PairRotationError(p.camb_from_cama));
    problem.AddResidualBlock(cost,
                             new ceres::ScaledLoss(nullptr, static_cast<double>(p.inliers), ceres::TAKE_OWNERSHIP),
                             rotations[p.camera_a].coeffs().data(), rotations[p.camera_b].coeffs().data());
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  if (num_cams > 1) ceres::Solve(options, &problem, &summary);
  for (auto& q : rotations) q.normalize();
  return rotations;
}

}  // namespace

void RingCalibrationOptions::Check() const {
  if (!(view_half_width_deg > 0.0 && view_half_width_deg < 90.0) ||
      !(view_half_height_deg > 0.0 && view_half_height_deg < 90.0)) {
    throw std::invalid_argument("RingCalibrationOptions: view extents must be in (0, 90) deg");
  }
  if (!(max_ratio > 0.0 && max_ratio <= 1.0))
    throw std::invalid_argument("RingCalibrationOptions: max_ratio in (0, 1]");
  if (!(inlier_threshold_deg > 0.0) || ransac_iterations < 1 || min_inliers < 5 || orb_features < 10) {
    throw std::invalid_argument(
        "RingCalibrationOptions: threshold, iterations, min_inliers or orb_features out of range");
  }
}

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
        AngleBetween(CameraAxisInRig(rig.cameras[a].cam_from_rig), CameraAxisInRig(rig.cameras[b].cam_from_rig)) / kDeg;
    const double reach = 0.5 * (rig.cameras[a].camera.max_fov_deg + rig.cameras[b].camera.max_fov_deg);
    if (apart < reach - 10.0) pairs.emplace_back(std::min(a, b), std::max(a, b));
  }
  return pairs;
}

struct RingCalibrator::Impl {
  Rig rig;
  RingCalibrationOptions options;
  std::vector<PairState> pairs;
  int frames = 0;
};

RingCalibrator::RingCalibrator(const Rig& rig, const std::vector<cv::Mat>& static_masks,
                               const RingCalibrationOptions& options)
    : impl_(std::make_unique<Impl>()) {
  options.Check();
  if (!static_masks.empty() && static_cast<int>(static_masks.size()) != rig.NumCameras()) {
    throw std::invalid_argument("ring calibration: " + std::to_string(static_masks.size()) + " masks for " +
                                std::to_string(rig.NumCameras()) + " cameras");
  }
  impl_->rig = rig;
  impl_->options = options;
  for (const auto& [a, b] : RingPairs(rig)) {
    PairState p;
    p.a = a;
    p.b = b;
    p.geometry = MakeViewGeometry(rig, a, b, options);
    const int cams[2] = {a, b};
    for (int s = 0; s < 2; ++s) {
      const cv::Mat mask = static_masks.empty() ? cv::Mat() : static_masks[cams[s]];
      p.side[s] = MakeViewSide(rig.cameras[cams[s]], cams[s], p.geometry, mask);
    }
    impl_->pairs.push_back(std::move(p));
  }
}

RingCalibrator::~RingCalibrator() = default;

const cv::Mat& RingCalibrator::overlap_view(int pair_index, int side) const {
  return impl_->pairs.at(pair_index).last_view[side];
}

void RingCalibrator::AddFrame(const std::vector<cv::Mat>& images) {
  const Rig& rig = impl_->rig;
  const RingCalibrationOptions& o = impl_->options;
  if (static_cast<int>(images.size()) != rig.NumCameras()) {
    throw std::invalid_argument("ring calibration: " + std::to_string(images.size()) + " images for " +
                                std::to_string(rig.NumCameras()) + " cameras");
  }
  std::vector<cv::Mat> gray(images.size());
  for (size_t j = 0; j < images.size(); ++j) gray[j] = Gray(images[j]);
  auto orb = cv::ORB::create(o.orb_features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, o.orb_fast_threshold);
  for (PairState& p : impl_->pairs) {
    std::vector<cv::KeyPoint> keypoints[2];
    cv::Mat descriptors[2];
    for (int s = 0; s < 2; ++s) {
      cv::remap(gray[p.side[s].camera], p.last_view[s], p.side[s].map_x, p.side[s].map_y, cv::INTER_LINEAR,
                cv::BORDER_CONSTANT, 0);
      orb->detectAndCompute(p.last_view[s], p.side[s].valid, keypoints[s], descriptors[s]);
    }
    const double max_prior = std::cos(o.max_prior_angle_deg * kDeg);
    std::vector<cv::Point2f> points_a, points_b;
    for (const auto& [i, j] :
         MutualRatioOrbMatches(descriptors[0], descriptors[1], o.max_ratio, o.max_descriptor_distance)) {
      points_a.push_back(keypoints[0][i].pt);
      points_b.push_back(keypoints[1][j].pt);
    }
    if (o.refine_matches)
      RefineMatchesKlt(p.last_view[0], p.last_view[1], o.klt_normalize_sigma_px, &points_a, &points_b);
    for (size_t k = 0; k < points_a.size(); ++k) {
      const Eigen::Vector3d d_a = p.geometry.DirectionInRig(points_a[k].x, points_a[k].y);
      const Eigen::Vector3d d_b = p.geometry.DirectionInRig(points_b[k].x, points_b[k].y);
      if (d_a.dot(d_b) < max_prior) continue;
      p.bearings_a.push_back((p.side[0].cam_from_rig_nominal * d_a).normalized());
      p.bearings_b.push_back((p.side[1].cam_from_rig_nominal * d_b).normalized());
    }
  }
  ++impl_->frames;
}

namespace {

// Angle (sine) of b's bearing, rotated into a, to the epipolar plane through the baseline t_a and
// a's bearing, all in camera a's frame:  e = (b_a x t_a) . (R_ab b_b) / |b_a x t_a|.
struct FixedBaselineEpipolarError {
  FixedBaselineEpipolarError(const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& bearing_b,
                             const Eigen::Vector3d& baseline_in_a)
      : normal_in_a(bearing_a.cross(baseline_in_a).normalized()), bearing_b(bearing_b) {}
  template <typename T>
  bool operator()(const T* q_ab, T* residual) const {
    const Eigen::Quaternion<T> q(q_ab[3], q_ab[0], q_ab[1], q_ab[2]);
    residual[0] = normal_in_a.cast<T>().dot(q * bearing_b.cast<T>());
    return true;
  }
  Eigen::Vector3d normal_in_a, bearing_b;
};

// Whether the rays from camera a along `ray_a` and from camera b (at `baseline_in_a`, direction only)
// along `ray_b` (both in a's frame) meet in front of both cameras. Nearly parallel rays (a far
// point) pass: their depths are not determined.
bool InFrontOfBoth(const Eigen::Vector3d& ray_a, const Eigen::Vector3d& ray_b, const Eigen::Vector3d& baseline_in_a) {
  // depth_a ray_a - depth_b ray_b = baseline, in the least-squares sense.
  const double aa = ray_a.dot(ray_a), ab = ray_a.dot(ray_b), bb = ray_b.dot(ray_b);
  const double det = aa * bb - ab * ab;
  if (det < 1e-6) return true;  // rays within about 0.06 deg of each other
  const double ta = ray_a.dot(baseline_in_a), tb = ray_b.dot(baseline_in_a);
  const double depth_a = (bb * ta - ab * tb) / det;
  const double depth_b = (ab * ta - aa * tb) / det;
  return depth_a > 0.0 && depth_b > 0.0;
}

// R_ab minimising the robust epipolar residuals of the matches `used` for the baseline direction
// `baseline_in_a`, from `start`.
Eigen::Quaterniond RefineWithBaseline(const opengv::bearingVectors_t& bearings_a,
                                      const opengv::bearingVectors_t& bearings_b, const std::vector<int>& used,
                                      const Eigen::Vector3d& baseline_in_a, Eigen::Quaterniond start,
                                      double scale_rad) {
  ceres::Problem problem;
  problem.AddParameterBlock(start.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  for (int k : used) {
    if (bearings_a[k].cross(baseline_in_a).norm() < 1e-6) continue;  // bearing along the baseline: no plane
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FixedBaselineEpipolarError, 1, 4>(
                                 new FixedBaselineEpipolarError(bearings_a[k], bearings_b[k], baseline_in_a)),
                             new ceres::CauchyLoss(scale_rad), start.coeffs().data());
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return start.normalized();
}

// One pair's rotation from its pooled matches. The translation between the centres is known in the
// rig frame; in camera a's frame its direction is known up to a's own extrinsic error. A free
// translation (5-point relative pose) lets depth and baseline direction absorb rotation error along
// the epipolar lines: measured on quick cloudy_urban, 98 % inliers and pair rotations 3-9 deg off.
// So: a rotation-only RANSAC (OpenGV, Arun on 2 points) with a threshold wide enough for the parallax
// removes gross mismatches, then R_ab is refined on the epipolar residuals with the baseline direction
// held at its nominal value (Cauchy), and the inliers re-selected at the final threshold.
RingPairEstimate EstimatePair(const PairState& p, const Rig& rig, const RingCalibrationOptions& o,
                              std::vector<int>* inliers) {
  RingPairEstimate e;
  e.camera_a = p.a;
  e.camera_b = p.b;
  e.matches = static_cast<int>(p.bearings_a.size());
  if (e.matches < o.min_inliers) return e;
  using opengv::sac_problems::relative_pose::RotationOnlySacProblem;
  opengv::relative_pose::CentralRelativeAdapter adapter(p.bearings_a, p.bearings_b);
  opengv::sac::Ransac<RotationOnlySacProblem> ransac;
  ransac.sac_model_ = std::make_shared<RotationOnlySacProblem>(adapter, /*randomSeed=*/false);
  ransac.threshold_ = 1.0 - std::cos(o.max_parallax_deg * kDeg);
  ransac.max_iterations_ = o.ransac_iterations;
  if (!ransac.computeModel() || static_cast<int>(ransac.inliers_.size()) < o.min_inliers) return e;
  const std::vector<int>& ransac_inliers = ransac.inliers_;
  const Eigen::Matrix3d r12 = ransac.model_coefficients_;
  // OpenGV's R12 maps viewpoint 2 (b) into viewpoint 1 (a).
  Eigen::Quaterniond a_from_b(r12);
  const Rigid3& cam_a = rig.cameras[p.a].cam_from_rig;
  const Eigen::Vector3d baseline_in_a =
      (cam_a.rotation * (CameraPositionInRig(rig.cameras[p.b].cam_from_rig) - CameraPositionInRig(cam_a))).normalized();
  const double threshold = o.inlier_threshold_deg * kDeg;
  std::vector<int> used = ransac_inliers;
  for (int round = 0; round < 3; ++round) {
    a_from_b = RefineWithBaseline(p.bearings_a, p.bearings_b, used, baseline_in_a, a_from_b, threshold);
    std::vector<int> next;
    const int candidates = o.reselect_all ? e.matches : static_cast<int>(ransac_inliers.size());
    for (int c = 0; c < candidates; ++c) {
      const int k = o.reselect_all ? c : ransac_inliers[c];
      const FixedBaselineEpipolarError f(p.bearings_a[k], p.bearings_b[k], baseline_in_a);
      double r = 0.0;
      const double q[4] = {a_from_b.x(), a_from_b.y(), a_from_b.z(), a_from_b.w()};
      f(q, &r);
      if (std::abs(r) < threshold && InFrontOfBoth(p.bearings_a[k], a_from_b * p.bearings_b[k], baseline_in_a)) {
        next.push_back(k);
      }
    }
    used.swap(next);
    if (static_cast<int>(used.size()) < o.min_inliers) return e;
  }
  e.inliers = static_cast<int>(used.size());
  *inliers = used;
  e.camb_from_cama = a_from_b.inverse().normalized();
  const Eigen::Quaterniond nominal = rig.cameras[p.b].cam_from_rig.rotation * cam_a.rotation.inverse();
  e.change_deg = RotationDistanceDeg(e.camb_from_cama, nominal);
  e.usable = true;
  return e;
}

// A camera-frame bearing whose angle off the optical axis (+z) can be scaled by 1 + kappa: the lens
// model's error that the ring can see (a lens calibrated with angles too small near the rim). The
// angle and the length of the bearing's xy part are computed once.
struct OffAxisBearing {
  explicit OffAxisBearing(const Eigen::Vector3d& b)
      : bearing(b), r(std::hypot(b.x(), b.y())), theta(std::atan2(r, b.z())) {}
  template <typename T>
  Eigen::Matrix<T, 3, 1> Scaled(const T& kappa) const {
    if (r < 1e-12) return bearing.cast<T>();
    using std::cos;
    using std::sin;
    const T angle = T(theta) * (T(1.0) + kappa);
    const T s = sin(angle) / T(r);
    return Eigen::Matrix<T, 3, 1>(s * T(bearing.x()), s * T(bearing.y()), cos(angle));
  }
  Eigen::Vector3d bearing;
  double r, theta;
};

Eigen::Vector3d ScaledBearing(const Eigen::Vector3d& bearing, double kappa) {
  return kappa == 0.0 ? bearing : OffAxisBearing(bearing).Scaled<double>(kappa);
}

// The ring's epipolar residual with each baseline direction following its camera:
//   e = (b_a x t_a) . (R_a R_b^T b_b) / |b_a x t_a|,   t_a = R_a (c_b - c_a),   R_j = rotation of cam_j_from_rig.
template <typename T>
T RingEpipolarResidual(const T* q_a, const T* q_b, const Eigen::Matrix<T, 3, 1>& bearing_a,
                       const Eigen::Matrix<T, 3, 1>& bearing_b, const Eigen::Vector3d& baseline_in_rig) {
  const Eigen::Quaternion<T> qa(q_a[3], q_a[0], q_a[1], q_a[2]);
  const Eigen::Quaternion<T> qb(q_b[3], q_b[0], q_b[1], q_b[2]);
  const Eigen::Matrix<T, 3, 1> t_a = qa * baseline_in_rig.cast<T>();
  const Eigen::Matrix<T, 3, 1> n = bearing_a.cross(t_a);
  const Eigen::Matrix<T, 3, 1> r = qa * (qb.conjugate() * bearing_b);
  return n.dot(r) / (n.norm() + T(1e-12));
}

// RingEpipolarResidual with the lenses as given.
struct RingEpipolarError {
  RingEpipolarError(const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& bearing_b,
                    const Eigen::Vector3d& baseline_in_rig)
      : bearing_a(bearing_a), bearing_b(bearing_b), baseline_in_rig(baseline_in_rig) {}
  template <typename T>
  bool operator()(const T* q_a, const T* q_b, T* residual) const {
    residual[0] = RingEpipolarResidual<T>(q_a, q_b, bearing_a.cast<T>(), bearing_b.cast<T>(), baseline_in_rig);
    return true;
  }
  Eigen::Vector3d bearing_a, bearing_b, baseline_in_rig;
};

// RingEpipolarResidual with both bearings' off-axis angles scaled by 1 + kappa (a parameter).
struct ScaledRingEpipolarError {
  ScaledRingEpipolarError(const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& bearing_b,
                          const Eigen::Vector3d& baseline_in_rig)
      : bearing_a(bearing_a), bearing_b(bearing_b), baseline_in_rig(baseline_in_rig) {}
  template <typename T>
  bool operator()(const T* q_a, const T* q_b, const T* kappa, T* residual) const {
    residual[0] =
        RingEpipolarResidual<T>(q_a, q_b, bearing_a.Scaled(kappa[0]), bearing_b.Scaled(kappa[0]), baseline_in_rig);
    return true;
  }
  OffAxisBearing bearing_a, bearing_b;
  Eigen::Vector3d baseline_in_rig;
};

// kappa near 0 (a weak prior of standard deviation `sigma`, as strong as ten matches at the Cauchy
// scale `scale_rad` for an error of sigma).
struct AngleScalePrior {
  explicit AngleScalePrior(double weight) : weight(weight) {}
  template <typename T>
  bool operator()(const T* kappa, T* residual) const {
    residual[0] = T(weight) * kappa[0];
    return true;
  }
  double weight;
};

// Camera 0's rotation stays near its given value (a weak prior: the common rotation of the cameras
// against their centres is seen only through the parallax of near points).
struct RotationPrior {
  RotationPrior(const Eigen::Quaterniond& prior, double weight) : prior_inverse(prior.inverse()), weight(weight) {}
  template <typename T>
  bool operator()(const T* q, T* residual) const {
    const Eigen::Quaternion<T> e = Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]) * prior_inverse.cast<T>();
    const T wxyz[4] = {e.w(), e.x(), e.y(), e.z()};
    ceres::QuaternionToAngleAxis(wxyz, residual);
    for (int k = 0; k < 3; ++k) residual[k] *= T(weight);
    return true;
  }
  Eigen::Quaterniond prior_inverse;
  double weight;
};

// The joint unknowns: every camera's rotation and the lenses' common angle scale.
struct RingModel {
  std::vector<Eigen::Quaterniond> rotations;  // cam_j_from_rig
  double kappa = 0.0;                         // off-axis angles scaled by 1 + kappa
};

Eigen::Vector3d PairBaselineInRig(const PairState& p, const Rig& rig) {
  return CameraPositionInRig(rig.cameras[p.b].cam_from_rig) - CameraPositionInRig(rig.cameras[p.a].cam_from_rig);
}

// |RingEpipolarResidual| of bearings `b_a`, `b_b` (already scaled) of pair `p` under `model`.
double RingResidual(const PairState& p, const Eigen::Vector3d& b_a, const Eigen::Vector3d& b_b,
                    const Eigen::Vector3d& baseline_in_rig, const RingModel& model) {
  return std::abs(RingEpipolarResidual<double>(model.rotations[p.a].coeffs().data(),
                                               model.rotations[p.b].coeffs().data(), b_a, b_b, baseline_in_rig));
}

// |RingEpipolarResidual| of match `i` of pair `p` under `model`.
double RingResidual(const PairState& p, int i, const Eigen::Vector3d& baseline_in_rig, const RingModel& model) {
  return RingResidual(p, ScaledBearing(p.bearings_a[i], model.kappa), ScaledBearing(p.bearings_b[i], model.kappa),
                      baseline_in_rig, model);
}

// The ring's epipolar residuals of the `inliers` (per pair) as blocks of `problem` on `model`'s
// rotations, and on its angle scale when that is free or not 0 (Cauchy at `scale_rad`; plain least
// squares when scale_rad <= 0). `residuals`, when given, receives their |values| at `model`.
void AddRingResiduals(const std::vector<PairState>& pairs, const std::vector<std::vector<int>>& inliers, const Rig& rig,
                      double scale_rad, bool scale_free, RingModel* model, ceres::Problem* problem,
                      std::vector<double>* residuals = nullptr) {
  const bool scaled = scale_free || model->kappa != 0.0;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const PairState& p = pairs[k];
    const Eigen::Vector3d baseline = PairBaselineInRig(p, rig);
    double* q_a = model->rotations[p.a].coeffs().data();
    double* q_b = model->rotations[p.b].coeffs().data();
    for (int i : inliers[k]) {
      if (residuals) residuals->push_back(RingResidual(p, i, baseline, *model));
      ceres::LossFunction* loss = scale_rad > 0.0 ? new ceres::CauchyLoss(scale_rad) : nullptr;
      if (scaled) {
        problem->AddResidualBlock(new ceres::AutoDiffCostFunction<ScaledRingEpipolarError, 1, 4, 4, 1>(
                                      new ScaledRingEpipolarError(p.bearings_a[i], p.bearings_b[i], baseline)),
                                  loss, q_a, q_b, &model->kappa);
      } else {
        problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RingEpipolarError, 1, 4, 4>(
                                      new RingEpipolarError(p.bearings_a[i], p.bearings_b[i], baseline)),
                                  loss, q_a, q_b);
      }
    }
  }
  if (scaled && !scale_free) problem->SetParameterBlockConstant(&model->kappa);
}

// Refines every cam_j_from_rig rotation on all pairs' inlier matches at once (RingEpipolarError,
// Cauchy at `scale_rad`), camera 0 held near its start by RotationPrior; the angle scale too when
// `angle_scale_sigma` > 0 (AngleScalePrior), else it stays at its start.
RingModel RefineRing(const std::vector<PairState>& pairs, const std::vector<std::vector<int>>& inliers, const Rig& rig,
                     RingModel model, double scale_rad, double prior_sigma_deg, double angle_scale_sigma) {
  ceres::Problem problem;
  for (auto& q : model.rotations) problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  AddRingResiduals(pairs, inliers, rig, scale_rad, angle_scale_sigma > 0.0, &model, &problem);
  // Priors as strong as ten matches at the Cauchy scale for an error of one sigma.
  const double weight = std::sqrt(10.0) * scale_rad / (prior_sigma_deg * kDeg);
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<RotationPrior, 3, 4>(new RotationPrior(model.rotations[0], weight)), nullptr,
      model.rotations[0].coeffs().data());
  if (angle_scale_sigma > 0.0) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<AngleScalePrior, 1, 1>(
                                 new AngleScalePrior(std::sqrt(10.0) * scale_rad / angle_scale_sigma)),
                             nullptr, &model.kappa);
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 100;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (auto& q : model.rotations) q.normalize();
  return model;
}

// One-sigma uncertainty (degrees) of the worst-determined camera's rotation relative to camera 0 at
// the joint solution: the covariance of the epipolar least-squares problem on the inliers with
// camera 0 held (and the angle scale free when it is estimated), scaled by the residuals' robust
// variance, largest eigenvalue over cameras 1..N-1. A near-field overlap leaves the rotation about
// the epipolar planes' normal (roughly the yaw of a pair) nearly free, because depth absorbs it:
// this is where that shows. -1: not computable.
// camera_zero_free: every camera free, and the result is camera 0's one sigma alone (how well the
// matches, without the prior, know the cameras' common turn against their centres).
double RingUncertaintyDeg(const std::vector<PairState>& pairs, const std::vector<std::vector<int>>& inliers,
                          const Rig& rig, RingModel model, bool angle_scale_free, bool camera_zero_free = false) {
  ceres::Problem problem;
  for (auto& q : model.rotations) problem.AddParameterBlock(q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  if (!camera_zero_free) problem.SetParameterBlockConstant(model.rotations[0].coeffs().data());
  std::vector<double> residuals;
  AddRingResiduals(pairs, inliers, rig, 0.0, angle_scale_free, &model, &problem, &residuals);
  if (residuals.size() < 10) return -1.0;
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  const double sigma = 1.4826 * residuals[residuals.size() / 2];
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.null_space_rank = -1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  const size_t first = camera_zero_free ? 0 : 1, end = camera_zero_free ? 1 : model.rotations.size();
  for (size_t j = first; j < end; ++j) {
    blocks.emplace_back(model.rotations[j].coeffs().data(), model.rotations[j].coeffs().data());
  }
  if (!covariance.Compute(blocks, &problem)) return -1.0;
  double worst = 0.0;
  for (size_t j = first; j < end; ++j) {
    Eigen::Matrix3d c;
    covariance.GetCovarianceMatrixInTangentSpace({model.rotations[j].coeffs().data()}, c.data());
    const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(c).eigenvalues().maxCoeff();
    // Ceres' quaternion tangent is half the rotation vector.
    worst = std::max(worst, 2.0 * std::sqrt(std::max(0.0, largest)) * sigma / kDeg);
  }
  return worst;
}

// RingEpipolarResidual of `model`'s cameras all turned by one rig-frame rotation (the parameter).
struct CommonRotationError {
  CommonRotationError(const Eigen::Quaterniond& cam_a_from_rig, const Eigen::Quaterniond& cam_b_from_rig,
                      const Eigen::Vector3d& bearing_a, const Eigen::Vector3d& bearing_b,
                      const Eigen::Vector3d& baseline_in_rig)
      : qa(cam_a_from_rig),
        qb(cam_b_from_rig),
        bearing_a(bearing_a),
        bearing_b(bearing_b),
        baseline_in_rig(baseline_in_rig) {}
  template <typename T>
  bool operator()(const T* q_turn, T* residual) const {
    const Eigen::Quaternion<T> turn(q_turn[3], q_turn[0], q_turn[1], q_turn[2]);
    const Eigen::Quaternion<T> a = qa.cast<T>() * turn, b = qb.cast<T>() * turn;
    residual[0] = RingEpipolarResidual<T>(a.coeffs().data(), b.coeffs().data(), bearing_a.cast<T>(),
                                          bearing_b.cast<T>(), baseline_in_rig);
    return true;
  }
  Eigen::Quaterniond qa, qb;
  Eigen::Vector3d bearing_a, bearing_b, baseline_in_rig;
};

// `model` with every camera turned by the rig-frame rotation that best explains all the pairs'
// matches (Cauchy at `scale_rad`): the relative rotations and the angle scale stay.
RingModel FitCommonRotation(const std::vector<PairState>& pairs, const Rig& rig, RingModel model, double scale_rad) {
  Eigen::Quaterniond turn = Eigen::Quaterniond::Identity();
  ceres::Problem problem;
  problem.AddParameterBlock(turn.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  int residuals = 0;
  for (const PairState& p : pairs) {
    const Eigen::Vector3d baseline = PairBaselineInRig(p, rig);
    for (size_t i = 0; i < p.bearings_a.size(); ++i) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<CommonRotationError, 1, 4>(new CommonRotationError(
              model.rotations[p.a], model.rotations[p.b], ScaledBearing(p.bearings_a[i], model.kappa),
              ScaledBearing(p.bearings_b[i], model.kappa), baseline)),
          new ceres::CauchyLoss(scale_rad), turn.coeffs().data());
      ++residuals;
    }
  }
  if (residuals < 3) return model;
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (auto& q : model.rotations) q = (q * turn).normalized();
  return model;
}

// Per pair, the indices of the matches that the joint model explains: epipolar residual
// (RingEpipolarError) below `threshold_rad` and the rays meeting in front of both cameras.
std::vector<std::vector<int>> ReselectInliers(const std::vector<PairState>& pairs, const Rig& rig,
                                              const RingModel& model, double threshold_rad) {
  std::vector<std::vector<int>> out(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    const PairState& p = pairs[k];
    const Eigen::Quaterniond& qa = model.rotations[p.a];
    const Eigen::Quaterniond a_from_b = qa * model.rotations[p.b].conjugate();
    const Eigen::Vector3d baseline_in_rig = PairBaselineInRig(p, rig);
    const Eigen::Vector3d baseline_in_a = (qa * baseline_in_rig).normalized();
    for (size_t i = 0; i < p.bearings_a.size(); ++i) {
      const Eigen::Vector3d b_a = ScaledBearing(p.bearings_a[i], model.kappa);
      const Eigen::Vector3d b_b = ScaledBearing(p.bearings_b[i], model.kappa);
      if (RingResidual(p, b_a, b_b, baseline_in_rig, model) < threshold_rad &&
          InFrontOfBoth(b_a, a_from_b * b_b, baseline_in_a)) {
        out[k].push_back(static_cast<int>(i));
      }
    }
  }
  return out;
}

// Median |RingEpipolarError| over `indices` of pair `p` under `model`, degrees.
double MedianResidualDeg(const PairState& p, const std::vector<int>& indices, const Rig& rig, const RingModel& model) {
  if (indices.empty()) return -1.0;
  const Eigen::Vector3d baseline_in_rig = PairBaselineInRig(p, rig);
  std::vector<double> residuals;
  for (int i : indices) residuals.push_back(RingResidual(p, i, baseline_in_rig, model));
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  return std::asin(std::min(1.0, residuals[residuals.size() / 2])) / kDeg;
}

// Angle between the joint rotation of a pair and the pair's own rotation refined on its inliers alone
// with the joint baseline direction and angle scale: how far the pair's matches pull away from the
// ring solution.
double PairDisagreementDeg(const PairState& p, const std::vector<int>& inliers, const Rig& rig, const RingModel& model,
                           double scale_rad) {
  const Eigen::Quaterniond& qa = model.rotations[p.a];
  const Eigen::Quaterniond joint_a_from_b = qa * model.rotations[p.b].conjugate();
  const Eigen::Vector3d baseline_in_a = (qa * PairBaselineInRig(p, rig)).normalized();
  opengv::bearingVectors_t scaled_a(p.bearings_a.size()), scaled_b(p.bearings_b.size());
  for (int i : inliers) {
    scaled_a[i] = ScaledBearing(p.bearings_a[i], model.kappa);
    scaled_b[i] = ScaledBearing(p.bearings_b[i], model.kappa);
  }
  const Eigen::Quaterniond own =
      RefineWithBaseline(scaled_a, scaled_b, inliers, baseline_in_a, joint_a_from_b, scale_rad);
  return RotationDistanceDeg(own, joint_a_from_b);
}

// cam_j_from_cam0 rotations by chaining usable pairs outward from camera 0 (breadth first); false
// when some camera is not reached.
bool ChainFromCameraZero(const std::vector<RingPairEstimate>& pairs, int num_cams,
                         std::vector<Eigen::Quaterniond>* rotations) {
  std::vector<bool> known(num_cams, false);
  rotations->assign(num_cams, Eigen::Quaterniond::Identity());
  known[0] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (const RingPairEstimate& p : pairs) {
      if (!p.usable || known[p.camera_a] == known[p.camera_b]) continue;
      if (known[p.camera_a]) {
        (*rotations)[p.camera_b] = p.camb_from_cama * (*rotations)[p.camera_a];
        known[p.camera_b] = true;
      } else {
        (*rotations)[p.camera_a] = p.camb_from_cama.inverse() * (*rotations)[p.camera_b];
        known[p.camera_a] = true;
      }
      grew = true;
    }
  }
  return std::all_of(known.begin(), known.end(), [](bool k) { return k; });
}

// Angle of the product of the pair rotations around the ring (every pair usable, N >= 3); -1 otherwise.
double LoopClosureErrorDeg(const std::vector<RingPairEstimate>& pairs, int num_cams) {
  if (num_cams < 3 || static_cast<int>(pairs.size()) != num_cams) return -1.0;
  std::vector<Eigen::Quaterniond> chained;
  if (!ChainFromCameraZero(pairs, num_cams, &chained)) return -1.0;
  double worst = 0.0;
  for (const RingPairEstimate& p : pairs) {
    if (!p.usable) return -1.0;
    // The pair not used by the chain closes the loop; checking every pair's consistency with the
    // chained rotations gives the loop's error (the others are exactly 0).
    worst = std::max(worst, RotationDistanceDeg(p.camb_from_cama * chained[p.camera_a], chained[p.camera_b]));
  }
  return worst;
}

// " (pairs: a-b inliers/matches ...)" for a failure message.
std::string PairCounts(const std::vector<RingPairEstimate>& pairs) {
  std::string out = " (pairs:";
  for (const RingPairEstimate& p : pairs) {
    out += " " + std::to_string(p.camera_a) + "-" + std::to_string(p.camera_b) + " " + std::to_string(p.inliers) + "/" +
           std::to_string(p.matches);
  }
  return out + " inliers/matches)";
}

struct JointSolution {
  RingModel model;
  std::vector<std::vector<int>> inliers;  // per pair
  int total_inliers = -1;
};

// The joint refinement (RefineRing) from `start` (cam_j_from_rig, kappa 0) on the pairs' own inliers
// (the angle scale estimated when `estimate_scale`),
// then `joint_rounds` times: inliers re-selected from every match by the joint solution, refined again.
JointSolution SolveJoint(const std::vector<PairState>& pairs, const std::vector<std::vector<int>>& pair_inliers,
                         const Rig& rig, const std::vector<Eigen::Quaterniond>& start, const RingCalibrationOptions& o,
                         bool estimate_scale) {
  const double scale = o.inlier_threshold_deg * kDeg;
  const double angle_scale_sigma = estimate_scale ? o.angle_scale_sigma : 0.0;
  JointSolution s;
  s.inliers = pair_inliers;
  s.model.rotations = start;
  s.model = RefineRing(pairs, s.inliers, rig, s.model, scale, o.prior_sigma_deg, angle_scale_sigma);
  for (int round = 0; round < o.joint_rounds; ++round) {
    s.inliers = ReselectInliers(pairs, rig, s.model, scale);
    s.model = RefineRing(pairs, s.inliers, rig, s.model, scale, o.prior_sigma_deg, angle_scale_sigma);
  }
  s.inliers = ReselectInliers(pairs, rig, s.model, scale);
  s.total_inliers = 0;
  for (const auto& v : s.inliers) s.total_inliers += static_cast<int>(v.size());
  return s;
}

// The joint solution from each of `starts` (cam_j_from_rig) with the most inliers, the angle scale
// estimated when `estimate_scale`.
JointSolution BestJointSolution(const std::vector<PairState>& pairs, const std::vector<std::vector<int>>& pair_inliers,
                                const Rig& rig, const std::vector<std::vector<Eigen::Quaterniond>>& starts,
                                const RingCalibrationOptions& o, bool estimate_scale) {
  JointSolution best;
  for (const auto& start : starts) {
    JointSolution candidate = SolveJoint(pairs, pair_inliers, rig, start, o, estimate_scale);
    if (candidate.total_inliers > best.total_inliers) best = std::move(candidate);
  }
  return best;
}

// Starting points (cam_j_from_cam0) of the joint refinement: the pairs averaged around the ring
// (AverageRing from the chain `chained`) and, for a closed ring, the chain that leaves out each pair
// in turn. The pairs' own rotations are biased by the given baseline directions (off by the draw), so
// one start can fall into another minimum of the joint problem on near-field scenes.
std::vector<std::vector<Eigen::Quaterniond>> JointStarts(const std::vector<RingPairEstimate>& pairs, int num_cams,
                                                         const std::vector<Eigen::Quaterniond>& chained) {
  std::vector<std::vector<Eigen::Quaterniond>> starts = {AverageRing(pairs, num_cams, chained)};
  for (size_t left_out = 0; left_out < pairs.size(); ++left_out) {
    if (!pairs[left_out].usable) continue;
    std::vector<RingPairEstimate> others = pairs;
    others[left_out].usable = false;
    std::vector<Eigen::Quaterniond> chain;
    if (ChainFromCameraZero(others, num_cams, &chain)) starts.push_back(chain);
  }
  return starts;
}

}  // namespace

std::vector<RingPairFit> RingCalibrator::Fit(const std::vector<Rigid3>& cam_from_rig, double angle_scale) const {
  const Rig& rig = impl_->rig;
  if (static_cast<int>(cam_from_rig.size()) != rig.NumCameras()) {
    throw std::invalid_argument("RingCalibrator::Fit: " + std::to_string(cam_from_rig.size()) + " extrinsics for " +
                                std::to_string(rig.NumCameras()) + " cameras");
  }
  RingModel model;
  for (const Rigid3& t : cam_from_rig) model.rotations.push_back(t.rotation.normalized());
  model.kappa = angle_scale - 1.0;
  model = FitCommonRotation(impl_->pairs, rig, model, impl_->options.inlier_threshold_deg * kDeg);
  const std::vector<std::vector<int>> inliers =
      ReselectInliers(impl_->pairs, rig, model, impl_->options.inlier_threshold_deg * kDeg);
  std::vector<RingPairFit> fits;
  for (size_t k = 0; k < impl_->pairs.size(); ++k) {
    const PairState& p = impl_->pairs[k];
    RingPairFit f;
    f.camera_a = p.a;
    f.camera_b = p.b;
    f.matches = static_cast<int>(p.bearings_a.size());
    f.inliers = static_cast<int>(inliers[k].size());
    f.median_residual_deg = MedianResidualDeg(p, inliers[k], rig, model);
    const Eigen::Vector3d baseline_in_rig = PairBaselineInRig(p, rig);
    for (size_t i = 0; i < p.bearings_a.size(); ++i) {
      const double r = RingResidual(p, static_cast<int>(i), baseline_in_rig, model);
      f.residuals_deg.push_back(std::asin(std::min(1.0, r)) / kDeg);
    }
    fits.push_back(f);
  }
  return fits;
}

RingCalibrationReport RingCalibrator::Solve() const {
  const Rig& rig = impl_->rig;
  const RingCalibrationOptions& o = impl_->options;
  const int n = rig.NumCameras();
  RingCalibrationReport report;
  report.frames = impl_->frames;
  report.cam_from_rig = rig.Extrinsics();
  std::vector<std::vector<int>> inliers(impl_->pairs.size());
  for (size_t k = 0; k < impl_->pairs.size(); ++k)
    report.pairs.push_back(EstimatePair(impl_->pairs[k], rig, o, &inliers[k]));
  std::vector<Eigen::Quaterniond> rotations;
  if (!ChainFromCameraZero(report.pairs, n, &rotations)) {
    report.reason = "too few overlap matches to connect every camera to camera 0" + PairCounts(report.pairs);
    return report;
  }
  report.loop_error_deg = LoopClosureErrorDeg(report.pairs, n);
  if (o.require_closed_ring && report.loop_error_deg < 0.0 && n >= 3 && static_cast<int>(report.pairs.size()) == n) {
    report.reason = "the ring is open (a pair has too few overlap matches), so nothing checks the chained pairs" +
                    PairCounts(report.pairs);
    return report;
  }
  if (report.loop_error_deg > o.max_loop_error_deg) {
    report.reason = "the pair rotations do not close the ring (loop error " + std::to_string(report.loop_error_deg) +
                    " deg > " + std::to_string(o.max_loop_error_deg) + ")";
    return report;
  }
  const Eigen::Quaterniond cam0_from_rig = rig.cameras[0].cam_from_rig.rotation;
  std::vector<std::vector<Eigen::Quaterniond>> starts = JointStarts(report.pairs, n, rotations);
  for (auto& start : starts) {
    for (auto& q : start) q = (q * cam0_from_rig).normalized();  // cam_j_from_rig
  }
  JointSolution best = BestJointSolution(impl_->pairs, inliers, rig, starts, o, false);  // the lenses as given
  if (o.angle_scale_sigma > 0.0 && report.loop_error_deg >= 0.0) {  // an open ring does not see the scale
    // The scale refined from that solution says whether it matters; only then are all starts solved
    // again with it free (refined from one solution alone, the draws of real shots agree less).
    const JointSolution probe = SolveJoint(impl_->pairs, inliers, rig, best.model.rotations, o, true);
    if (std::abs(probe.model.kappa) >= o.min_angle_scale_change) {
      JointSolution scaled = BestJointSolution(impl_->pairs, inliers, rig, starts, o, true);
      if (std::abs(scaled.model.kappa) >= o.min_angle_scale_change) best = std::move(scaled);
    }
  }
  const RingModel& model = best.model;
  inliers = best.inliers;
  report.angle_scale = 1.0 + model.kappa;
  const double scale = o.inlier_threshold_deg * kDeg;
  RingModel given;
  for (const RigCamera& c : rig.cameras) given.rotations.push_back(c.cam_from_rig.rotation);
  report.uncertainty_deg = RingUncertaintyDeg(impl_->pairs, inliers, rig, model, model.kappa != 0.0);
  for (size_t k = 0; k < impl_->pairs.size(); ++k) {
    RingPairEstimate& p = report.pairs[k];
    if (!p.usable) continue;
    p.inliers = static_cast<int>(inliers[k].size());
    p.median_residual_deg_given = MedianResidualDeg(impl_->pairs[k], inliers[k], rig, given);
    p.median_residual_deg_result = MedianResidualDeg(impl_->pairs[k], inliers[k], rig, model);
    report.max_pair_disagreement_deg =
        std::max(report.max_pair_disagreement_deg, PairDisagreementDeg(impl_->pairs[k], inliers[k], rig, model, scale));
  }
  if (report.uncertainty_deg < 0.0 || report.uncertainty_deg > o.max_uncertainty_deg) {
    report.reason = "the overlaps leave a camera's rotation uncertain (one sigma " +
                    std::to_string(report.uncertainty_deg) + " deg > " + std::to_string(o.max_uncertainty_deg) + ")";
    return report;
  }
  if (report.max_pair_disagreement_deg > o.max_pair_disagreement_deg) {
    report.reason = "a pair's own rotation is " + std::to_string(report.max_pair_disagreement_deg) +
                    " deg from the ring solution (> " + std::to_string(o.max_pair_disagreement_deg) + ")";
    return report;
  }
  // Camera 0 stays the gauge. The joint solution also turned the cameras together against their
  // centres (model.rotations[0] against cam0_from_rig); with camera 0 kept, the centres turn by the
  // inverse about camera 0's centre instead, so that every baseline keeps the direction the solution
  // gives it in each camera (turn_centres; false: the centres stay the given ones).
  report.common_turn_deg = RotationDistanceDeg(model.rotations[0], cam0_from_rig);
  report.common_turn_sigma_deg = RingUncertaintyDeg(impl_->pairs, inliers, rig, model, model.kappa != 0.0, true);
  report.centres_turned = o.turn_centres;
  report.centres_known = o.turn_centres && report.common_turn_sigma_deg >= 0.0 &&
                         report.common_turn_sigma_deg <= o.max_common_turn_sigma_deg;
  const Eigen::Quaterniond rig_turn = report.centres_turned
                                          ? (cam0_from_rig.inverse() * model.rotations[0]).normalized()
                                          : Eigen::Quaterniond::Identity();
  const Eigen::Vector3d centre0 = CameraPositionInRig(rig.cameras[0].cam_from_rig);
  for (int j = 1; j < n; ++j) {
    const Eigen::Vector3d centre = centre0 + rig_turn * (CameraPositionInRig(rig.cameras[j].cam_from_rig) - centre0);
    const Eigen::Quaterniond camj_from_rig =
        (model.rotations[j] * model.rotations[0].inverse() * cam0_from_rig).normalized();
    report.cam_from_rig[j] = Rigid3(camj_from_rig, -(camj_from_rig * centre));
  }
  report.converged = true;
  return report;
}

}  // namespace rovo
