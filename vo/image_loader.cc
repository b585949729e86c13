#include "vo/image_loader.h"

#include <tbb/parallel_for.h>

#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "datasets/dataset.h"

namespace rovo {

LoadedFrame LoadFrameImages(const std::string& dataset_dir, const Rig& rig, int frame) {
  const int n = rig.NumCameras();
  LoadedFrame loaded;
  loaded.images.resize(n);
  std::vector<std::string> missing(n), wrong_size(n);
  tbb::parallel_for(0, n, [&](int j) {
    const RigCamera& cam = rig.cameras[j];
    const std::string path = ImagePath(dataset_dir, cam.name, frame);
    cv::Mat& image = loaded.images[j];
    image = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (image.empty()) {
      missing[j] = path + ": missing or unreadable";
      image = cv::Mat::zeros(cam.camera.height, cam.camera.width, CV_8UC1);
    } else if (image.cols != cam.camera.width || image.rows != cam.camera.height) {
      wrong_size[j] = path + ": image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                      " but dataset.json rig.cameras[" + cam.name + "] says " + std::to_string(cam.camera.width) + "x" +
                      std::to_string(cam.camera.height);
    }
  });
  for (int j = 0; j < n; ++j) {
    if (!wrong_size[j].empty()) throw std::runtime_error(wrong_size[j]);
    if (missing[j].empty()) continue;
    loaded.missing_cameras.push_back(j);
    loaded.problems += (loaded.problems.empty() ? "" : "; ") + missing[j];
  }
  return loaded;
}

std::vector<cv::Mat> LoadStaticMasks(const std::string& dataset_dir, const Rig& rig, bool has_static_masks) {
  std::vector<cv::Mat> masks;
  if (!has_static_masks) return masks;
  for (const RigCamera& cam : rig.cameras) {
    const std::string path = StaticMaskPath(dataset_dir, cam.name);
    cv::Mat mask = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (mask.empty())
      throw std::runtime_error(path + ": static mask missing or unreadable (dataset.json has_static_masks)");
    if (mask.cols != cam.camera.width || mask.rows != cam.camera.height) {
      throw std::runtime_error(path + ": static mask is " + std::to_string(mask.cols) + "x" +
                               std::to_string(mask.rows) + " but camera " + cam.name + " is " +
                               std::to_string(cam.camera.width) + "x" + std::to_string(cam.camera.height));
    }
    masks.push_back(mask);
  }
  return masks;
}

ImagePrefetcher::ImagePrefetcher(const std::string& dataset_dir, const Rig& rig, int begin, int end)
    : dataset_dir_(dataset_dir), rig_(rig), end_(end) {
  Start(begin);
}

ImagePrefetcher::~ImagePrefetcher() {
  if (next_.valid()) next_.wait();
}

LoadedFrame ImagePrefetcher::Get(int frame) {
  LoadedFrame loaded = next_.get();
  Start(frame + 1);
  return loaded;
}

void ImagePrefetcher::Start(int frame) {
  if (frame >= end_) return;
  next_ = std::async(std::launch::async, [this, frame] { return LoadFrameImages(dataset_dir_, rig_, frame); });
}

}  // namespace rovo
