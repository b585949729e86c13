#pragma once
// Decoding of the PNG images rovo writes, for replaying datasets (`rovo vo` without --preload).
// libpng with zlib spends about 60 % of its instructions in zlib's inflate and its Adler-32;
// libdeflate inflates the same stream in fewer than half of them (docs/design-notes.md, section Speed).
//
// The fast path takes 8-bit gray or RGB, non-interlaced PNGs whose other chunks cannot change the
// pixels (text, oFFs, pHYs, tIME) and converts RGB to gray with the weights and truncation of
// libpng's rgb_to_gray at 0.299 / 0.587 (9797, 19234, 3737 of 32768), the conversion of
// cv::imread(IMREAD_GRAYSCALE), so its result equals OpenCV's byte for byte. Every other PNG, and
// any file the fast path finds damaged (a CRC, the zlib stream, a filter byte), goes to libpng set
// up as OpenCV sets it up (datasets/image_file.h), which decides.

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace rovo {

// The fast path on a file's bytes: the gray image, or nullopt when the file is not of the handled
// kind or is damaged (then libpng decides). Never throws on bad input.
std::optional<cv::Mat> DecodePngGrayFast(const uint8_t* data, size_t size);

// A PNG file as 8-bit gray, as cv::imread(path, IMREAD_GRAYSCALE) reads it (the fast path for
// the PNGs above): empty when the file is missing, not a PNG or unreadable.
cv::Mat ReadGrayImage(const std::string& path);
// A PNG file as 8-bit samples, as cv::imread(path, IMREAD_ANYCOLOR) reads it: gray as one channel,
// every other colour type as three in BGR order, alpha dropped; empty as above.
cv::Mat ReadImageAnyColour(const std::string& path);

}  // namespace rovo
