#pragma once
// Reading a dataset frame's images for the VO: one decoder call per view (colour images made gray,
// after undoing the lens's lateral colour when it is given), and a prefetcher that decodes the next
// frames on a thread of its own while the current one is processed.

#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/rig.h"
#include "vo/flat_field.h"
#include "vo/lateral_colour.h"

namespace rovo {

struct LoadedFrame {
  std::vector<cv::Mat> images;  // 8-bit gray, one per camera
  // Cameras whose image is missing or unreadable (their image is black: the back-end then loses the
  // frame or sees the other views only) and the message naming the file of each.
  std::vector<int> missing_cameras;
  std::string problems;
};

// What the VO undoes of a lens before it tracks: none by default.
struct LensCorrections {
  LateralColour lateral_colour;                // lateral_colour.h
  RelativeIllumination relative_illumination;  // flat_field.h
  std::string response = "srgb";               // the sensor's response curve, for the flat field
};

// Reads the frames of a dataset. A missing or unreadable file becomes a black image and is named in
// `problems`; an image of the wrong size throws, naming the file and dataset.json's field.
// PNG images take the fast path of png_gray.h; with lateral colour (lateral_colour.h), colour
// images are decoded in colour, corrected and then made gray (gray images are read as they are);
// with relative illumination the gray image gets its flat-field correction (flat_field.h).
class FrameReader {
 public:
  FrameReader(std::string dataset_dir, const Rig& rig, const LensCorrections& corrections = {});
  // The images of one frame. `parallel`: the views in parallel (TBB).
  LoadedFrame Load(int frame, bool parallel = true) const;

 private:
  cv::Mat ReadView(int camera, const std::string& path) const;
  std::string dataset_dir_;
  const Rig& rig_;
  std::vector<LateralColourCorrection> lateral_colour_;  // one per camera, or none
  std::vector<FlatFieldCorrection> flat_field_;          // one per camera, or none
};

// The lateral colour and relative illumination that dataset.json "optics" states for the dataset's
// lens, with its sensor's response curve (none without optics).
LensCorrections DatasetLensCorrections(const DatasetInfo& info);

// FrameReader(dataset_dir, rig).Load(frame, parallel): without lateral colour correction.
LoadedFrame LoadFrameImages(const std::string& dataset_dir, const Rig& rig, int frame, bool parallel = true);

// The dataset's static masks (dataset.json has_static_masks), one 8-bit image per camera, 0 =
// invalid; empty when the dataset has none. Throws naming the file when one is unreadable or of the
// wrong size.
std::vector<cv::Mat> LoadStaticMasks(const std::string& dataset_dir, const Rig& rig, bool has_static_masks);

// Decodes the frames ahead of the one being processed, on a thread of its own, at most `depth`
// frames ahead (a bounded queue): the decoding fills the cycles that the front-end's and the BA's
// less parallel stretches leave free, and a frame of slow decoding borrows from the frames before it.
// A frame's views are decoded one after the other there (no TBB: the prefetch thread does not take
// the pool's workers from the front-end). The images are exactly those of LoadFrameImages.
class ImagePrefetcher {
 public:
  // Frames [begin, end) are requested in order; end <= begin reads nothing. depth >= 1. `reader`
  // must outlive the prefetcher.
  ImagePrefetcher(const FrameReader& reader, int begin, int end, int depth = 2);
  ~ImagePrefetcher();
  ImagePrefetcher(const ImagePrefetcher&) = delete;
  ImagePrefetcher& operator=(const ImagePrefetcher&) = delete;
  // The images of `frame` (the next in order); rethrows its read error.
  LoadedFrame Get(int frame);

 private:
  struct Slot {
    int frame = 0;
    LoadedFrame loaded;
    std::exception_ptr error;
  };
  void Run();
  const FrameReader& reader_;
  int begin_, end_, depth_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Slot> ready_;
  bool stop_ = false;
  std::thread worker_;
};

}  // namespace rovo
