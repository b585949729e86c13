#include "datasets/png_encode.h"

#include <libdeflate.h>

#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

namespace rovo {
namespace {

void PutU32(uint32_t v, std::string* out) {
  const char bytes[4] = {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
                         static_cast<char>(v)};
  out->append(bytes, 4);
}

// One chunk: length, type, data, CRC-32 of type and data.
void PutChunk(const char type[4], const void* data, size_t size, std::string* out) {
  PutU32(static_cast<uint32_t>(size), out);
  const size_t type_at = out->size();
  out->append(type, 4);
  if (size > 0) out->append(static_cast<const char*>(data), size);
  PutU32(static_cast<uint32_t>(libdeflate_crc32(0, out->data() + type_at, size + 4)), out);
}

// A buffer that keeps its memory between calls of its thread: a view's buffers are the same size from
// frame to frame, so their pages are mapped and touched once per thread, not once per image.
uint8_t* Scratch(std::vector<uint8_t>* buffer, size_t size) {
  if (buffer->size() < size) buffer->resize(size);
  return buffer->data();
}

// The filtered scanlines of `height` rows of `row_bytes` into `filtered` (height * (row_bytes + 1) bytes): per
// row the filter byte 2 ("Up": each byte minus the byte above it), then the row's bytes (16-bit samples
// big-endian).
void UpFiltered(size_t row_bytes, int height, int bit_depth, const void* pixels, uint8_t* filtered) {
  const uint8_t* bytes = static_cast<const uint8_t*>(pixels);
  if (bit_depth == 16) {
    static thread_local std::vector<uint8_t> big_endian_buffer;
    uint8_t* big_endian = Scratch(&big_endian_buffer, static_cast<size_t>(height) * row_bytes);
    const uint16_t* in = static_cast<const uint16_t*>(pixels);
    for (size_t i = 0; i < static_cast<size_t>(height) * row_bytes / 2; ++i) {
      big_endian[2 * i] = static_cast<uint8_t>(in[i] >> 8);
      big_endian[2 * i + 1] = static_cast<uint8_t>(in[i]);
    }
    bytes = big_endian;
  }
  for (int y = 0; y < height; ++y) {
    const uint8_t* row = bytes + y * row_bytes;
    uint8_t* out = filtered + y * (row_bytes + 1);
    out[0] = 2;
    if (y == 0) {
      std::memcpy(out + 1, row, row_bytes);
      continue;
    }
    const uint8_t* above = row - row_bytes;
    for (size_t x = 0; x < row_bytes; ++x) out[1 + x] = static_cast<uint8_t>(row[x] - above[x]);
  }
}

struct CompressorDeleter {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};

}  // namespace

std::string EncodePng(int width, int height, int channels, int bit_depth, const void* pixels,
                      const std::string& software, int level) {
  if (width <= 0 || height <= 0 || !(channels == 1 || channels == 3) ||
      !(bit_depth == 8 || (bit_depth == 16 && channels == 1)) || level < 1 || level > 12) {
    throw std::invalid_argument("EncodePng: unsupported layout " + std::to_string(width) + "x" +
                                std::to_string(height) + ", " + std::to_string(channels) + " channel(s) of " +
                                std::to_string(bit_depth) + " bits at level " + std::to_string(level));
  }
  const size_t row_bytes = static_cast<size_t>(width) * channels * (bit_depth / 8);
  const size_t filtered_size = static_cast<size_t>(height) * (row_bytes + 1);
  static thread_local std::vector<uint8_t> filtered_buffer, zlib_buffer;
  uint8_t* filtered = Scratch(&filtered_buffer, filtered_size);
  UpFiltered(row_bytes, height, bit_depth, pixels, filtered);
  // One compressor per thread: its tables are allocated once (again when the level changes).
  static thread_local std::unique_ptr<libdeflate_compressor, CompressorDeleter> compressor;
  static thread_local int compressor_level = 0;
  if (!compressor || compressor_level != level) {
    compressor.reset(libdeflate_alloc_compressor(level));
    compressor_level = level;
  }
  if (!compressor) throw std::runtime_error("EncodePng: libdeflate cannot allocate a compressor");
  const size_t zlib_bound = libdeflate_zlib_compress_bound(compressor.get(), filtered_size);
  uint8_t* zlib = Scratch(&zlib_buffer, zlib_bound);
  const size_t zlib_size = libdeflate_zlib_compress(compressor.get(), filtered, filtered_size, zlib, zlib_bound);
  if (zlib_size == 0) throw std::runtime_error("EncodePng: libdeflate's output exceeded its own bound");
  if (zlib_size > 0x7fffffffu)
    throw std::length_error("EncodePng: image data over PNG's chunk limit of 2^31 - 1 bytes");

  std::string png("\x89PNG\r\n\x1a\n", 8);
  png.reserve(zlib_size + software.size() + 128);
  uint8_t header[13];
  const uint32_t size[2] = {static_cast<uint32_t>(width), static_cast<uint32_t>(height)};
  for (int k = 0; k < 2; ++k)
    for (int b = 0; b < 4; ++b) header[4 * k + b] = static_cast<uint8_t>(size[k] >> (24 - 8 * b));
  header[8] = static_cast<uint8_t>(bit_depth);
  header[9] = channels == 3 ? 2 : 0;         // colour type: truecolour or greyscale
  header[10] = header[11] = header[12] = 0;  // deflate, adaptive filtering, no interlace
  PutChunk("IHDR", header, sizeof(header), &png);
  const std::string text = "Software" + std::string(1, '\0') + software;
  PutChunk("tEXt", text.data(), text.size(), &png);
  PutChunk("IDAT", zlib, zlib_size, &png);
  PutChunk("IEND", nullptr, 0, &png);
  return png;
}

}  // namespace rovo
