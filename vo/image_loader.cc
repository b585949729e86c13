#include "vo/image_loader.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "datasets/dataset.h"
#include "vo/png_gray.h"

namespace rovo {

FrameReader::FrameReader(std::string dataset_dir, const Rig& rig, const LensCorrections& corrections)
    : dataset_dir_(std::move(dataset_dir)), rig_(rig) {
  for (const RigCamera& cam : rig.cameras) {
    if (corrections.lateral_colour.Any()) lateral_colour_.emplace_back(cam.camera, corrections.lateral_colour);
    if (corrections.relative_illumination.Any())
      flat_field_.emplace_back(cam.camera, corrections.relative_illumination, corrections.response);
  }
}

cv::Mat FrameReader::ReadView(int camera, const std::string& path) const {
  cv::Mat image;
  if (lateral_colour_.empty()) {
    image = ReadGrayImage(path);
  } else {
    image = ReadImageAnyColour(path);  // 8-bit; gray stays gray, alpha is dropped
    const LateralColourCorrection& correction = lateral_colour_[static_cast<size_t>(camera)];
    if (image.channels() == 3 && image.cols == correction.width() && image.rows == correction.height())
      image = correction.ToGray(image);
  }
  const bool right_size = image.cols == rig_.cameras[camera].camera.width &&
                          image.rows == rig_.cameras[camera].camera.height;  // else Load names it
  if (!flat_field_.empty() && image.type() == CV_8UC1 && right_size)
    flat_field_[static_cast<size_t>(camera)].Apply(&image);
  return image;
}

LoadedFrame FrameReader::Load(int frame, bool parallel) const {
  const int n = rig_.NumCameras();
  LoadedFrame loaded;
  loaded.images.resize(n);
  std::vector<std::string> missing(n), wrong_size(n);
  const auto load_view = [&](int j) {
    const RigCamera& cam = rig_.cameras[j];
    const std::string path = ImagePath(dataset_dir_, cam.name, frame);
    cv::Mat& image = loaded.images[j];
    image = ReadView(j, path);
    if (image.empty()) {
      missing[j] = path + ": missing or unreadable";
      image = cv::Mat::zeros(cam.camera.height, cam.camera.width, CV_8UC1);
    } else if (image.cols != cam.camera.width || image.rows != cam.camera.height) {
      wrong_size[j] = path + ": image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                      " but dataset.json rig.cameras[" + cam.name + "] says " + std::to_string(cam.camera.width) + "x" +
                      std::to_string(cam.camera.height);
    }
  };
  if (parallel) {
    tbb::parallel_for(0, n, load_view);
  } else {
    for (int j = 0; j < n; ++j) load_view(j);
  }
  for (int j = 0; j < n; ++j) {
    if (!wrong_size[j].empty()) throw std::runtime_error(wrong_size[j]);
    if (missing[j].empty()) continue;
    loaded.missing_cameras.push_back(j);
    loaded.problems += (loaded.problems.empty() ? "" : "; ") + missing[j];
  }
  return loaded;
}

LensCorrections DatasetLensCorrections(const DatasetInfo& info) {
  LensCorrections c;
  if (!info.optics) return c;
  c.lateral_colour = {info.optics->lateral_ca_red, info.optics->lateral_ca_blue};
  c.relative_illumination = {info.optics->falloff_angle_scale, info.optics->rim_illumination};
  if (info.sensor) c.response = info.sensor->response;
  return c;
}

LoadedFrame LoadFrameImages(const std::string& dataset_dir, const Rig& rig, int frame, bool parallel) {
  return FrameReader(dataset_dir, rig).Load(frame, parallel);
}

std::vector<cv::Mat> LoadStaticMasks(const std::string& dataset_dir, const Rig& rig, bool has_static_masks) {
  std::vector<cv::Mat> masks;
  if (!has_static_masks) return masks;
  for (const RigCamera& cam : rig.cameras) {
    const std::string path = StaticMaskPath(dataset_dir, cam.name);
    cv::Mat mask = ReadGrayImage(path);
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

ImagePrefetcher::ImagePrefetcher(const FrameReader& reader, int begin, int end, int depth)
    : reader_(reader), begin_(begin), end_(end), depth_(std::max(1, depth)) {
  if (end_ > begin_) worker_ = std::thread([this] { Run(); });
}

ImagePrefetcher::~ImagePrefetcher() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void ImagePrefetcher::Run() {
  for (int frame = begin_; frame < end_; ++frame) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return stop_ || static_cast<int>(ready_.size()) < depth_; });
      if (stop_) return;
    }
    Slot slot;
    slot.frame = frame;
    try {
      slot.loaded = reader_.Load(frame, /*parallel=*/false);
    } catch (...) {
      slot.error = std::current_exception();
    }
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      ready_.push_back(std::move(slot));
    }
    changed_.notify_all();
  }
}

LoadedFrame ImagePrefetcher::Get(int frame) {
  Slot slot;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !ready_.empty(); });
    slot = std::move(ready_.front());
    ready_.pop_front();
  }
  changed_.notify_all();
  if (slot.error) std::rethrow_exception(slot.error);
  if (slot.frame != frame) {
    throw std::logic_error("ImagePrefetcher: frame " + std::to_string(frame) + " requested, frame " +
                           std::to_string(slot.frame) + " is next");
  }
  return std::move(slot.loaded);
}

}  // namespace rovo
