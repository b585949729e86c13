// `rovo bench vo --floor` (vo_floor.h): the front-end against the bare OpenCV calls of the same work.
#include "eval/bench/vo_floor.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <ctime>
#include <memory>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/dataset_cameras.h"
#include "datasets/progress.h"
#include "eval/bench/vo_bench.h"
#include "vo/frontend.h"
#include "vo/image_loader.h"
#include "vo/opencv_threads.h"

namespace rovo {
namespace {

double CpuMs(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

enum FloorStage { kWarp, kTrack, kDetect, kMatch, kStages };
using StageMs = std::array<double, kStages>;

// One view's state of the floor: the previous frame's pyramid and points.
struct FloorView {
  std::vector<cv::Mat> pyramid, previous_pyramid;
  std::vector<cv::Point2f> points;
  cv::Mat descriptors;
};

// The bare OpenCV calls of the front-end, with its parameters, on one thread.
class Floor {
 public:
  Floor(const std::vector<HybridProjection>& projections, const std::vector<std::pair<int, int>>& pairs,
        const FrontendOptions& options)
      : projections_(projections),
        pairs_(pairs),
        options_(options),
        views_(projections.size()),
        orb_(cv::ORB::create(500, 1.2f, 1, 19, 0, 2, cv::ORB::HARRIS_SCORE, 31)) {}

  // Thread CPU ms by stage for one frame.
  StageMs Process(const std::vector<cv::Mat>& fisheye) {
    StageMs ms{};
    for (size_t i = 0; i < views_.size(); ++i) ProcessView(fisheye[i], projections_[i], &views_[i], &ms);
    double start = CpuMs(CLOCK_THREAD_CPUTIME_ID);
    for (const auto& [a, b] : pairs_) MatchPair(a, b);
    ms[kMatch] += CpuMs(CLOCK_THREAD_CPUTIME_ID) - start;
    return ms;
  }

 private:
  void ProcessView(const cv::Mat& fisheye, const HybridProjection& projection, FloorView* view, StageMs* ms) {
    double start = CpuMs(CLOCK_THREAD_CPUTIME_ID);
    const auto lap = [&](FloorStage stage) {
      const double now = CpuMs(CLOCK_THREAD_CPUTIME_ID);
      (*ms)[stage] += now - start;
      start = now;
    };
    // cv::remap in the front-end's bands of rows (HybridProjection::kWarpBandRows).
    cv::Mat warped(projection.height(), projection.width(), fisheye.type());
    for (int first = 0; first < warped.rows; first += HybridProjection::kWarpBandRows) {
      const int last = std::min(first + HybridProjection::kWarpBandRows, warped.rows);
      cv::Mat band = warped.rowRange(first, last);
      cv::remap(fisheye, band, projection.map_fixed().rowRange(first, last),
                projection.map_frac().rowRange(first, last), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
    }
    lap(kWarp);
    const cv::Size window(options_.klt_window_px, options_.klt_window_px);
    std::swap(view->pyramid, view->previous_pyramid);
    cv::buildOpticalFlowPyramid(warped, view->pyramid, window, options_.klt_levels);
    if (!view->points.empty()) Track(window, view);
    lap(kTrack);
    std::vector<cv::KeyPoint> corners;
    cv::FAST(warped, corners, options_.fast_threshold, true, cv::FastFeatureDetector::TYPE_9_16);
    cv::KeyPointsFilter::retainBest(corners, options_.target_features_per_view);
    for (cv::KeyPoint& kp : corners) {
      kp.size = 31.0f;
      kp.angle = 0.0f;
    }
    orb_->compute(warped, corners, view->descriptors);
    view->points.clear();
    for (const cv::KeyPoint& kp : corners) view->points.push_back(kp.pt);
    corners_.resize(views_.size());
    corners_[view - views_.data()] = std::move(corners);
    lap(kDetect);
  }

  // Forward LK of the previous frame's points, then the backward pass from scratch.
  void Track(cv::Size window, FloorView* view) const {
    const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, options_.klt_max_iterations,
                                    options_.klt_epsilon_px);
    std::vector<cv::Point2f> forward, backward, ok;
    std::vector<uint8_t> status, back_status;
    cv::calcOpticalFlowPyrLK(view->previous_pyramid, view->pyramid, view->points, forward, status, cv::noArray(),
                             window, options_.klt_levels, criteria);
    for (size_t k = 0; k < forward.size(); ++k) {
      if (status[k]) ok.push_back(forward[k]);
    }
    if (!ok.empty()) {
      cv::calcOpticalFlowPyrLK(view->pyramid, view->previous_pyramid, ok, backward, back_status, cv::noArray(), window,
                               options_.klt_levels, criteria);
    }
  }

  // k = 2 Hamming matching both ways between a's right half and b's left half (a's right neighbour).
  void MatchPair(int a, int b) {
    const auto half = [&](int view, bool right) {
      const double middle = 0.5 * projections_[view].width();
      cv::Mat rows;
      for (size_t k = 0; k < corners_[view].size(); ++k) {
        if ((corners_[view][k].pt.x >= middle) == right)
          rows.push_back(views_[view].descriptors.row(static_cast<int>(k)));
      }
      return rows;
    };
    const cv::Mat da = half(a, true), db = half(b, false);
    if (da.empty() || db.empty()) return;
    std::vector<std::vector<cv::DMatch>> ab, ba;
    matcher_.knnMatch(da, db, ab, 2);
    matcher_.knnMatch(db, da, ba, 2);
  }

  const std::vector<HybridProjection>& projections_;
  const std::vector<std::pair<int, int>>& pairs_;
  FrontendOptions options_;
  std::vector<FloorView> views_;
  std::vector<std::vector<cv::KeyPoint>> corners_;
  cv::Ptr<cv::ORB> orb_;
  cv::BFMatcher matcher_{cv::NORM_HAMMING};
};

// The pairs of neighbouring views the front-end matches: (camera, its right neighbour), each once.
std::vector<std::pair<int, int>> NeighbourPairs(const std::vector<HybridLayout>& layouts) {
  std::vector<std::pair<int, int>> pairs;
  std::set<std::pair<int, int>> seen;
  for (int i = 0; i < static_cast<int>(layouts.size()); ++i) {
    const int j = layouts[i].right_neighbour;
    if (j == i || !seen.insert({std::min(i, j), std::max(i, j)}).second) continue;
    pairs.emplace_back(i, j);
  }
  return pairs;
}

void PrintFloorTable(const StageMs& frontend, const StageMs& floor, int frames, int threads) {
  const char* names[kStages] = {"warp", "track (pyramid + LK)", "detect + describe", "match"};
  std::printf("rovo bench vo --floor: %d frames; front-end on %d thread%s (process CPU), floor on one thread\n", frames,
              threads, threads == 1 ? "" : "s");
  std::printf(
      "| stage                | front-end CPU ms/frame | floor CPU ms/frame | ratio |\n"
      "|----------------------|-----------------------:|-------------------:|------:|\n");
  double total_frontend = 0, total_floor = 0;
  for (int k = 0; k < kStages; ++k) {
    const double a = frontend[k] / frames, b = floor[k] / frames;
    total_frontend += a;
    total_floor += b;
    std::printf("| %-20s | %22.2f | %18.2f | %5.2f |\n", names[k], a, b, b > 0 ? a / b : 0.0);
  }
  std::printf("| %-20s | %22.2f | %18.2f | %5.2f |\n", "total", total_frontend, total_floor,
              total_floor > 0 ? total_frontend / total_floor : 0.0);
  std::printf("front-end / floor: %.3f (target <= 1.1)\n", total_floor > 0 ? total_frontend / total_floor : 0.0);
}

}  // namespace

void RunVoFloorBenchmark(VoOptions options) {
  if (options.io.out_dir.empty()) options.io.out_dir = options.io.dataset_dir + "_bench_vo_run";  // not written
  options.Check();
  const DatasetInfo full = ReadDatasetInfo(options.io.dataset_dir);
  const std::vector<int> cameras = VoCameraIndices(options.io.cameras, full.rig);
  const DatasetInfo info = static_cast<int>(cameras.size()) == full.rig.NumCameras()
                               ? full
                               : SelectDatasetCameras(full, cameras, "bench vo --floor: --cameras");
  const int begin = options.io.frames.begin;
  const int end = options.io.frames.end < 0 ? info.frame_count : std::min(options.io.frames.end, info.frame_count);
  if (begin < 0 || begin >= end) throw std::invalid_argument("bench vo --floor: --frames is an empty range");
  const int threads =
      options.io.threads > 0 ? options.io.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  std::vector<std::vector<cv::Mat>> images;
  Progress progress("bench vo --floor: decoding images", end - begin, "frames", options.io.quiet);
  for (int frame = begin; frame < end; ++frame) {
    images.push_back(LoadFrameImages(options.io.dataset_dir, info.rig, frame).images);
    progress.Add();
  }
  progress.Finish();
  const double reference_before_ms = MachineReferenceWarpMs(threads);
  Frontend frontend(info.rig, options.frontend);
  frontend.SetStaticMasks(LoadStaticMasks(options.io.dataset_dir, info.rig, info.has_static_masks));
  std::vector<HybridProjection> projections;
  projections.reserve(static_cast<size_t>(info.rig.NumCameras()));
  for (int i = 0; i < info.rig.NumCameras(); ++i) projections.push_back(frontend.projection(i));
  const std::vector<std::pair<int, int>> pairs = NeighbourPairs(ComputeHybridLayouts(info.rig));
  Floor floor(projections, pairs, options.frontend);
  StageMs frontend_ms{}, floor_ms{};
  const ScopedOpenCvThreads serial_opencv;
  for (const std::vector<cv::Mat>& frame_images : images) {
    const FrontendFrame f = frontend.Process(frame_images);  // frames alternate: both see the same load
    const StageMs stages = {f.cpu_ms_warp, f.cpu_ms_track, f.cpu_ms_detect, f.cpu_ms_match};
    const StageMs floor_stages = floor.Process(frame_images);
    for (int k = 0; k < kStages; ++k) {
      frontend_ms[k] += stages[k];
      floor_ms[k] += floor_stages[k];
    }
  }
  const double reference_after_ms = MachineReferenceWarpMs(threads);
  PrintFloorTable(frontend_ms, floor_ms, end - begin, threads);
  std::printf(
      "machine reference: one full-size hybrid warp by cv::remap per core on %d core%s at once: %.2f ms before, %.2f "
      "ms after\n",
      threads, threads == 1 ? "" : "s", reference_before_ms, reference_after_ms);
}

}  // namespace rovo
