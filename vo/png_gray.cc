#include "vo/png_gray.h"

#include <libdeflate.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "datasets/image_file.h"

namespace rovo {
namespace {

constexpr std::array<uint8_t, 8> kSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
// Larger images go to libpng (datasets/image_file.h, whose own limits then apply).
constexpr uint64_t kMaxPixels = uint64_t{1} << 28;

uint32_t ReadBe32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

bool ChunkIs(const uint8_t* type, const char* name) { return std::memcmp(type, name, 4) == 0; }

// Ancillary chunks that do not change how libpng and OpenCV turn the pixels into gray.
bool HarmlessAncillary(const uint8_t* type) {
  for (const char* name : {"tEXt", "zTXt", "iTXt", "oFFs", "pHYs", "tIME"}) {
    if (ChunkIs(type, name)) return true;
  }
  return false;
}

struct PngLayout {
  int width = 0, height = 0, channels = 0;  // channels: 1 (gray) or 3 (RGB)
  std::vector<uint8_t> zlib_stream;         // the IDAT chunks' data, concatenated
};

// IHDR of the handled kind: 8-bit gray or RGB, deflate, adaptive filtering, no interlace.
bool ParseHeader(const uint8_t* data, uint32_t length, PngLayout* png) {
  if (length != 13) return false;
  const uint32_t width = ReadBe32(data), height = ReadBe32(data + 4);
  const uint8_t depth = data[8], colour = data[9], compression = data[10], filter = data[11], interlace = data[12];
  if (width == 0 || height == 0 || width > 65535 || height > 65535 || uint64_t{width} * height > kMaxPixels) {
    return false;
  }
  if (depth != 8 || (colour != 0 && colour != 2) || compression != 0 || filter != 0 || interlace != 0) return false;
  png->width = static_cast<int>(width);
  png->height = static_cast<int>(height);
  png->channels = colour == 0 ? 1 : 3;
  return true;
}

// Walks the chunks (checking every CRC): the header and the image data, or false when the file is
// not of the handled kind or is damaged.
bool ParseChunks(const uint8_t* data, size_t size, PngLayout* png) {
  if (size < kSignature.size() || std::memcmp(data, kSignature.data(), kSignature.size()) != 0) return false;
  size_t at = kSignature.size();
  bool header = false, in_idat = false, idat_done = false;
  while (at + 12 <= size) {
    const uint32_t length = ReadBe32(data + at);
    if (length > size - at - 12) return false;
    const uint8_t* type = data + at + 4;
    const uint8_t* body = type + 4;
    if (libdeflate_crc32(0, type, length + 4) != ReadBe32(body + length)) return false;
    at += 12 + size_t{length};
    if (!header) {
      if (!ChunkIs(type, "IHDR") || !ParseHeader(body, length, png)) return false;
      header = true;
    } else if (ChunkIs(type, "IDAT")) {
      if (idat_done) return false;  // IDAT chunks must be consecutive
      in_idat = true;
      png->zlib_stream.insert(png->zlib_stream.end(), body, body + length);
    } else if (ChunkIs(type, "IEND")) {
      return in_idat || idat_done;
    } else if (HarmlessAncillary(type)) {
      idat_done = idat_done || in_idat;
      in_idat = false;
    } else {
      return false;  // PLTE, colour management, an unknown chunk: libpng decides
    }
  }
  return false;  // no IEND
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

libdeflate_decompressor* ThreadDecompressor() {
  thread_local const std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> decompressor(
      libdeflate_alloc_decompressor());
  return decompressor.get();
}

uint8_t Paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<uint8_t>(a);
  return static_cast<uint8_t>(pb <= pc ? b : c);
}

// Undoes one row's filter in place; `previous` is the unfiltered row above (zeros for the first).
bool Unfilter(uint8_t filter, uint8_t* row, const uint8_t* previous, size_t bytes, size_t bpp) {
  switch (filter) {
    case 0:
      return true;
    case 1:
      for (size_t i = bpp; i < bytes; ++i) row[i] = static_cast<uint8_t>(row[i] + row[i - bpp]);
      return true;
    case 2:
      for (size_t i = 0; i < bytes; ++i) row[i] = static_cast<uint8_t>(row[i] + previous[i]);
      return true;
    case 3:
      for (size_t i = 0; i < bpp; ++i) row[i] = static_cast<uint8_t>(row[i] + (previous[i] >> 1));
      for (size_t i = bpp; i < bytes; ++i) row[i] = static_cast<uint8_t>(row[i] + ((row[i - bpp] + previous[i]) >> 1));
      return true;
    case 4:
      for (size_t i = 0; i < bpp; ++i) row[i] = static_cast<uint8_t>(row[i] + previous[i]);
      for (size_t i = bpp; i < bytes; ++i) {
        row[i] = static_cast<uint8_t>(row[i] + Paeth(row[i - bpp], previous[i], previous[i - bpp]));
      }
      return true;
    default:
      return false;
  }
}

// libpng's png_do_rgb_to_gray for 8 bits without gamma, with the weights OpenCV asks for
// (png_set_rgb_to_gray(0.299, 0.587): 29900 and 58700 of 100000 scaled to 32768 and truncated).
void RgbRowToGray(const uint8_t* rgb, uint8_t* gray, int width) {
  constexpr uint32_t kRed = 29900u * 32768u / 100000u, kGreen = 58700u * 32768u / 100000u;
  constexpr uint32_t kBlue = 32768u - kRed - kGreen;
  for (int x = 0; x < width; ++x, rgb += 3) {
    gray[x] = static_cast<uint8_t>((kRed * rgb[0] + kGreen * rgb[1] + kBlue * rgb[2]) >> 15);
  }
}

}  // namespace

std::optional<cv::Mat> DecodePngGrayFast(const uint8_t* data, size_t size) {
  PngLayout png;
  if (!ParseChunks(data, size, &png)) return std::nullopt;
  const size_t row_bytes = static_cast<size_t>(png.width) * png.channels;
  const size_t stride = row_bytes + 1;  // the filter byte, then the row
  const size_t raw_size = stride * png.height;
  const std::unique_ptr<uint8_t[]> raw(new uint8_t[raw_size]);  // not zeroed: inflate fills it
  size_t produced = 0;
  if (libdeflate_zlib_decompress(ThreadDecompressor(), png.zlib_stream.data(), png.zlib_stream.size(), raw.get(),
                                 raw_size, &produced) != LIBDEFLATE_SUCCESS ||
      produced != raw_size) {
    return std::nullopt;
  }
  cv::Mat gray(png.height, png.width, CV_8UC1);
  const std::vector<uint8_t> zeros(row_bytes, 0);
  const uint8_t* previous = zeros.data();
  for (int y = 0; y < png.height; ++y) {
    uint8_t* line = raw.get() + stride * y;
    uint8_t* row = line + 1;
    if (!Unfilter(line[0], row, previous, row_bytes, png.channels)) return std::nullopt;
    if (png.channels == 1) {
      std::memcpy(gray.ptr<uint8_t>(y), row, row_bytes);
    } else {
      RgbRowToGray(row, gray.ptr<uint8_t>(y), png.width);
    }
    previous = row;
  }
  return gray;
}

namespace {

// The whole file, or nothing when it cannot be read.
std::vector<uint8_t> FileBytes(const std::string& path) {
  std::vector<uint8_t> bytes;
  if (FILE* file = std::fopen(path.c_str(), "rb")) {
    if (std::fseek(file, 0, SEEK_END) == 0) {
      const long size = std::ftell(file);
      if (size > 0 && std::fseek(file, 0, SEEK_SET) == 0) {
        bytes.resize(static_cast<size_t>(size));
        bytes.resize(std::fread(bytes.data(), 1, bytes.size(), file));
      }
    }
    std::fclose(file);
  }
  return bytes;
}

// libpng's decoding as OpenCV sets it up (16-bit samples to their high byte) into a cv::Mat of
// `channels` (0: as stored), or an empty one when the bytes are not a readable PNG.
cv::Mat DecodeOrEmpty(const std::vector<uint8_t>& bytes, int channels, const std::string& path) {
  Image8 image;
  try {
    image = DecodePng8(bytes.data(), bytes.size(), {channels, false}, path);
  } catch (const std::runtime_error&) {
    return cv::Mat();
  }
  return cv::Mat(image.height, image.width, CV_8UC(image.channels), image.pixels.data()).clone();
}

}  // namespace

cv::Mat ReadGrayImage(const std::string& path) {
  const std::vector<uint8_t> bytes = FileBytes(path);
  if (auto gray = DecodePngGrayFast(bytes.data(), bytes.size())) return *gray;
  return DecodeOrEmpty(bytes, 1, path);
}

cv::Mat ReadImageAnyColour(const std::string& path) {
  cv::Mat image = DecodeOrEmpty(FileBytes(path), 0, path);
  if (image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_RGB2BGR);
  return image;
}

}  // namespace rovo
