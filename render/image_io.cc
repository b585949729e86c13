#include "render/image_io.h"

#include <signal.h>

#include <cerrno>
#include <filesystem>
#include <stdexcept>

#include "datasets/image_file.h"
#include "datasets/io.h"
#include "datasets/png_encode.h"
#include "rovo/version.h"

namespace rovo {
namespace fs = std::filesystem;

void WritePngRgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  WritePng8(path, width, height, 3, rgb, "rovo " ROVO_VERSION);
}

void WritePngGray8(const std::string& path, int width, int height, const std::vector<uint8_t>& gray) {
  WritePng8(path, width, height, 1, gray, "rovo " ROVO_VERSION);
}

void WritePngGray16(const std::string& path, int width, int height, const std::vector<uint16_t>& values) {
  if (width <= 0 || height <= 0 || values.size() != static_cast<size_t>(width) * height) {
    throw std::invalid_argument(path + ": " + std::to_string(values.size()) + " values for a " + std::to_string(width) +
                                "x" + std::to_string(height) + " image");
  }
  WriteFileAtomic(path, EncodePng(width, height, 1, 16, values.data(), "rovo " ROVO_VERSION));
}

void WriteExrFloat(const std::string& path, int width, int height, const std::vector<float>& values) {
  rovo::WriteExrFloat(path, width, height, values, "Z", "rovo " ROVO_VERSION);
}

void RemoveStaleTempFiles(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const size_t pos = name.rfind(".tmp.");
    if (pos == std::string::npos) continue;
    const std::string rest = name.substr(pos + 5);  // "<pid>.<n>"
    const size_t dot = rest.find('.');
    if (dot == std::string::npos) continue;
    long pid = 0;
    try {
      pid = std::stol(rest.substr(0, dot));
    } catch (const std::exception&) {
      continue;
    }
    if (pid <= 0) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // still running (or not ours)
    fs::remove(entry.path(), ec);
  }
}

}  // namespace rovo
