#pragma once
// Atomic image writers for the render outputs (a temporary sibling is written, then renamed onto the
// final name, so a killed process never leaves a partial file under the final name). PNGs are encoded
// by datasets/png_encode.h, EXR by OpenEXR (datasets/image_file.h).

#include <cstdint>
#include <string>
#include <vector>

namespace rovo {

// 8-bit RGB PNG (deflate level 1: higher levels cost more than tracing; the "Up" row filter only:
// half the encoding time of an adaptive filter choice per row).
void WritePngRgb8(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);
// 8-bit single-channel PNG (a grayscale sensor's images), same settings as WritePngRgb8.
void WritePngGray8(const std::string& path, int width, int height, const std::vector<uint8_t>& gray);
// 16-bit single-channel PNG (object ids).
void WritePngGray16(const std::string& path, int width, int height, const std::vector<uint16_t>& values);
// float32 single-channel OpenEXR (zip compression).
void WriteExrFloat(const std::string& path, int width, int height, const std::vector<float>& values);

// Removes `*.tmp.<pid>.<n>` files in `dir` left by processes that no longer run.
void RemoveStaleTempFiles(const std::string& dir);

}  // namespace rovo
