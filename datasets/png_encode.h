#pragma once
// PNG encoding with libdeflate (Debian libdeflate-dev, whose inflate the replays' decoder uses too:
// vo/png_gray.h): non-interlaced 8-bit gray or RGB and 16-bit gray, each row with the "Up" filter,
// the whole zlib stream (libdeflate, level 1 unless asked) in one IDAT chunk, and a tEXt "Software" chunk. A
// full-size rendered view compresses in about 40 ms where libpng with zlib at level 1 (OpenImageIO)
// takes 63 ms, to a smaller file (docs/results.md, section "Speed of the renderer").

#include <cstdint>
#include <string>

namespace rovo {

// The PNG file of `height` rows of `width` pixels with `channels` (1 or 3) samples of `bit_depth` (8, or
// 16 with one channel; 16-bit samples in the host's order, written big-endian as PNG wants), rows
// packed without padding; `level` is libdeflate's compression level (1-12). Throws
// std::invalid_argument on an unsupported layout or level.
std::string EncodePng(int width, int height, int channels, int bit_depth, const void* pixels,
                      const std::string& software, int level = 1);

}  // namespace rovo
