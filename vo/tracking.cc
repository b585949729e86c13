#include "vo/tracking.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>
#include <string>

#include "vo/patch_kernels.h"
#include "vo/pyr_lk.h"

namespace rovo {

void TrackerOptions::Check() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("TrackerOptions.") + what);
  };
  require(target_features >= 0, "target_features must be >= 0");
  require(max_new_per_frame >= 0, "max_new_per_frame must be >= 0");
  require(min_feature_distance_px >= 0.0f, "min_feature_distance_px must be >= 0");
  require(fast_threshold >= 0, "fast_threshold must be >= 0");
  require(klt_window_px >= 3, "klt_window_px must be >= 3");
  require(klt_levels >= 0, "klt_levels must be >= 0");
  require(klt_max_iterations >= 1, "klt_max_iterations must be >= 1");
  require(klt_epsilon_px >= 0.0f, "klt_epsilon_px must be >= 0");
  require(max_forward_backward_px >= 0.0f, "max_forward_backward_px must be >= 0");
  require(klt_predicted_levels >= 0, "klt_predicted_levels must be >= 0");
  require(border_px >= 0, "border_px must be >= 0");
}
namespace {

// Square-grid occupancy for the minimum-distance rule: cell side = min distance / sqrt(2), so one
// point per cell and a check of the 5x5 cell neighbourhood is exact.
class OccupancyGrid {
 public:
  OccupancyGrid(int width, int height, float min_distance)
      : min_distance2_(min_distance * min_distance),
        cell_(std::max(1.0f, min_distance / std::sqrt(2.0f))),
        cols_(static_cast<int>(width / cell_) + 1),
        rows_(static_cast<int>(height / cell_) + 1),
        cells_(static_cast<size_t>(cols_) * rows_, cv::Point2f(-1e9f, -1e9f)) {}

  bool Free(cv::Point2f p) const {
    const int cx = static_cast<int>(p.x / cell_), cy = static_cast<int>(p.y / cell_);
    for (int y = std::max(0, cy - 2); y <= std::min(rows_ - 1, cy + 2); ++y) {
      for (int x = std::max(0, cx - 2); x <= std::min(cols_ - 1, cx + 2); ++x) {
        const cv::Point2f q = cells_[static_cast<size_t>(y) * cols_ + x];
        const cv::Point2f d = p - q;
        if (d.dot(d) < min_distance2_) return false;
      }
    }
    return true;
  }
  void Add(cv::Point2f p) {
    const int cx = std::clamp(static_cast<int>(p.x / cell_), 0, cols_ - 1);
    const int cy = std::clamp(static_cast<int>(p.y / cell_), 0, rows_ - 1);
    cells_[static_cast<size_t>(cy) * cols_ + cx] = p;
  }

 private:
  float min_distance2_, cell_;
  int cols_, rows_;
  std::vector<cv::Point2f> cells_;
};

bool MaskAt(const cv::Mat& mask, cv::Point2f p) {
  const int x = static_cast<int>(std::lround(p.x)), y = static_cast<int>(std::lround(p.y));
  return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<uint8_t>(y, x) != 0;
}

// The validity mask eroded by `border` pixels, also away from the image edges (ORB patch + blur).
cv::Mat DetectionMask(const cv::Mat& mask, int border) {
  cv::Mat eroded;
  const int k = 2 * border + 1;
  cv::erode(mask, eroded, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
  if (eroded.rows > 2 * border && eroded.cols > 2 * border) {
    eroded.rowRange(0, border).setTo(0);
    eroded.rowRange(eroded.rows - border, eroded.rows).setTo(0);
    eroded.colRange(0, border).setTo(0);
    eroded.colRange(eroded.cols - border, eroded.cols).setTo(0);
  } else {
    eroded.setTo(0);
  }
  return eroded;
}

}  // namespace

float IntensityCentroidAngleDeg(const cv::Mat& image, cv::Point2f px) {
  const int cx = static_cast<int>(std::lround(px.x)), cy = static_cast<int>(std::lround(px.y));
  const DiscMoments m = DiscMomentsAt(image, cx, cy);
  float angle = static_cast<float>(std::atan2(static_cast<double>(m.m01), static_cast<double>(m.m10)) * 180.0 / M_PI);
  if (angle < 0) angle += 360.0f;
  return angle;
}

void PyrLkInChunks(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
                   const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to, std::vector<uint8_t>* status,
                   cv::Size window, int levels, const cv::TermCriteria& criteria, int flags) {
  const int n = static_cast<int>(from.size());
  if ((flags & cv::OPTFLOW_USE_INITIAL_FLOW) != 0 && static_cast<int>(to->size()) != n) {
    throw std::invalid_argument("PyrLkInChunks: the starts and the points differ in number");
  }
  to->resize(n);
  status->assign(n, 0);
  const int chunks = (n + kLkChunkPoints - 1) / kLkChunkPoints;
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(0, chunks, [&](int c) {
      const auto first = static_cast<std::ptrdiff_t>(c) * kLkChunkPoints;
      const auto last = std::min<std::ptrdiff_t>(first + kLkChunkPoints, n);
      PyrLk(from_pyramid, to_pyramid, from.data() + first, to->data() + first, status->data() + first,
            static_cast<int>(last - first), window, levels, criteria, flags);
    });
  });
}

int HammingDistance(const cv::Mat& a, const cv::Mat& b) { return static_cast<int>(cv::norm(a, b, cv::NORM_HAMMING)); }

ViewTracker::ViewTracker(const TrackerOptions& options) : options_(options) { options_.Check(); }

void ViewTracker::Clear() {
  image_.release();
  pyramid_.clear();
  spare_pyramid_.clear();
  points_.clear();
  descriptors_.release();
}

void ViewTracker::ResetImage(const cv::Mat& image, const cv::Mat& mask, std::vector<TrackedPoint> points) {
  image_ = image;
  detect_mask_ = DetectionMask(mask, options_.border_px);
  pyramid_.clear();
  BuildPyrLkPyramid(image_, &pyramid_, cv::Size(options_.klt_window_px, options_.klt_window_px), options_.klt_levels);
  points_.clear();
  for (TrackedPoint& p : points) {
    if (MaskAt(detect_mask_, p.px)) points_.push_back(std::move(p));
  }
}

namespace {

// KLT rounds from the previous image's pyramid into the current one, for ViewTracker::Track.
struct KltPass {
  const std::vector<cv::Mat>& previous_pyramid;
  const std::vector<cv::Mat>& pyramid;
  const std::vector<TrackedPoint>& points;  // of the previous image
  const cv::Mat& detect_mask;
  cv::Size window;
  cv::TermCriteria criteria;
  float max_fb2;     // squared forward-backward bound
  int check_levels;  // levels of the backward (check) pass

  // One KLT round for the points `which`: the forward pass starts at start[k] with `levels` levels
  // when `guided`, else at the point itself with all levels; the backward (check) pass runs for the
  // forward successes that land in the detection area. Appends the survivors to `kept`, returns the
  // lost ones.
  std::vector<int> Run(const std::vector<int>& which, const std::vector<cv::Point2f>& start, bool guided, int levels,
                       std::vector<TrackedPoint>* kept) const {
    std::vector<cv::Point2f> previous, forward = start;
    previous.reserve(which.size());
    for (int i : which) previous.push_back(points[i].px);
    std::vector<uint8_t> status_fw, status_bw;
    PyrLkInChunks(previous_pyramid, pyramid, previous, &forward, &status_fw, window, levels, criteria,
                  guided ? cv::OPTFLOW_USE_INITIAL_FLOW : 0);
    std::vector<int> candidates, lost;
    std::vector<cv::Point2f> forward_ok, backward;
    for (size_t k = 0; k < which.size(); ++k) {
      if (!status_fw[k] || !MaskAt(detect_mask, forward[k])) {
        lost.push_back(which[k]);
        continue;
      }
      candidates.push_back(static_cast<int>(k));
      forward_ok.push_back(forward[k]);
    }
    if (!candidates.empty()) {
      PyrLkInChunks(pyramid, previous_pyramid, forward_ok, &backward, &status_bw, window, check_levels, criteria, 0);
    }
    for (size_t c = 0; c < candidates.size(); ++c) {
      const int k = candidates[c];
      const cv::Point2f d = backward[c] - previous[k];
      if (!status_bw[c] || d.dot(d) > max_fb2) {
        lost.push_back(which[k]);
        continue;
      }
      TrackedPoint p = points[which[k]];
      p.flow = forward[k] - p.px;
      p.px = forward[k];
      ++p.age;
      p.has_descriptor = false;
      kept->push_back(std::move(p));
    }
    return lost;
  }
};

// The minimum distance among tracks too (converging tracks): older tracks win.
std::vector<TrackedPoint> SpacedOut(std::vector<TrackedPoint> kept, int width, int height, float min_distance) {
  std::stable_sort(kept.begin(), kept.end(),
                   [](const TrackedPoint& a, const TrackedPoint& b) { return a.age > b.age; });
  OccupancyGrid grid(width, height, min_distance);
  std::vector<TrackedPoint> spaced;
  spaced.reserve(kept.size());
  for (TrackedPoint& p : kept) {
    if (!grid.Free(p.px)) continue;
    grid.Add(p.px);
    spaced.push_back(std::move(p));
  }
  return spaced;
}

// Indices of the corners, strongest response first. std::sort of (response, index) pairs under a
// comparison of the responses alone makes the same comparisons, and so the same order, as sorting the
// key points themselves, moving 8 bytes per corner instead of 28.
std::vector<int> ByResponse(const std::vector<cv::KeyPoint>& corners) {
  struct Entry {
    float response;
    int index;
  };
  std::vector<Entry> entries(corners.size());
  for (size_t k = 0; k < corners.size(); ++k) entries[k] = {corners[k].response, static_cast<int>(k)};
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.response > b.response; });
  std::vector<int> order(entries.size());
  for (size_t k = 0; k < entries.size(); ++k) order[k] = entries[k].index;
  return order;
}

}  // namespace

int ViewTracker::Track(const cv::Mat& image, const cv::Mat& mask) {
  if (image.type() != CV_8UC1) throw std::invalid_argument("ViewTracker: image must be 8-bit gray");
  if (mask.size() != image.size()) throw std::invalid_argument("ViewTracker: mask size differs from the image");
  const cv::Size window(options_.klt_window_px, options_.klt_window_px);
  std::vector<cv::Mat>& pyramid = spare_pyramid_;  // reuses the buffers of two frames ago
  BuildPyrLkPyramid(image, &pyramid, window, options_.klt_levels);
  if (detect_mask_.size() != mask.size() || detect_mask_.empty()) {
    detect_mask_ = DetectionMask(mask, options_.border_px);
  }
  std::vector<TrackedPoint> kept;
  if (!points_.empty() && !pyramid_.empty()) {
    const KltPass klt{pyramid_,
                      pyramid,
                      points_,
                      detect_mask_,
                      window,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, options_.klt_max_iterations,
                                       options_.klt_epsilon_px),
                      options_.max_forward_backward_px * options_.max_forward_backward_px,
                      options_.klt_levels};
    std::vector<int> predicted, unpredicted;
    std::vector<cv::Point2f> predicted_start;
    for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
      if (options_.klt_predict_flow && points_[i].age > 0) {
        predicted.push_back(i);
        predicted_start.push_back(points_[i].px + points_[i].flow);
      } else {
        unpredicted.push_back(i);
      }
    }
    if (!predicted.empty()) {
      const std::vector<int> lost = klt.Run(predicted, predicted_start, true, options_.klt_predicted_levels, &kept);
      unpredicted.insert(unpredicted.end(), lost.begin(), lost.end());
      std::sort(unpredicted.begin(), unpredicted.end());
    }
    if (!unpredicted.empty()) klt.Run(unpredicted, {}, false, options_.klt_levels, &kept);
    kept = SpacedOut(std::move(kept), image.cols, image.rows, options_.min_feature_distance_px);
  }
  points_ = std::move(kept);
  image_ = image;
  std::swap(pyramid_, spare_pyramid_);
  return static_cast<int>(points_.size());
}

void ViewTracker::DetectAndDescribe(const std::function<uint64_t()>& next_id) {
  if (image_.empty()) return;
  if (static_cast<int>(points_.size()) < options_.target_features) {
    std::vector<cv::KeyPoint> corners;
    cv::FAST(image_, corners, options_.fast_threshold, true, cv::FastFeatureDetector::TYPE_9_16);
    const std::vector<int> strongest_first = ByResponse(corners);
    OccupancyGrid grid(image_.cols, image_.rows, options_.min_feature_distance_px);
    for (const TrackedPoint& p : points_) grid.Add(p.px);
    const size_t limit =
        points_.empty() || options_.max_new_per_frame <= 0
            ? options_.target_features
            : std::min(options_.target_features, static_cast<int>(points_.size()) + options_.max_new_per_frame);
    for (const int c : strongest_first) {
      const cv::KeyPoint& kp = corners[c];
      if (points_.size() >= limit) break;
      if (!MaskAt(detect_mask_, kp.pt) || !grid.Free(kp.pt)) continue;
      grid.Add(kp.pt);
      TrackedPoint p;
      p.track_id = next_id();
      p.px = kp.pt;
      points_.push_back(std::move(p));
    }
  }

  // Orientation and descriptors for all points.
  std::vector<cv::KeyPoint> keypoints;
  keypoints.reserve(points_.size());
  for (size_t i = 0; i < points_.size(); ++i) {
    points_[i].angle_deg = IntensityCentroidAngleDeg(image_, points_[i].px);
    points_[i].has_descriptor = false;
    const float descriptor_angle = options_.upright_descriptors ? 0.0f : points_[i].angle_deg;
    cv::KeyPoint kp(points_[i].px, 31.0f, descriptor_angle, 0.0f, 0, static_cast<int>(i));
    keypoints.push_back(kp);
  }
  static thread_local cv::Ptr<cv::ORB> orb = cv::ORB::create(500, 1.2f, 1, 19, 0, 2, cv::ORB::HARRIS_SCORE, 31);
  descriptors_.release();
  if (!keypoints.empty()) orb->compute(image_, keypoints, descriptors_);
  for (size_t k = 0; k < keypoints.size(); ++k) {
    const int i = keypoints[k].class_id;
    if (i < 0 || i >= static_cast<int>(points_.size())) continue;
    points_[i].has_descriptor = true;
    points_[i].descriptor = descriptors_.row(static_cast<int>(k));
  }
}

}  // namespace rovo
