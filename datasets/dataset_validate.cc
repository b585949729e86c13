#include "datasets/dataset_validate.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include "datasets/dataset.h"
#include "datasets/dataset_internal.h"
#include "datasets/image_file.h"
#include "datasets/io.h"
#include "datasets/json_check.h"

namespace rovo {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Image header check (the header only).
void CheckImage(const std::string& path, const std::string& field, int width, int height, int max_channels,
                std::vector<ValidationIssue>* issues) {
  ImageHeader header;
  try {
    header = ReadImageHeader(path);
  } catch (const std::runtime_error& e) {
    std::string why = e.what();
    if (why.rfind(path + ": ", 0) == 0) why = why.substr(path.size() + 2);
    issues->push_back({path, field, "unreadable image: " + why});
    return;
  }
  if (header.width != width || header.height != height) {
    issues->push_back({path, field,
                       "image is " + std::to_string(header.width) + "x" + std::to_string(header.height) +
                           " but the rig camera is " + std::to_string(width) + "x" + std::to_string(height)});
  }
  if (header.channels < 1 || header.channels > max_channels) {
    issues->push_back({path, field,
                       "image has " + std::to_string(header.channels) + " channels (expected 1.." +
                           std::to_string(max_channels) + ")"});
  }
}

// Frame numbers of files named NNNNNN.<extension> in `folder`; other names go to `others`.
std::set<int> FrameFilesIn(const std::string& folder, const std::string& extension, std::vector<std::string>* others) {
  std::set<int> frames;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::string suffix = "." + extension;
    bool is_frame = name.size() == 6 + suffix.size() && name.compare(6, suffix.size(), suffix) == 0;
    for (int i = 0; is_frame && i < 6; ++i) is_frame = std::isdigit(static_cast<unsigned char>(name[i]));
    if (is_frame) {
      frames.insert(std::stoi(name.substr(0, 6)));
    } else if (others) {
      others->push_back(name);
    }
  }
  return frames;
}

// static_masks/<cam>.png of a dataset that declares them: present, one channel, the camera's size.
void CheckStaticMasks(const std::string& dir, const DatasetInfo& info, std::vector<ValidationIssue>* issues) {
  for (const RigCamera& rc : info.rig.cameras) {
    const std::string path = StaticMaskPath(dir, rc.name);
    if (!fs::exists(path)) {
      issues->push_back(
          {path, "file", "missing static mask of camera " + rc.name + " (dataset.json has_static_masks)"});
    } else {
      CheckImage(path, "header", rc.camera.width, rc.camera.height, 1, issues);
    }
  }
}

// exposure.csv of a dataset whose dataset.json has /sensor: present, one row per frame and camera.
void CheckExposureRecord(const std::string& dir, const DatasetInfo& info, std::vector<ValidationIssue>* issues) {
  const std::string path = ExposurePath(dir);
  if (!fs::exists(path)) {
    issues->push_back({path, "file", "missing exposure record of every frame and camera (dataset.json has /sensor)"});
    return;
  }
  try {
    ParseExposureCsv(ReadFile(path), path, info.frame_count, info.rig, issues);
  } catch (const std::exception& e) {
    issues->push_back({path, "file", e.what()});
  }
}

// groundtruth.tum: every line parses, unit quaternions, increasing timestamps; returns the number
// of lines (-1 when not read).
int CheckGroundTruth(const std::string& dir, bool json_ok, const DatasetInfo& info,
                     std::vector<ValidationIssue>* issues) {
  const std::string gt_path = GroundTruthPath(dir);
  int gt_lines = -1;
  if (json_ok && !info.has_ground_truth) {
    // A capture without ground truth: nothing to check (a file present is ignored).
  } else if (!fs::exists(gt_path)) {
    issues->push_back({gt_path, "file", "missing ground truth (world_from_rig per frame, TUM format)"});
  } else {
    try {
      std::vector<std::string> errors;
      const std::vector<TumLine> lines = ParseTumText(ReadFile(gt_path), gt_path, &errors);
      for (const std::string& e : errors) {
        // "<path>: line N: message" -> field "line N".
        const size_t a = e.find(": line ");
        const size_t b = a == std::string::npos ? std::string::npos : e.find(": ", a + 2);
        if (b == std::string::npos) {
          issues->push_back({gt_path, "line", e});
        } else {
          issues->push_back({gt_path, e.substr(a + 2, b - a - 2), e.substr(b + 2)});
        }
      }
      double previous_t = -std::numeric_limits<double>::infinity();
      for (const TumLine& line : lines) {
        const std::string field = "line " + std::to_string(line.line_number);
        const double qn = std::sqrt(line.values[4] * line.values[4] + line.values[5] * line.values[5] +
                                    line.values[6] * line.values[6] + line.values[7] * line.values[7]);
        if (!(std::abs(qn - 1.0) <= 1e-6)) {
          issues->push_back(
              {gt_path, field,
               "quaternion (qx qy qz qw) norm " + JsonChecker::Format(qn) + " is not 1 (tolerance 1e-6)"});
        }
        if (!(line.values[0] > previous_t)) {
          issues->push_back({gt_path, field,
                             "timestamp " + JsonChecker::Format(line.values[0]) + " is not after the previous one " +
                                 JsonChecker::Format(previous_t)});
        }
        previous_t = line.values[0];
      }
      gt_lines = static_cast<int>(lines.size() + errors.size());
    } catch (const std::exception& e) {
      issues->push_back({gt_path, "file", e.what()});
    }
  }
  return gt_lines;
}

// Images (and depth/masks when declared): present, readable, the rig camera's size; no extras.
void CheckImageLayers(const std::string& dir, const DatasetInfo& info, std::vector<ValidationIssue>* issues) {
  struct Layer {
    bool enabled;
    std::string folder_prefix;  // "" for images, "depth/" or "masks/"
    const char* extension;
    int max_channels;
    std::string (*path)(const std::string&, const std::string&, int);
  };
  const int image_channels = info.sensor && info.sensor->grayscale ? 1 : 4;  // a grayscale sensor: 1 channel
  const Layer layers[3] = {{true, "", "png", image_channels, &ImagePath},
                           {info.has_depth, "depth/", "exr", 1, &DepthPath},
                           {info.has_masks, "masks/", "png", 1, &MaskPath}};
  for (const Layer& layer : layers) {
    if (!layer.enabled) continue;
    for (const RigCamera& rc : info.rig.cameras) {
      if (rc.name.empty() || rc.camera.width <= 0 || rc.camera.height <= 0) continue;  // reported above
      const std::string folder = (fs::path(dir) / (layer.folder_prefix + rc.name)).string();
      if (!fs::is_directory(folder)) {
        issues->push_back({folder, "folder", "missing image folder of camera " + rc.name});
        continue;
      }
      const std::set<int> present = FrameFilesIn(folder, layer.extension, nullptr);
      int missing = 0;
      for (int frame = 0; frame < info.frame_count; ++frame) {
        const std::string path = layer.path(dir, rc.name, frame);
        if (!present.count(frame)) {
          // List the first few; summarise the rest so a missing folder does not flood the output.
          if (++missing <= 5) issues->push_back({path, "file", "missing (frame " + std::to_string(frame) + ")"});
          continue;
        }
        CheckImage(path, "header", rc.camera.width, rc.camera.height, layer.max_channels, issues);
      }
      if (missing > 5) {
        issues->push_back({folder, "files", std::to_string(missing) + " frames missing in total"});
      }
      for (int frame : present) {
        if (info.frame_count > 0 && frame >= info.frame_count) {  // 0: /frame_count itself was bad
          issues->push_back({layer.path(dir, rc.name, frame), "file",
                             "frame " + std::to_string(frame) + " beyond dataset.json /frame_count " +
                                 std::to_string(info.frame_count)});
        }
      }
    }
  }
}

}  // namespace

std::vector<ValidationIssue> ValidateDataset(const std::string& dir) {
  std::vector<ValidationIssue> issues;
  if (!fs::is_directory(dir)) {
    issues.push_back({dir, "/", "not a folder"});
    return issues;
  }
  const std::string json_path = DatasetJsonPath(dir);
  DatasetInfo info;
  bool json_ok = false;
  try {
    const json root = ReadJsonFile(json_path);
    JsonChecker check(json_path, &issues);
    info = ParseDatasetJson(check, root);
    json_ok = true;
  } catch (const std::exception& e) {
    const std::string message = StripPrefix(e.what(), json_path + ": ");
    issues.push_back({json_path, "/", message == e.what() ? "cannot read JSON: " + message : message});
  }

  // groundtruth.tum: one pose per frame.
  const std::string gt_path = GroundTruthPath(dir);
  const int gt_lines = CheckGroundTruth(dir, json_ok, info, &issues);
  if (!json_ok) return issues;
  if (gt_lines >= 0 && info.frame_count > 0 && gt_lines != info.frame_count) {
    issues.push_back(
        {gt_path, "lines",
         std::to_string(gt_lines) + " poses but dataset.json /frame_count is " + std::to_string(info.frame_count)});
  }

  if (json_ok && info.has_static_masks) CheckStaticMasks(dir, info, &issues);
  if (json_ok && info.sensor) CheckExposureRecord(dir, info, &issues);
  CheckImuStreams(dir, info, &issues);

  CheckImageLayers(dir, info, &issues);
  return issues;
}

}  // namespace rovo
