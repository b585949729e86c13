#include "eval/studies/projection_study.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "datasets/dataset.h"
#include "datasets/image_file.h"
#include "datasets/io.h"
#include "datasets/progress.h"
#include "rovo/version.h"
#include "vo/frontend.h"
#include "vo/hybrid_projection.h"
#include "vo/interview_matching.h"
#include "vo/png_gray.h"
#include "vo/tracking.h"

namespace rovo {
namespace {

cv::Mat ReadGray(const std::string& path) {
  cv::Mat image = ReadGrayImage(path);
  if (image.empty()) throw std::runtime_error(path + ": cannot read image");
  return image;
}

}  // namespace

cv::Mat ReadDepthImage(const std::string& path) {
  const FloatImage exr = ReadExr(path);
  if (exr.planes.empty()) throw std::runtime_error(path + ": no channel to read depth from");
  cv::Mat depth(exr.height, exr.width, CV_32F);
  std::copy(exr.planes[0].begin(), exr.planes[0].end(), depth.ptr<float>(0));
  return depth;
}

namespace {

float DepthAt(const cv::Mat& depth, const Eigen::Vector2d& px) {
  const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
  if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) return 0.0f;
  return depth.at<float>(v, u);
}

}  // namespace

int GroundTruthMatchVerdict(const Rig& rig, int camera_a, const Eigen::Vector3d& bearing_a,
                            const Eigen::Vector2d& fisheye_a, int camera_b, const Eigen::Vector2d& fisheye_b,
                            const cv::Mat& depth_a, const cv::Mat& depth_b, double inlier_px, double* error_px) {
  if (error_px) *error_px = std::numeric_limits<double>::infinity();
  const float centre_range = DepthAt(depth_a, fisheye_a);
  if (!(centre_range > 0.0f) || !std::isfinite(centre_range)) return -1;
  const Rigid3 rig_from_a = rig.cameras[camera_a].cam_from_rig.Inverse();
  const Rigid3& b_from_rig = rig.cameras[camera_b].cam_from_rig;
  const int ua = static_cast<int>(std::lround(fisheye_a.x())), va = static_cast<int>(std::lround(fisheye_a.y()));
  int verdict = 0;
  for (int dv = -1; dv <= 1; ++dv) {
    for (int du = -1; du <= 1; ++du) {
      const int u = ua + du, v = va + dv;
      if (u < 0 || v < 0 || u >= depth_a.cols || v >= depth_a.rows) continue;
      const float range = depth_a.at<float>(v, u);
      if (!(range > 0.0f) || !std::isfinite(range)) continue;
      const Eigen::Vector3d point_in_b = b_from_rig * (rig_from_a * (static_cast<double>(range) * bearing_a));
      const auto predicted = rig.cameras[camera_b].camera.Project(point_in_b);
      if (!predicted) continue;
      const double error = (*predicted - fisheye_b).norm();
      if (error_px) *error_px = std::min(*error_px, error);
      if (error > inlier_px || verdict == 1) continue;
      const double expected = point_in_b.norm();
      const int u0 = static_cast<int>(std::lround(predicted->x())), v0 = static_cast<int>(std::lround(predicted->y()));
      for (int y = v0 - 1; y <= v0 + 1 && verdict == 0; ++y) {
        for (int x = u0 - 1; x <= u0 + 1; ++x) {
          if (x < 0 || y < 0 || x >= depth_b.cols || y >= depth_b.rows) continue;
          const double d = depth_b.at<float>(y, x);
          if (d > 0 && std::abs(d - expected) <= 0.03 * expected + 0.05) {
            verdict = 1;
            break;
          }
        }
      }
    }
  }
  return verdict;
}

int FrontendMatchVerdict(const Frontend& frontend, const Rig& rig, const Frontend::ViewMatch& match,
                         const std::vector<cv::Mat>& depths, double inlier_px, double* error_px) {
  const cv::Point2f pa = frontend.tracker(match.camera_a).points()[match.index_a].px;
  const cv::Point2f pb = frontend.tracker(match.camera_b).points()[match.index_b].px;
  const HybridProjection& a = frontend.projection(match.camera_a);
  const auto bearing_a = a.BearingFromWarped(Eigen::Vector2d(pa.x, pa.y));
  const auto fa = a.FisheyeFromWarped(Eigen::Vector2d(pa.x, pa.y));
  const auto fb = frontend.projection(match.camera_b).FisheyeFromWarped(Eigen::Vector2d(pb.x, pb.y));
  if (!bearing_a || !fa || !fb) return -2;
  return GroundTruthMatchVerdict(rig, match.camera_a, *bearing_a, *fa, match.camera_b, *fb, depths[match.camera_a],
                                 depths[match.camera_b], inlier_px, error_px);
}

namespace {

struct DrawnMatch {
  cv::Point2f a, b;
  bool inlier;
};

void WriteMatchesPng(const std::string& path, const cv::Mat& image_a, const cv::Mat& image_b,
                     const std::vector<DrawnMatch>& matches, const std::string& caption) {
  const int height = std::max(image_a.rows, image_b.rows);
  cv::Mat canvas(height + 30, image_a.cols + image_b.cols, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::Mat left = canvas(cv::Rect(0, 30, image_a.cols, image_a.rows));
  cv::Mat right = canvas(cv::Rect(image_a.cols, 30, image_b.cols, image_b.rows));
  cv::cvtColor(image_a, left, cv::COLOR_GRAY2BGR);
  cv::cvtColor(image_b, right, cv::COLOR_GRAY2BGR);
  const cv::Point2f offset_a(0, 30), offset_b(static_cast<float>(image_a.cols), 30);
  for (const DrawnMatch& m : matches) {
    const cv::Scalar colour = m.inlier ? cv::Scalar(0, 220, 0) : cv::Scalar(0, 0, 255);
    cv::line(canvas, m.a + offset_a, m.b + offset_b, colour, 1, cv::LINE_AA);
    cv::circle(canvas, m.a + offset_a, 3, colour, 1, cv::LINE_AA);
    cv::circle(canvas, m.b + offset_b, 3, colour, 1, cv::LINE_AA);
  }
  cv::putText(canvas, caption, cv::Point(8, 21), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  cv::cvtColor(canvas, canvas, cv::COLOR_BGR2RGB);
  WritePng8(path, canvas.cols, canvas.rows, 3, std::vector<uint8_t>(canvas.datastart, canvas.dataend),
            "rovo " ROVO_VERSION);
}

bool MaskAt(const cv::Mat& mask, const Eigen::Vector2d& px) {
  const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
  return u >= 0 && v >= 0 && u < mask.cols && v < mask.rows && mask.at<uint8_t>(v, u) != 0;
}

// Error bins of the ground-truth check (fisheye px): [0, .5), [.5, 1), [1, 2), [2, 4), [4, 8), >= 8.
constexpr double kErrorBinEdges[] = {0.5, 1.0, 2.0, 4.0, 8.0};
constexpr int kErrorBins = 6;

int ErrorBin(double error_px) {
  int bin = 0;
  while (bin < kErrorBins - 1 && error_px >= kErrorBinEdges[bin]) ++bin;
  return bin;
}

// A track's descriptors at its first frame and at the previous frame.
struct TrackHistory {
  cv::Mat first, previous;
  int first_frame = 0;
};

// One image representation (raw fisheye or hybrid) of the study.
struct Arm {
  std::vector<ViewTracker> trackers;
  std::vector<std::unordered_map<uint64_t, TrackHistory>> history;  // per camera, live tracks only
  std::vector<std::set<uint64_t>> contributing;                     // per camera: ids that contributed
  double first_sum = 0, age_sum = 0, step_sum = 0;
  int64_t first_pairs = 0, step_pairs = 0;
  int64_t matches = 0, inliers = 0;              // epipolar-consistent mutual-NN matches
  int64_t raw_matches = 0, raw_inliers = 0;      // all mutual-NN matches (descriptors only)
  int64_t chain_matches = 0, chain_inliers = 0;  // the front-end's filter chain on this arm's images
  std::vector<int64_t> error_bins = std::vector<int64_t>(kErrorBins, 0);
  std::vector<DrawnMatch> drawn;  // last frame, first pair
};

// (a): descriptor distances of the live tracks of one view at frame t.
void AccumulateDescriptorDrift(Arm* arm, int camera, int t) {
  std::unordered_map<uint64_t, TrackHistory> live;
  for (const TrackedPoint& p : arm->trackers[camera].points()) {
    if (!p.has_descriptor) continue;
    const auto it = arm->history[camera].find(p.track_id);
    TrackHistory h;
    if (it == arm->history[camera].end()) {
      h.first = p.descriptor.clone();
      h.first_frame = t;
    } else {
      h = std::move(it->second);
      arm->first_sum += HammingDistance(h.first, p.descriptor);
      arm->age_sum += t - h.first_frame;
      ++arm->first_pairs;
      arm->step_sum += HammingDistance(h.previous, p.descriptor);
      ++arm->step_pairs;
      arm->contributing[camera].insert(p.track_id);
    }
    h.previous = p.descriptor.clone();
    live.emplace(p.track_id, std::move(h));
  }
  arm->history[camera] = std::move(live);
}

// The fixed inputs of one study run: the rig, the front-end, the neighbouring view pairs and masks.
struct StudySetup {
  const ProjectionStudyOptions& options;
  const Rig& rig;
  int n = 0;
  std::vector<HybridLayout> layouts;
  std::vector<std::pair<int, int>> pairs;  // neighbouring views (a, b), each pair once
  std::vector<cv::Mat> fisheye_masks;      // valid pixels of each lens
  InterviewMatchOptions nn_options;        // part (b): mutual nearest descriptors, no other filter
};

// One frame's images: fisheye, warped (hybrid) and depth.
struct StudyFrame {
  std::vector<cv::Mat> images, warped, depths;
};

// Both arms' accumulators plus the front-end column.
struct StudyTally {
  Arm fisheye, hybrid;
  std::vector<DrawnMatch> drawn_frontend;
  std::vector<int64_t> frontend_error_bins = std::vector<int64_t>(kErrorBins, 0);
  cv::Mat last_fisheye_a, last_fisheye_b;
};

// Neighbouring view pairs (a, right neighbour of a), each unordered pair once.
std::vector<std::pair<int, int>> NeighbourPairs(const std::vector<HybridLayout>& layouts) {
  std::vector<std::pair<int, int>> pairs;
  std::set<std::pair<int, int>> seen;
  for (int i = 0; i < static_cast<int>(layouts.size()); ++i) {
    const int j = layouts[i].right_neighbour;
    if (j != i && seen.insert({std::min(i, j), std::max(i, j)}).second) pairs.emplace_back(i, j);
  }
  return pairs;
}

std::vector<cv::Mat> FisheyeMasks(const Rig& rig) {
  std::vector<cv::Mat> masks(rig.NumCameras());
  for (int i = 0; i < rig.NumCameras(); ++i) {
    const Camera& camera = rig.cameras[i].camera;
    const std::vector<unsigned char> mask = camera.ValidPixelMask();
    masks[i] = cv::Mat(camera.height, camera.width, CV_8UC1, const_cast<unsigned char*>(mask.data())).clone();
  }
  return masks;
}

// Part (b) matcher: mutual nearest descriptors over the overlap features; epipolar check applied after.
InterviewMatchOptions NearestNeighbourMatchOptions() {
  InterviewMatchOptions nn_options;
  nn_options.use_y_distance = false;
  nn_options.use_zncc = false;
  nn_options.use_positive_disparity = false;
  nn_options.max_orientation_diff_deg = 180.0;
  nn_options.max_descriptor_distance = 256;
  nn_options.max_epipolar_angle_deg = 180.0;
  nn_options.max_ratio = 1.0;
  return nn_options;
}

// A direction (rig frame) is in the overlap of (a, b) when it falls inside both hybrid images.
bool InHybridImage(const Frontend& frontend, const Rig& rig, int camera, const Eigen::Vector3d& bearing_in_rig) {
  const HybridProjection& projection = frontend.projection(camera);
  const Eigen::Vector3d bearing_in_cam = rig.cameras[camera].cam_from_rig.RotationMatrix() * bearing_in_rig;
  const auto px = projection.WarpedInImageFromBearing(bearing_in_cam);
  if (!px) return false;
  const int u = static_cast<int>(std::lround(px->x())), v = static_cast<int>(std::lround(px->y()));
  return projection.valid_mask().at<uint8_t>(v, u) != 0;
}

// Reads frame t, runs the front-end on it and tracks both arms (ids from one sequential source).
StudyFrame TrackFrame(const StudySetup& setup, int t, Frontend& frontend, StudyTally& tally,
                      const std::function<uint64_t()>& id_source) {
  const int n = setup.n;
  StudyFrame frame;
  frame.images.resize(n);
  frame.depths.resize(n);
  frame.warped.resize(n);
  tbb::parallel_for(0, n, [&](int i) {
    frame.images[i] = ReadGray(ImagePath(setup.options.dataset_dir, setup.rig.cameras[i].name, t));
    frame.depths[i] = ReadDepthImage(DepthPath(setup.options.dataset_dir, setup.rig.cameras[i].name, t));
  });
  frontend.Process(frame.images);
  tbb::parallel_for(0, n, [&](int i) {
    frame.warped[i] = frontend.warped_image(i);
    tally.fisheye.trackers[i].Track(frame.images[i], setup.fisheye_masks[i]);
    tally.hybrid.trackers[i].Track(frame.warped[i], frontend.projection(i).valid_mask());
  });
  for (Arm* arm : {&tally.fisheye, &tally.hybrid}) {
    for (int i = 0; i < n; ++i) arm->trackers[i].DetectAndDescribe(id_source);
  }
  return frame;
}

// Bearings (rig frame, rotation only) of every tracked point of an arm; zero where there is none.
std::vector<std::vector<Eigen::Vector3d>> ArmBearingsInRig(const StudySetup& setup, const Frontend& frontend,
                                                           const Arm& arm, bool hybrid) {
  std::vector<std::vector<Eigen::Vector3d>> bearings_in_rig(setup.n);
  for (int i = 0; i < setup.n; ++i) {
    const Eigen::Matrix3d rig_from_cam = setup.rig.cameras[i].cam_from_rig.RotationMatrix().transpose();
    for (const TrackedPoint& p : arm.trackers[i].points()) {
      const Eigen::Vector2d px(p.px.x, p.px.y);
      const auto bearing =
          hybrid ? frontend.projection(i).BearingFromWarped(px) : setup.rig.cameras[i].camera.Unproject(px);
      bearings_in_rig[i].push_back(bearing ? Eigen::Vector3d(rig_from_cam * *bearing) : Eigen::Vector3d::Zero());
    }
  }
  return bearings_in_rig;
}

// The overlap features of a view pair (a, b) in one arm, as the two sides of MatchViews.
struct OverlapViews {
  std::vector<TrackedPoint> points[2];
  MatchView views[2];
};

// Fills `out` (its views point into its own points).
void BuildOverlapViews(const StudySetup& setup, const Frontend& frontend, const StudyFrame& frame, const Arm& arm,
                       bool hybrid, const std::vector<std::vector<Eigen::Vector3d>>& bearings_in_rig, int a, int b,
                       OverlapViews* out) {
  for (int side = 0; side < 2; ++side) {
    const int camera = side == 0 ? a : b;
    const auto& all = arm.trackers[camera].points();
    MatchView& view = out->views[side];
    for (int q = 0; q < static_cast<int>(all.size()); ++q) {
      const Eigen::Vector3d& d = bearings_in_rig[camera][q];
      if (!all[q].has_descriptor || d.isZero() || !InHybridImage(frontend, setup.rig, a, d) ||
          !InHybridImage(frontend, setup.rig, b, d))
        continue;
      out->points[side].push_back(all[q]);
      view.bearings_in_rig.push_back(d);
    }
    view.points = &out->points[side];
    view.centre_in_rig = setup.rig.cameras[camera].cam_from_rig.Inverse().translation;
    view.image = hybrid ? &frame.warped[camera] : &frame.images[camera];
    const Eigen::Matrix3d cam_from_rig = setup.rig.cameras[camera].cam_from_rig.RotationMatrix();
    if (hybrid) {
      const HybridProjection* projection = &frontend.projection(camera);
      view.pixel_from_direction_in_rig = [projection, cam_from_rig](const Eigen::Vector3d& d) {
        return projection->WarpedInImageFromBearing(cam_from_rig * d);
      };
    } else {
      const Camera* lens = &setup.rig.cameras[camera].camera;
      const cv::Mat* mask = &setup.fisheye_masks[camera];
      view.pixel_from_direction_in_rig = [lens, mask, cam_from_rig](const Eigen::Vector3d& d) {
        auto px = lens->Project(Eigen::Vector3d(cam_from_rig * d));
        if (px && !MaskAt(*mask, *px)) px.reset();
        return px;
      };
    }
  }
}

// Part (b) on one view pair of one arm: the filter chain and the mutual-NN matches, verified with depth.
void MatchOverlapPair(const StudySetup& setup, const Frontend& frontend, const StudyFrame& frame, Arm* arm, bool hybrid,
                      const std::vector<std::vector<Eigen::Vector3d>>& bearings_in_rig, int a, int b, bool draw) {
  const Rig& rig = setup.rig;
  OverlapViews overlap;
  BuildOverlapViews(setup, frontend, frame, *arm, hybrid, bearings_in_rig, a, b, &overlap);
  const std::vector<TrackedPoint>(&points)[2] = overlap.points;
  const MatchView(&views)[2] = overlap.views;
  // The verdict of a match between views[0] point ia and views[1] point ib (-1: no depth).
  const auto verdict_of = [&](int ia, int ib, double* error) {
    const cv::Point2f pa = points[0][ia].px, pb = points[1][ib].px;
    std::optional<Eigen::Vector2d> fa(Eigen::Vector2d(pa.x, pa.y)), fb(Eigen::Vector2d(pb.x, pb.y));
    if (hybrid) {
      fa = frontend.projection(a).FisheyeFromWarped(*fa);
      fb = frontend.projection(b).FisheyeFromWarped(*fb);
      if (!fa || !fb) return -1;
    }
    const Eigen::Vector3d bearing_a = rig.cameras[a].cam_from_rig.RotationMatrix() * views[0].bearings_in_rig[ia];
    return GroundTruthMatchVerdict(rig, a, bearing_a, *fa, b, *fb, frame.depths[a], frame.depths[b],
                                   setup.options.inlier_px, error);
  };
  PairGeometry geometry;
  geometry.up_in_rig = setup.layouts[a].up_in_rig;
  geometry.plane_normal_in_rig = setup.layouts[a].right_normal_in_rig;
  geometry.focal_px = 0.5 * (frontend.projection(a).focal_px() + frontend.projection(b).focal_px());
  for (const InterviewMatch& m : MatchViews(geometry, views[0], views[1], setup.options.frontend_matching)) {
    double error = 0;
    const int verdict = verdict_of(m.index_a, m.index_b, &error);
    if (verdict < 0) continue;
    ++arm->chain_matches;
    arm->chain_inliers += verdict;
  }
  for (const InterviewMatch& m : MatchViews(PairGeometry{}, views[0], views[1], setup.nn_options)) {
    const Eigen::Vector3d& da = views[0].bearings_in_rig[m.index_a];
    const Eigen::Vector3d& db = views[1].bearings_in_rig[m.index_b];
    const bool epipolar_ok = EpipolarAngle(views[0].centre_in_rig, da, views[1].centre_in_rig, db) <=
                             setup.options.epipolar_deg * M_PI / 180;
    const cv::Point2f pa = points[0][m.index_a].px, pb = points[1][m.index_b].px;
    double error = 0;
    const int verdict = verdict_of(m.index_a, m.index_b, &error);
    if (verdict < 0) continue;
    ++arm->raw_matches;
    arm->raw_inliers += verdict;
    if (!epipolar_ok) continue;
    ++arm->matches;
    arm->inliers += verdict;
    ++arm->error_bins[ErrorBin(error)];
    if (draw) arm->drawn.push_back({pa, pb, verdict == 1});
  }
}

// The front-end's own accepted matches (all filters), verified with depth as the arms' matches are.
void VerifyFrontendMatches(const StudySetup& setup, const Frontend& frontend, const StudyFrame& frame, bool last,
                           StudyTally* tally, ProjectionStudyResult* result) {
  if (last) tally->drawn_frontend.clear();
  for (const Frontend::ViewMatch& m : frontend.last_matches()) {
    double error = 0;
    const int verdict = FrontendMatchVerdict(frontend, setup.rig, m, frame.depths, setup.options.inlier_px, &error);
    if (verdict < 0) continue;
    const cv::Point2f pa = frontend.tracker(m.camera_a).points()[m.index_a].px;
    const cv::Point2f pb = frontend.tracker(m.camera_b).points()[m.index_b].px;
    ++result->matches_frontend;
    result->inliers_frontend += verdict;
    ++tally->frontend_error_bins[ErrorBin(error)];
    if (last && !setup.pairs.empty() && m.camera_a == setup.pairs[0].first && m.camera_b == setup.pairs[0].second) {
      tally->drawn_frontend.push_back({pa, pb, verdict == 1});
    }
  }
}

// One frame of the study: tracking, part (a), part (b) in both arms, the front-end column.
void StudyOneFrame(const StudySetup& setup, int t, int frames, Frontend& frontend, StudyTally* tally,
                   const std::function<uint64_t()>& id_source, ProjectionStudyResult* result) {
  const StudyFrame frame = TrackFrame(setup, t, frontend, *tally, id_source);
  // (a) descriptor drift along the tracks.
  for (Arm* arm : {&tally->fisheye, &tally->hybrid}) {
    for (int i = 0; i < setup.n; ++i) AccumulateDescriptorDrift(arm, i, t);
  }
  // (b) inter-view matching in the overlaps, verified with depth.
  const bool last = t + 1 == frames;
  for (Arm* arm : {&tally->fisheye, &tally->hybrid}) {
    const bool hybrid = arm == &tally->hybrid;
    const std::vector<std::vector<Eigen::Vector3d>> bearings_in_rig = ArmBearingsInRig(setup, frontend, *arm, hybrid);
    if (last) arm->drawn.clear();
    for (size_t k = 0; k < setup.pairs.size(); ++k) {
      MatchOverlapPair(setup, frontend, frame, arm, hybrid, bearings_in_rig, setup.pairs[k].first,
                       setup.pairs[k].second, last && k == 0);
    }
  }
  VerifyFrontendMatches(setup, frontend, frame, last, tally, result);
  if (last && !setup.pairs.empty()) {
    tally->last_fisheye_a = frame.images[setup.pairs[0].first];
    tally->last_fisheye_b = frame.images[setup.pairs[0].second];
  }
}

// The arms' sums as the result's means and counts.
void SummarizeArms(const Arm& fisheye_arm, const Arm& hybrid_arm, ProjectionStudyResult* result) {
  const auto distinct = [](const Arm& arm) {
    int64_t count = 0;
    for (const auto& ids : arm.contributing) count += static_cast<int64_t>(ids.size());
    return count;
  };
  const auto ratio = [](double sum, int64_t count) { return count ? sum / static_cast<double>(count) : 0.0; };
  result->hamming_fisheye = ratio(fisheye_arm.first_sum, fisheye_arm.first_pairs);
  result->hamming_hybrid = ratio(hybrid_arm.first_sum, hybrid_arm.first_pairs);
  result->hamming_step_fisheye = ratio(fisheye_arm.step_sum, fisheye_arm.step_pairs);
  result->hamming_step_hybrid = ratio(hybrid_arm.step_sum, hybrid_arm.step_pairs);
  result->mean_age_fisheye = ratio(fisheye_arm.age_sum, fisheye_arm.first_pairs);
  result->mean_age_hybrid = ratio(hybrid_arm.age_sum, hybrid_arm.first_pairs);
  result->tracked_pairs_fisheye = fisheye_arm.first_pairs;
  result->tracked_pairs_hybrid = hybrid_arm.first_pairs;
  result->features_fisheye = distinct(fisheye_arm);
  result->features_hybrid = distinct(hybrid_arm);
  result->raw_matches_fisheye = fisheye_arm.raw_matches;
  result->raw_inliers_fisheye = fisheye_arm.raw_inliers;
  result->raw_matches_hybrid = hybrid_arm.raw_matches;
  result->raw_inliers_hybrid = hybrid_arm.raw_inliers;
  result->chain_matches_fisheye = fisheye_arm.chain_matches;
  result->chain_inliers_fisheye = fisheye_arm.chain_inliers;
  result->chain_matches_hybrid = hybrid_arm.chain_matches;
  result->chain_inliers_hybrid = hybrid_arm.chain_inliers;
  result->matches_fisheye = fisheye_arm.matches;
  result->inliers_fisheye = fisheye_arm.inliers;
  result->matches_hybrid = hybrid_arm.matches;
  result->inliers_hybrid = hybrid_arm.inliers;
}

// "ratio % (correct / all)" of a match count.
std::string RatioCell(int64_t inliers, int64_t matches) {
  char text[96];
  std::snprintf(text, sizeof(text), "%.2f (%lld / %lld)", matches ? 100.0 * double(inliers) / double(matches) : 0.0,
                static_cast<long long>(inliers), static_cast<long long>(matches));
  return std::string(text);
}

std::string BinsRow(const char* name, const std::vector<int64_t>& bins) {
  std::string row = std::string("| ") + name;
  for (int64_t count : bins) row += " | " + std::to_string(count);
  return row + " |\n";
}

// The Table II rows of table.md, then the ratios and track counts under it.
void WriteTableRows(const ProjectionStudyResult& result, std::ostringstream& md) {
  char line[1024];
  md << "| | Original fisheye | Hybrid projection (ours) | Paper: fisheye / hybrid |\n|---|---|---|---|\n";
  std::snprintf(line, sizeof(line),
                "| Descriptor distance (mean Hamming, track's first frame vs each later frame) | %.2f | %.2f | 124.85 "
                "/ 35.27 |\n",
                result.hamming_fisheye, result.hamming_hybrid);
  md << line;
  std::snprintf(line, sizeof(line), "| Descriptor distance (mean Hamming, frame t vs t+1) | %.2f | %.2f | - |\n",
                result.hamming_step_fisheye, result.hamming_step_hybrid);
  md << line;
  md << "| Inter-view inlier ratio %, mutual-NN ORB matches in the overlaps, descriptors only (correct / all) | "
     << RatioCell(result.raw_inliers_fisheye, result.raw_matches_fisheye) << " | "
     << RatioCell(result.raw_inliers_hybrid, result.raw_matches_hybrid) << " | - |\n";
  md << "| Inter-view inlier ratio %, the same matches kept when epipolar-consistent | "
     << RatioCell(result.inliers_fisheye, result.matches_fisheye) << " | "
     << RatioCell(result.inliers_hybrid, result.matches_hybrid) << " | 21.53 / 73.16 |\n";
  md << "| Inter-view inlier ratio %, the front-end's filter chain on the same overlap features | "
     << RatioCell(result.chain_inliers_fisheye, result.chain_matches_fisheye) << " | "
     << RatioCell(result.chain_inliers_hybrid, result.chain_matches_hybrid) << " | - |\n";
  md << "| Inter-view inlier ratio %, the front-end itself | - | "
     << RatioCell(result.inliers_frontend, result.matches_frontend) << " | - |\n\n";
  std::snprintf(line, sizeof(line),
                "Ratios: descriptor distance hybrid/fisheye = %.3f (target <= 0.35); inlier ratio hybrid/fisheye = "
                "%.2f (target >= 3, hybrid >= 80%%); correct matches of the filter chain hybrid/fisheye = %.2f.\n\n",
                result.hamming_fisheye > 0 ? result.hamming_hybrid / result.hamming_fisheye : 0.0,
                result.InlierRatioFisheye() > 0 ? result.InlierRatioHybrid() / result.InlierRatioFisheye() : 0.0,
                result.chain_inliers_fisheye > 0
                    ? double(result.chain_inliers_hybrid) / double(result.chain_inliers_fisheye)
                    : 0.0);
  md << line;
  std::snprintf(line, sizeof(line),
                "Tracks behind the descriptor distances: (track, later frame) pairs fisheye %lld (%lld tracks, mean "
                "%.1f frames after the first), hybrid %lld (%lld tracks, mean %.1f frames).\n\n",
                static_cast<long long>(result.tracked_pairs_fisheye), static_cast<long long>(result.features_fisheye),
                result.mean_age_fisheye, static_cast<long long>(result.tracked_pairs_hybrid),
                static_cast<long long>(result.features_hybrid), result.mean_age_hybrid);
  md << line;
}

// The error bins and the method of table.md.
void WriteTableMethod(const StudySetup& setup, const FrontendOptions& frontend_options, const StudyTally& tally,
                      std::ostringstream& md) {
  const ProjectionStudyOptions& options = setup.options;
  md << "Ground-truth reprojection distance of the counted matches (fisheye px):\n\n"
     << "| | < 0.5 | 0.5-1 | 1-2 | 2-4 | 4-8 | >= 8 |\n|---|---|---|---|---|---|---|\n"
     << BinsRow("fisheye, NN", tally.fisheye.error_bins) << BinsRow("hybrid, NN", tally.hybrid.error_bins)
     << BinsRow("hybrid, front-end", tally.frontend_error_bins) << "\n";
  md << "Method: the same tracker (FAST + " << frontend_options.min_feature_distance_px
     << " px minimum distance, pyramidal KLT with forward-backward check, re-detection to the target, ORB "
        "descriptors recomputed every frame, "
     << (options.upright_descriptors ? "upright (angle 0)" : "at the intensity-centroid orientation")
     << ") on both image kinds. Descriptor distance: Hamming distance between a "
        "track's ORB descriptor at its first frame and at every later frame it is alive, averaged over all such "
        "pairs. Matches: mutual nearest ORB neighbours between neighbouring views among the features whose "
        "direction lies inside both views' hybrid images (same scene area for both arms); the second row keeps "
        "those within "
     << options.epipolar_deg
     << " deg of the epipolar plane (ground-truth extrinsics). The filter chain is interview_matching.h's "
        "(y-distance, descriptor, orientation, epipolar, ratio, mutual, positive disparity, ZNCC, uniqueness along "
        "the epipolar curve) with the same settings on both arms; its appearance filters (descriptor, orientation, "
        "ZNCC, uniqueness) see the arm's own images, its geometric ones the same bearings. Inlier: the depth-map "
     << "back-projection of the first feature (any of its 3x3 depth pixels) reprojects within " << options.inlier_px
     << " fisheye px of the second and is not occluded (depth agrees). Matches without depth (sky) are not "
        "counted.\n";
}

// table.md: the Table II rows, ratios, track counts, error bins and the method.
void WriteStudyTable(const StudySetup& setup, const DatasetInfo& info, const FrontendOptions& frontend_options,
                     const StudyTally& tally, const ProjectionStudyResult& result) {
  const ProjectionStudyOptions& options = setup.options;
  const Rig& rig = setup.rig;
  const int frames = result.frames;
  std::ostringstream md;
  md << "# Hybrid projection vs raw fisheye (paper Table II)\n\n";
  md << "Dataset: `" << options.dataset_dir << "` (preset " << (info.preset.empty() ? "custom" : info.preset)
     << ", seed " << info.seed << "), frames 0-" << frames - 1 << ", " << setup.n << " cameras of "
     << rig.cameras[0].camera.width << "x" << rig.cameras[0].camera.height << ", " << options.features_per_view
     << " features per view. rovo " << ROVO_VERSION << ".\n\n";
  WriteTableRows(result, md);
  WriteTableMethod(setup, frontend_options, tally, md);
  WriteFileAtomic(options.out_dir + "/table.md", md.str());
}

// study.json: the settings and both arms' and the front-end's counts.
void WriteStudyJson(const StudySetup& setup, const DatasetInfo& info, const StudyTally& tally,
                    const ProjectionStudyResult& result) {
  const ProjectionStudyOptions& options = setup.options;
  nlohmann::json json;
  json["generator"] = "rovo study projection";
  json["generator_version"] = ROVO_VERSION;
  json["dataset"] = options.dataset_dir;
  json["dataset_seed"] = info.seed;
  json["preset"] = info.preset;
  json["frames"] = result.frames;
  json["features_per_view"] = options.features_per_view;
  json["epipolar_deg"] = options.epipolar_deg;
  json["inlier_px"] = options.inlier_px;
  json["upright_descriptors"] = options.upright_descriptors;
  json["error_bin_edges_px"] = std::vector<double>(std::begin(kErrorBinEdges), std::end(kErrorBinEdges));
  const auto arm_json = [&](const Arm& arm, double hamming, double step, double age, int64_t tracks,
                            double ratio_value) {
    return nlohmann::json{{"mean_hamming_first_vs_later", hamming},
                          {"mean_hamming_consecutive", step},
                          {"tracked_pairs", arm.first_pairs},
                          {"mean_frames_after_first", age},
                          {"tracks", tracks},
                          {"raw_matches", arm.raw_matches},
                          {"raw_inliers", arm.raw_inliers},
                          {"chain_matches", arm.chain_matches},
                          {"chain_inliers", arm.chain_inliers},
                          {"matches", arm.matches},
                          {"inliers", arm.inliers},
                          {"inlier_ratio", ratio_value},
                          {"error_bins", arm.error_bins}};
  };
  json["fisheye"] = arm_json(tally.fisheye, result.hamming_fisheye, result.hamming_step_fisheye,
                             result.mean_age_fisheye, result.features_fisheye, result.InlierRatioFisheye());
  json["hybrid"] = arm_json(tally.hybrid, result.hamming_hybrid, result.hamming_step_hybrid, result.mean_age_hybrid,
                            result.features_hybrid, result.InlierRatioHybrid());
  json["frontend"] = {{"matches", result.matches_frontend},
                      {"inliers", result.inliers_frontend},
                      {"inlier_ratio", result.InlierRatioFrontend()},
                      {"error_bins", tally.frontend_error_bins}};
  WriteJsonFileAtomic(options.out_dir + "/study.json", json);
}

// The match drawings of the first pair at the last frame.
void WriteStudyDrawings(const StudySetup& setup, const Frontend& frontend, const StudyTally& tally,
                        const ProjectionStudyResult& result) {
  if (!setup.pairs.empty()) {
    const auto [a, b] = setup.pairs[0];
    const std::string pair_name = "cam" + std::to_string(a) + "-cam" + std::to_string(b) + " frame " +
                                  std::to_string(result.frames - 1) + " (green: inlier by depth GT, red: outlier)";
    WriteMatchesPng(setup.options.out_dir + "/matches_frontend.png", frontend.warped_image(a), frontend.warped_image(b),
                    tally.drawn_frontend, "hybrid, front-end matches " + pair_name);
    WriteMatchesPng(setup.options.out_dir + "/matches_hybrid.png", frontend.warped_image(a), frontend.warped_image(b),
                    tally.hybrid.drawn, "hybrid, epipolar-consistent NN matches " + pair_name);
    WriteMatchesPng(setup.options.out_dir + "/matches_fisheye.png", tally.last_fisheye_a, tally.last_fisheye_b,
                    tally.fisheye.drawn, "raw fisheye, epipolar-consistent NN matches " + pair_name);
  }
}

}  // namespace

ProjectionStudyResult RunProjectionStudy(const ProjectionStudyOptions& options) {
  const DatasetInfo info = ReadDatasetInfo(options.dataset_dir);
  if (!info.has_depth) {
    throw std::runtime_error(DatasetJsonPath(options.dataset_dir) +
                             ": has_depth is false; the study needs depth (render with --depth)");
  }
  const Rig& rig = info.rig;
  const int n = rig.NumCameras();
  const int frames = std::min(options.frames, info.frame_count);
  if (frames < 2) throw std::runtime_error(DatasetJsonPath(options.dataset_dir) + ": frame_count < 2");
  EnsureWritableDir(options.out_dir);

  FrontendOptions frontend_options;
  frontend_options.matching = options.frontend_matching;
  frontend_options.upright_descriptors = options.upright_descriptors;
  Frontend frontend(rig, frontend_options);
  const std::vector<HybridLayout> layouts = ComputeHybridLayouts(rig);
  const StudySetup setup{
      options, rig, n, layouts, NeighbourPairs(layouts), FisheyeMasks(rig), NearestNeighbourMatchOptions()};

  TrackerOptions tracker_options = TrackerOptionsFrom(frontend_options);
  tracker_options.target_features = options.features_per_view;
  StudyTally tally;
  for (Arm* arm : {&tally.fisheye, &tally.hybrid}) {
    arm->trackers.assign(n, ViewTracker(tracker_options));
    arm->history.resize(n);
    arm->contributing.resize(n);
  }

  ProjectionStudyResult result;
  result.frames = frames;
  uint64_t next_id = 0;
  const std::function<uint64_t()> id_source = [&next_id] { return ++next_id; };
  Progress progress("projection study", frames, "frames", options.quiet);
  for (int t = 0; t < frames; ++t) {
    StudyOneFrame(setup, t, frames, frontend, &tally, id_source, &result);
    progress.Add(1);
  }
  progress.Finish();

  SummarizeArms(tally.fisheye, tally.hybrid, &result);
  WriteStudyTable(setup, info, frontend_options, tally, result);
  WriteStudyJson(setup, info, tally, result);
  WriteStudyDrawings(setup, frontend, tally, result);
  return result;
}

}  // namespace rovo
