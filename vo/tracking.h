#pragma once
// Intra-view feature processing (ROVO paper IV-B): FAST corners (ORB's detector) picked strongest
// first under a minimum-distance constraint so they cover the image uniformly; pyramidal KLT
// (cv::calcOpticalFlowPyrLK) from the previous frame, started at the last displacement for tracks
// seen before, with an independent forward-backward check; re-detection to
// keep a target count; ORB descriptors (oriented BRIEF, orientation by the intensity centroid of a
// radius-15 disc) recomputed on every point every frame so that inter-view matching can use them.
//
// Works on any 8-bit gray image with a validity mask: the hybrid-warped views, or (for the
// projection study) the raw fisheye images.

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

namespace rovo {

struct TrackerOptions {
  int target_features = 600;  // per view; re-detect when fewer are tracked
  // At most this many new detections per frame while the view has tracks (0: no limit, fill to
  // target_features); most fresh detections die at once (docs/design-notes.md), so a limit saves
  // tracking work. A view without tracks (first frame, after a loss) still fills up.
  int max_new_per_frame = 0;
  float min_feature_distance_px = 12.0f;  // between any two features (detections and tracks)
  int fast_threshold = 12;                // FAST-9 intensity threshold
  int klt_window_px = 15;                 // KLT window side (FrontendOptions explains the choice)
  int klt_levels = 3;                     // pyramid levels above the base
  int klt_max_iterations = 20;            // LK iterations per pyramid level (at most)
  float klt_epsilon_px = 0.03f;           // LK stops a level when its update is below this (pixels)
  // Forward-backward check: the backward pass tracks the forward result back into the previous
  // image from scratch (all levels, no initial guess), and the track is kept when it lands within
  // this distance of where it started (FrontendOptions explains the value); a backward pass from the
  // known start would let gross forward errors pass (docs/design-notes.md).
  float max_forward_backward_px = 0.3f;
  // The forward pass of a track tracked before starts at its position plus its last displacement
  // (constant image velocity) with klt_predicted_levels levels; a track this loses (LK failure or
  // round trip) is tracked again from its position with all klt_levels. New tracks always use all
  // levels. false: every track uses all levels from its position.
  bool klt_predict_flow = true;
  int klt_predicted_levels = 0;
  int border_px = 20;  // features keep this distance from invalid pixels and image edges (ORB patch)
  // ORB descriptors at angle 0 (upright BRIEF) instead of at the intensity-centroid orientation;
  // angle_deg is still computed (the inter-view orientation filter). Rectified-like views agree on
  // "up", so they need no rotation invariance; raw fisheye views do not agree.
  bool upright_descriptors = false;
  void Check() const;  // throws std::invalid_argument naming the field
};

struct TrackedPoint {
  uint64_t track_id = 0;
  cv::Point2f px;
  int age = 0;          // frames tracked in this view (0 = detected this frame)
  cv::Point2f flow;     // displacement in the last Track (valid when age > 0)
  float angle_deg = 0;  // ORB orientation (intensity centroid), degrees in [0, 360)
  bool has_descriptor = false;
  cv::Mat descriptor;  // 1x32 CV_8U (ORB), a view into ViewTracker's descriptor matrix
};

class ViewTracker {
 public:
  explicit ViewTracker(const TrackerOptions& options = {});

  // Tracks the previous points into `image` (8-bit gray) and drops the lost ones. `mask` (CV_8U,
  // 255 = valid) is the image's validity area. Returns the number of points kept. The first call
  // only stores the image.
  int Track(const cv::Mat& image, const cv::Mat& mask);
  // Detects new points (ids from `next_id`) until target_features, then computes orientation and
  // descriptors for all points. Call after Track on the same image.
  void DetectAndDescribe(const std::function<uint64_t()>& next_id);

  std::vector<TrackedPoint>& points() { return points_; }
  const std::vector<TrackedPoint>& points() const { return points_; }
  const cv::Mat& image() const { return image_; }
  // Replaces the stored image (and the points), e.g. after the warp maps were rebuilt.
  void ResetImage(const cv::Mat& image, const cv::Mat& mask, std::vector<TrackedPoint> points);
  void Clear();

 private:
  TrackerOptions options_;
  cv::Mat image_, detect_mask_;
  // KLT pyramids (BuildPyrLkPyramid) of the current image and a spare whose buffers the next
  // frame's pyramid reuses: each image's pyramid is built once and serves the forward pass of the
  // next frame and the backward pass of this one.
  std::vector<cv::Mat> pyramid_, spare_pyramid_;
  std::vector<TrackedPoint> points_;
  cv::Mat descriptors_;
};

// ORB orientation of the patch around `px` (intensity centroid over a radius-15 disc), degrees in
// [0, 360). The patch must lie inside the image.
float IntensityCentroidAngleDeg(const cv::Mat& image, cv::Point2f px);

// Hamming distance of two 1x32 CV_8U ORB descriptors.
int HammingDistance(const cv::Mat& a, const cv::Mat& b);

// Points per PyrLk call in PyrLkInChunks.
constexpr int kLkChunkPoints = 64;
// cv::calcOpticalFlowPyrLK of `from` into `to` (which holds the starts when flags has
// cv::OPTFLOW_USE_INITIAL_FLOW, and must then be as long as `from`), in chunks of kLkChunkPoints points
// under TBB, isolated (a thread waiting for its chunks takes no other work). LK tracks every point on its
// own, so positions and status are those of one call; the chunks let an idle worker take part. Each chunk
// goes to PyrLk (vo/pyr_lk.h): the same results, computed in AVX2 where it applies.
void PyrLkInChunks(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
                   const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>* to, std::vector<uint8_t>* status,
                   cv::Size window, int levels, const cv::TermCriteria& criteria, int flags);

}  // namespace rovo
