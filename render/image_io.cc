#include "render/image_io.h"

#include <OpenImageIO/imageio.h>
#include <signal.h>

#include <cerrno>
#include <filesystem>
#include <stdexcept>

#include "datasets/io.h"
#include "render/png_encode.h"
#include "rovo/version.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

void WriteImage(const std::string& path, const char* format, const OIIO::ImageSpec& spec, const void* pixels) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) EnsureWritableDir(parent.string());
  const std::string tmp = TempPathFor(path);
  auto out = OIIO::ImageOutput::create(format);
  if (!out) throw std::runtime_error(path + ": OpenImageIO has no '" + format + "' writer");
  if (!out->open(tmp, spec) || !out->write_image(spec.format, pixels) || !out->close()) {
    const std::string message = out->geterror();
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error(path + ": cannot write image: " + message);
  }
  CommitTempFile(tmp, path);
}

// Encodes `pixels` (width x height x channels samples) as PNG and writes it atomically.
template <typename T>
void WritePng(const std::string& path, int width, int height, int channels, const std::vector<T>& pixels) {
  if (width <= 0 || height <= 0 || pixels.size() != static_cast<size_t>(width) * height * channels) {
    throw std::invalid_argument(path + ": " + std::to_string(pixels.size()) + " samples for a " +
                                std::to_string(width) + "x" + std::to_string(height) + " image of " +
                                std::to_string(channels) + " channel(s)");
  }
  WriteFileAtomic(path, EncodePng(width, height, channels, 8 * sizeof(T), pixels.data(), "rovo " ROVO_VERSION));
}

}  // namespace

void WritePngRgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  WritePng(path, width, height, 3, rgb);
}

void WritePngGray8(const std::string& path, int width, int height, const std::vector<uint8_t>& gray) {
  WritePng(path, width, height, 1, gray);
}

void WritePngGray16(const std::string& path, int width, int height, const std::vector<uint16_t>& values) {
  WritePng(path, width, height, 1, values);
}

void WriteExrFloat(const std::string& path, int width, int height, const std::vector<float>& values) {
  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Z"};
  spec.attribute("compression", "zip");
  spec.attribute("Software", "rovo " ROVO_VERSION);
  // A fixed DateTime (OpenImageIO would stamp the wall clock) keeps reruns byte-identical.
  spec.attribute("DateTime", "1970:01:01 00:00:00");
  WriteImage(path, "openexr", spec, values.data());
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
