#pragma once
// Reading a dataset frame's images for the VO: one decoder call per view, in parallel, and a
// prefetcher that decodes frame f + 1 on a second thread while frame f is processed.

#include <future>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "datasets/rig.h"

namespace rovo {

struct LoadedFrame {
  std::vector<cv::Mat> images;  // 8-bit gray, one per camera
  // Cameras whose image is missing or unreadable (their image is black: the back-end then loses the
  // frame or sees the other views only) and the message naming the file of each.
  std::vector<int> missing_cameras;
  std::string problems;
};

// The images of one frame. A missing or unreadable file becomes a black image and is named in
// `problems`; an image of the wrong size throws, naming the file and dataset.json's field.
LoadedFrame LoadFrameImages(const std::string& dataset_dir, const Rig& rig, int frame);

// The dataset's static masks (dataset.json has_static_masks), one 8-bit image per camera, 0 =
// invalid; empty when the dataset has none. Throws naming the file when one is unreadable or of the
// wrong size.
std::vector<cv::Mat> LoadStaticMasks(const std::string& dataset_dir, const Rig& rig, bool has_static_masks);

// Reads frame f+1's images on a second thread while frame f is processed (PNG decoding costs about
// 30 CPU-ms per full-size view; it overlaps the front-end's and the BA's less parallel stretches).
class ImagePrefetcher {
 public:
  // Frames [begin, end) are requested in order; end <= begin reads nothing.
  ImagePrefetcher(const std::string& dataset_dir, const Rig& rig, int begin, int end);
  ~ImagePrefetcher();
  ImagePrefetcher(const ImagePrefetcher&) = delete;
  ImagePrefetcher& operator=(const ImagePrefetcher&) = delete;
  // The images of `frame`; starts reading the next one. Rethrows a read error.
  LoadedFrame Get(int frame);

 private:
  void Start(int frame);
  std::string dataset_dir_;
  const Rig& rig_;
  int end_;
  std::future<LoadedFrame> next_;
};

}  // namespace rovo
