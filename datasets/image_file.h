#pragma once
// The image files rovo reads and writes: PNG (decoded by libpng, encoded by datasets/png_encode.h),
// OpenEXR (the OpenEXR library; the first part of a multi-part file), and JPEG to read real cameras'
// frames (libjpeg). Pixels are read as stored: an eXIf orientation is not applied. Readers throw
// std::runtime_error "<file>: <what is wrong>"; writers write atomically (datasets/io.h).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace rovo {

struct ImageHeader {
  int width = 0, height = 0;
  // PNG: 1 gray, 2 gray + alpha, 3 RGB or palette, 4 RGB + alpha; OpenEXR: the channel count.
  int channels = 0;
  int bit_depth = 0;  // PNG: bits per sample (1-16); OpenEXR: 16 (half) or 32 (float, uint) of the widest channel
};

// The header of a PNG or OpenEXR file, told apart by their signatures; a PNG's chunk list is checked
// whole first (PngChunkProblem, datasets/io.h).
ImageHeader ReadImageHeader(const std::string& path);

// An 8-bit image: rows packed, samples interleaved.
struct Image8 {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> pixels;
};

struct PngReadOptions {
  // 1: gray, colour turned to gray by libpng with weights 0.299 / 0.587 / 0.114 (9797, 19234, 3737
  // of 32768, as cv::imread(IMREAD_GRAYSCALE) reads it); 3: RGB, gray replicated; 0: as stored, 1
  // channel for gray and 3 for every other colour type. Alpha is dropped, palettes expanded. (OpenCV
  // would also turn the image by an eXIf orientation; rovo keeps the stored pixels.)
  int channels = 0;
  // 16-bit samples to 8 bits: rounded (v / 257), or their high byte (as OpenCV reads them).
  bool round_16_bit = true;
};

// A PNG file as 8-bit samples.
Image8 ReadPng8(const std::string& path, const PngReadOptions& options = {});
// A PNG or a JPEG file (baseline or progressive, gray or colour; libjpeg's decoding at its default
// settings), told apart by their signatures, as 8-bit samples: PNGs as ReadPng8 reads them, JPEGs as
// stored (1 channel for gray, 3 for colour, in RGB order). For images from outside rovo (real
// cameras' frames); rovo's own images are PNG.
Image8 ReadPngOrJpeg8(const std::string& path, const PngReadOptions& options = {});
// The same from the file's bytes; `name` is the file named in errors.
Image8 DecodePng8(const uint8_t* data, size_t size, const PngReadOptions& options, const std::string& name);

// Float channels of an OpenEXR file, each as a plane of width x height values (half and uint
// samples converted), in the file's channel order (sorted by name).
struct FloatImage {
  int width = 0, height = 0;
  std::vector<std::string> channel_names;
  std::vector<std::vector<float>> planes;
  // Index of the channel `name`, or -1.
  int Channel(const std::string& name) const;
};
FloatImage ReadExr(const std::string& path);

// One float32 channel named `channel` as OpenEXR (zip compression), with a "software" attribute.
void WriteExrFloat(const std::string& path, int width, int height, const std::vector<float>& values,
                   const std::string& channel, const std::string& software);
// 8-bit gray (1 channel) or RGB (3) as PNG (datasets/png_encode.h at `level`).
void WritePng8(const std::string& path, int width, int height, int channels, const std::vector<uint8_t>& pixels,
               const std::string& software, int level = 1);

}  // namespace rovo
