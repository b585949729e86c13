#include "datasets/image_file.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <libdeflate.h>
#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

// clang-format off
#include <jpeglib.h>  // after <cstdio>: it uses FILE without including it
// clang-format on

#include "datasets/io.h"
#include "datasets/png_encode.h"

namespace rovo {
namespace {
namespace fs = std::filesystem;

constexpr uint8_t kPngMagic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr uint8_t kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
// Deflate expands at most 1032-fold: image data (filtered rows as stored) beyond this many bytes per
// byte of file cannot be in the file, so it is refused before anything of that size is allocated.
constexpr size_t kMaxExpansion = 1100;
constexpr size_t kMaxPixels = size_t{1} << 28;
constexpr uint32_t kMaxPngSide = 1000000;  // libpng's default limit of either side
// An OpenEXR file's samples per byte of file: its lossless codecs (zip, RLE, PIZ) stay below deflate's
// bound; a flat image under the lossy DWA codec could exceed it and is refused.
constexpr size_t kMaxExrSamplesPerByte = kMaxExpansion;

std::vector<uint8_t> FileBytes(const std::string& path, size_t limit = SIZE_MAX) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the image");
  std::vector<uint8_t> bytes;
  char buffer[65536];
  while (bytes.size() < limit && in.read(buffer, sizeof(buffer)).gcount() > 0) {
    bytes.insert(bytes.end(), buffer, buffer + in.gcount());
  }
  if (bytes.size() > limit) bytes.resize(limit);
  return bytes;
}

uint32_t BigEndian32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

// The IHDR chunk of a PNG (bytes 8-32 of a file whose chunk list is sound).
struct PngIhdr {
  uint32_t width = 0, height = 0;
  int bit_depth = 0, colour_type = 0;
  bool interlaced = false;
  // Samples per pixel as stored (a palette index is one) and as read (a palette counts as RGB).
  int StoredSamples() const { return colour_type == 2 ? 3 : colour_type == 4 ? 2 : colour_type == 6 ? 4 : 1; }
  int Channels() const { return colour_type == 3 ? 3 : StoredSamples(); }
  // Bytes of the filtered rows the zlib stream inflates to (Adam7's passes add at most as much again).
  uint64_t StoredBytes() const {
    const uint64_t row = (uint64_t{width} * StoredSamples() * bit_depth + 7) / 8 + 1;
    return row * height * (interlaced ? 2 : 1);
  }
};

// Checks the IHDR as libpng does (length, CRC, sizes, bit depth for the colour type, methods);
// returns "" when sound, else the reason.
std::string ParseIhdr(const uint8_t* file, PngIhdr* ihdr) {
  const uint8_t* data = file + 16;
  if (BigEndian32(file + 8) != 13) return "IHDR is not 13 bytes long";
  if (libdeflate_crc32(0, file + 12, 17) != BigEndian32(file + 29)) return "IHDR CRC error";
  ihdr->width = BigEndian32(data);
  ihdr->height = BigEndian32(data + 4);
  ihdr->bit_depth = data[8];
  ihdr->colour_type = data[9];
  ihdr->interlaced = data[12] == 1;
  if (ihdr->width == 0 || ihdr->height == 0 || ihdr->width > kMaxPngSide || ihdr->height > kMaxPngSide) {
    return "IHDR size " + std::to_string(ihdr->width) + "x" + std::to_string(ihdr->height) + " (1 to " +
           std::to_string(kMaxPngSide) + " a side)";
  }
  const int d = ihdr->bit_depth;
  bool depth_ok = false;
  switch (ihdr->colour_type) {
    case 0:
      depth_ok = d == 1 || d == 2 || d == 4 || d == 8 || d == 16;
      break;
    case 3:
      depth_ok = d == 1 || d == 2 || d == 4 || d == 8;
      break;
    case 2:
    case 4:
    case 6:
      depth_ok = d == 8 || d == 16;
      break;
    default:
      return "IHDR colour type " + std::to_string(ihdr->colour_type);
  }
  if (!depth_ok) return "IHDR bit depth " + std::to_string(d) + " for colour type " + std::to_string(ihdr->colour_type);
  if (data[10] != 0 || data[11] != 0 || data[12] > 1) return "IHDR compression, filter or interlace method unknown";
  return "";
}

// The IHDR of a PNG's first 33 bytes, after the whole chunk list was checked (`chunk_problem`);
// throws naming `name`.
PngIhdr CheckedIhdr(const uint8_t* file, size_t size, const std::string& chunk_problem, const std::string& name) {
  if (!chunk_problem.empty()) throw std::runtime_error(name + ": unreadable PNG: " + chunk_problem);
  if (size < 33) throw std::runtime_error(name + ": unreadable PNG: the IHDR chunk is cut short");
  PngIhdr ihdr;
  const std::string problem = ParseIhdr(file, &ihdr);
  if (!problem.empty()) throw std::runtime_error(name + ": unreadable PNG: " + problem);
  return ihdr;
}

// ---- libpng, from memory, errors by longjmp ----

struct PngSource {
  const uint8_t* data;
  size_t size;
  size_t offset;
  char error[200];
};

void ReadFromSource(png_structp png, png_bytep out, png_size_t count) {
  auto* source = static_cast<PngSource*>(png_get_io_ptr(png));
  if (count > source->size - source->offset) png_error(png, "the file ends early");
  std::memcpy(out, source->data + source->offset, count);
  source->offset += count;
}

void OnPngError(png_structp png, png_const_charp message) {
  auto* source = static_cast<PngSource*>(png_get_error_ptr(png));
  std::snprintf(source->error, sizeof(source->error), "%s", message);
  png_longjmp(png, 1);
}

void OnPngWarning(png_structp, png_const_charp) {}

// The transforms of PngReadOptions on a read struct whose header has been read; returns the
// channels of the result.
int SetPngTransforms(png_structp png, png_infop info, const PngReadOptions& options) {
  const int colour_type = png_get_color_type(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  if (bit_depth == 16) {
    if (options.round_16_bit) {
      png_set_scale_16(png);
    } else {
      png_set_strip_16(png);
    }
  }
  png_set_strip_alpha(png);
  if (colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  const bool colour = (colour_type & PNG_COLOR_MASK_COLOR) != 0;
  if (!colour && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  const int channels = options.channels != 0 ? options.channels : (colour_type == PNG_COLOR_TYPE_GRAY ? 1 : 3);
  if (channels == 1 && colour) png_set_rgb_to_gray(png, 1, 0.299, 0.587);
  if (channels == 3 && !colour) png_set_gray_to_rgb(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  return channels;
}

// Decodes into `image` (sized by the caller's header check); false with source->error set on failure.
// No C++ object is created between setjmp and a longjmp back to it.
bool DecodeWithLibpng(PngSource* source, const PngReadOptions& options, Image8* image, std::vector<png_bytep>* rows) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, source, OnPngError, OnPngWarning);
  if (png == nullptr) {
    std::snprintf(source->error, sizeof(source->error), "libpng cannot start");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  png_infop end_info = png_create_info_struct(png);
  volatile bool ok = false;
  if (info == nullptr || end_info == nullptr) {
    std::snprintf(source->error, sizeof(source->error), "libpng cannot start");
  } else if (setjmp(png_jmpbuf(png)) == 0) {
    png_set_read_fn(png, source, ReadFromSource);
    png_read_info(png, info);
    const int channels = SetPngTransforms(png, info, options);
    if (static_cast<int>(png_get_rowbytes(png, info)) != image->width * channels) {
      png_error(png, "unexpected row size after the transforms");
    }
    image->channels = channels;
    for (int y = 0; y < image->height; ++y)
      (*rows)[y] = image->pixels.data() + static_cast<size_t>(y) * image->width * channels;
    png_read_image(png, rows->data());
    png_read_end(png, end_info);
    ok = true;
  }
  png_destroy_read_struct(&png, &info, &end_info);
  return ok;
}

// ---- libjpeg, from memory, errors by longjmp ----

struct JpegErrors {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void OnJpegError(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}

void OnJpegMessage(j_common_ptr, int) {}

// Decodes a JPEG into `image` (1 channel for gray, 3 for colour); false with errors->message set.
// `pixels` is sized here only after the header stated a size that passes `max_pixels`; no C++ object
// is created between setjmp and a longjmp back to it.
bool DecodeWithLibjpeg(const uint8_t* data, size_t size, uint64_t max_pixels, JpegErrors* errors, Image8* image) {
  jpeg_decompress_struct cinfo;
  cinfo.err = jpeg_std_error(&errors->manager);
  errors->manager.error_exit = OnJpegError;
  errors->manager.emit_message = OnJpegMessage;
  volatile bool ok = false;
  if (setjmp(errors->jump) == 0) {
    jpeg_create_decompress(&cinfo);
    jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
    jpeg_read_header(&cinfo, TRUE);
    if (cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK) {
      std::snprintf(errors->message, sizeof(errors->message), "CMYK JPEG (gray or colour wanted)");
    } else {
      cinfo.out_color_space = cinfo.num_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
      jpeg_start_decompress(&cinfo);
      const uint64_t pixels = uint64_t{cinfo.output_width} * cinfo.output_height;
      if (pixels == 0 || pixels > max_pixels) {
        std::snprintf(errors->message, sizeof(errors->message), "a JPEG of %ux%u pixels in %zu bytes",
                      cinfo.output_width, cinfo.output_height, size);
      } else {
        image->width = static_cast<int>(cinfo.output_width);
        image->height = static_cast<int>(cinfo.output_height);
        image->channels = cinfo.output_components;
        image->pixels.resize(static_cast<size_t>(pixels) * static_cast<size_t>(image->channels));
        while (cinfo.output_scanline < cinfo.output_height) {
          JSAMPROW row = image->pixels.data() + static_cast<size_t>(cinfo.output_scanline) * image->width *
                                                    static_cast<size_t>(image->channels);
          jpeg_read_scanlines(&cinfo, &row, 1);
        }
        jpeg_finish_decompress(&cinfo);
        ok = true;
      }
    }
  }
  jpeg_destroy_decompress(&cinfo);
  return ok;
}

// ---- OpenEXR ----

// OpenEXR sizes its tables and line buffers by the header's data window before reading any pixel:
// windows and tiles beyond these sides are refused while the header is read.
constexpr int kMaxExrSide = 65536, kMaxExrTileSide = 4096;

template <typename Fn>
auto WithExrErrors(const std::string& path, Fn fn) -> decltype(fn()) {
  static const bool limits_set = [] {
    Imf::Header::setMaxImageSize(kMaxExrSide, kMaxExrSide);
    Imf::Header::setMaxTileSize(kMaxExrTileSide, kMaxExrTileSide);
    return true;
  }();
  (void)limits_set;
  try {
    return fn();
  } catch (const std::runtime_error&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": unreadable OpenEXR file: " + e.what());
  }
}

ImageHeader HeaderOf(const Imf::Header& exr) {
  const Imath::Box2i& window = exr.dataWindow();
  const int64_t width = int64_t{window.max.x} - window.min.x + 1, height = int64_t{window.max.y} - window.min.y + 1;
  ImageHeader header;
  // A window beyond 2^31 - 1 pixels a side reads as 0 (refused by the readers).
  header.width = width > 0 && width <= INT32_MAX ? static_cast<int>(width) : 0;
  header.height = height > 0 && height <= INT32_MAX ? static_cast<int>(height) : 0;
  for (auto it = exr.channels().begin(); it != exr.channels().end(); ++it) {
    ++header.channels;
    header.bit_depth = std::max(header.bit_depth, it.channel().type == Imf::HALF ? 16 : 32);
  }
  return header;
}

// Why the header part of an OpenEXR file cannot be handed to OpenEXR, or "": every attribute must fit
// in the file (OpenEXR sizes its buffers by what the header states before it reads the data), the
// required attributes must be there, and the data and display windows within kMaxExrSide a side.
// Multi-part files: every part's header.
std::string ExrHeaderProblem(const std::string& path) {
  // The header only (a few kB; a preview image adds tens): not the pixels, which the validator
  // would otherwise read for every depth file. A header beyond the first 1 MB is refused.
  constexpr size_t kMaxHeaderBytes = size_t{1} << 20;
  const std::vector<uint8_t> bytes = FileBytes(path, kMaxHeaderBytes);
  if (bytes.size() < 8) return "the file ends in its version field";
  const std::string beyond = bytes.size() == kMaxHeaderBytes ? " (or a header longer than 1 MB)" : "";
  const bool multi_part = (bytes[5] & 0x10) != 0;  // version flag bit 12
  size_t at = 8;
  std::string name, type;
  const auto text = [&](std::string* out) {  // a NUL-terminated name of at most 255 characters
    const auto first = bytes.begin() + static_cast<std::ptrdiff_t>(at);
    const auto end = std::find(first, bytes.begin() + static_cast<std::ptrdiff_t>(std::min(bytes.size(), at + 256)), 0);
    if (end == bytes.end() || *end != 0) return false;
    out->assign(first, end);
    at = static_cast<size_t>(end - bytes.begin()) + 1;
    return true;
  };
  // The attributes every header must have (OpenEXR's own defaults for missing ones have sized tables
  // by nonsense), with the windows' sides bounded.
  static const char* const kRequired[] = {"channels", "compression", "dataWindow", "displayWindow", "lineOrder"};
  for (int part = 0; part < 1000; ++part) {
    std::set<std::string> seen;
    while (true) {  // the attributes of one header, up to an empty name
      if (!text(&name)) return "header " + std::to_string(part) + ": a name beyond the file or 255 characters" + beyond;
      if (name.empty()) break;
      if (!text(&type) || bytes.size() - at < 4) return "attribute " + name + " is cut short" + beyond;
      uint32_t size = 0;
      std::memcpy(&size, bytes.data() + at, 4);  // little-endian, as the host
      at += 4;
      if (size > bytes.size() - at) return "attribute " + name + " claims " + std::to_string(size) + " bytes" + beyond;
      if ((name == "dataWindow" || name == "displayWindow") && (type != "box2i" || size != 16)) {
        return "attribute " + name + " is not a box2i";
      }
      if (name == "dataWindow" || name == "displayWindow") {
        int32_t box[4];
        std::memcpy(box, bytes.data() + at, 16);
        if (box[0] > box[2] || box[1] > box[3] || int64_t{box[2]} - box[0] >= kMaxExrSide ||
            int64_t{box[3]} - box[1] >= kMaxExrSide) {
          return name + " (" + std::to_string(box[0]) + ", " + std::to_string(box[1]) + ") - (" +
                 std::to_string(box[2]) + ", " + std::to_string(box[3]) + ")";
        }
      }
      seen.insert(name);
      at += size;
    }
    for (const char* required : kRequired) {
      if (!seen.count(required)) return "header " + std::to_string(part) + " has no " + required;
    }
    // One header, or a multi-part file's list of them ended by an empty one.
    if (!multi_part || (at < bytes.size() && bytes[at] == 0)) return "";
  }
  return "more than 1000 parts";
}

// Throws naming the file when ExrHeaderProblem finds one.
void CheckExrHeader(const std::string& path) {
  const std::string problem = ExrHeaderProblem(path);
  if (!problem.empty()) throw std::runtime_error(path + ": unreadable OpenEXR file: " + problem);
}

ImageHeader ExrHeader(const std::string& path) {
  CheckExrHeader(path);
  return WithExrErrors(path, [&] { return HeaderOf(Imf::InputFile(path.c_str()).header()); });
}

// An in-memory OpenEXR output stream: OutputFile's destructor writes the line-offset table without
// reporting errors, so the file is encoded here and written to disk by WriteFileAtomic, which checks.
struct MemoryOStream : public Imf::OStream {
  MemoryOStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    if (position + static_cast<uint64_t>(n) > bytes.size()) bytes.resize(position + static_cast<uint64_t>(n));
    std::memcpy(&bytes[position], c, static_cast<size_t>(n));
    position += static_cast<uint64_t>(n);
  }
  uint64_t tellp() override { return position; }
  void seekp(uint64_t pos) override { position = pos; }

  std::string bytes;
  uint64_t position = 0;
};

}  // namespace

ImageHeader ReadImageHeader(const std::string& path) {
  const std::vector<uint8_t> start = FileBytes(path, 33);  // PNG signature + IHDR chunk
  if (start.size() >= 8 && std::memcmp(start.data(), kPngMagic, 8) == 0) {
    const PngIhdr ihdr = CheckedIhdr(start.data(), start.size(), PngChunkProblem(path), path);
    ImageHeader header;
    header.width = static_cast<int>(ihdr.width);
    header.height = static_cast<int>(ihdr.height);
    header.bit_depth = ihdr.bit_depth;
    header.channels = ihdr.Channels();
    return header;
  }
  if (start.size() >= 4 && std::memcmp(start.data(), kExrMagic, 4) == 0) return ExrHeader(path);
  throw std::runtime_error(path + ": not a PNG or OpenEXR file");
}

Image8 DecodePng8(const uint8_t* data, size_t size, const PngReadOptions& options, const std::string& name) {
  if (options.channels != 0 && options.channels != 1 && options.channels != 3) {
    throw std::invalid_argument(name + ": PngReadOptions::channels must be 0, 1 or 3");
  }
  if (size < 8 || std::memcmp(data, kPngMagic, 8) != 0) throw std::runtime_error(name + ": not a PNG file");
  const PngIhdr ihdr = CheckedIhdr(data, size, PngChunkProblem(data, size), name);
  const uint64_t pixels = uint64_t{ihdr.width} * ihdr.height;
  if (pixels > kMaxPixels || ihdr.StoredBytes() > kMaxExpansion * uint64_t{size}) {
    throw std::runtime_error(name + ": unreadable PNG: IHDR states " + std::to_string(ihdr.width) + "x" +
                             std::to_string(ihdr.height) + " pixels, more than " + std::to_string(size) +
                             " bytes can hold");
  }
  Image8 image;
  image.width = static_cast<int>(ihdr.width);
  image.height = static_cast<int>(ihdr.height);
  image.pixels.resize(static_cast<size_t>(pixels) * 3);  // room for RGB; trimmed to the result's channels
  std::vector<png_bytep> rows(ihdr.height);
  PngSource source{data, size, 0, {0}};
  if (!DecodeWithLibpng(&source, options, &image, &rows)) {
    throw std::runtime_error(name + ": unreadable PNG: " + source.error);
  }
  image.pixels.resize(static_cast<size_t>(pixels) * image.channels);
  return image;
}

Image8 ReadPng8(const std::string& path, const PngReadOptions& options) {
  const std::vector<uint8_t> bytes = FileBytes(path);
  return DecodePng8(bytes.data(), bytes.size(), options, path);
}

Image8 ReadPngOrJpeg8(const std::string& path, const PngReadOptions& options) {
  const std::vector<uint8_t> bytes = FileBytes(path);
  if (bytes.size() < 3 || bytes[0] != 0xff || bytes[1] != 0xd8 || bytes[2] != 0xff) {
    return DecodePng8(bytes.data(), bytes.size(), options, path);
  }
  // An 8x8 block of a flat JPEG takes a few bits: at most some 250 pixels per byte.
  const uint64_t max_pixels = std::min<uint64_t>(kMaxPixels, kMaxExpansion * bytes.size());
  JpegErrors errors{};
  Image8 image;
  if (!DecodeWithLibjpeg(bytes.data(), bytes.size(), max_pixels, &errors, &image)) {
    throw std::runtime_error(path + ": unreadable JPEG: " + errors.message);
  }
  return image;
}

int FloatImage::Channel(const std::string& name) const {
  const auto it = std::find(channel_names.begin(), channel_names.end(), name);
  return it == channel_names.end() ? -1 : static_cast<int>(it - channel_names.begin());
}

FloatImage ReadExr(const std::string& path) {
  std::error_code ec;
  const uint64_t file_size = fs::file_size(path, ec);
  if (ec) throw std::runtime_error(path + ": cannot open the image: " + ec.message());
  CheckExrHeader(path);
  return WithExrErrors(path, [&] {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i& window = file.header().dataWindow();
    const ImageHeader header = HeaderOf(file.header());
    FloatImage image;
    image.width = header.width;
    image.height = header.height;
    const Imf::ChannelList& channels = file.header().channels();
    const uint64_t pixels = uint64_t(image.width) * uint64_t(image.height);
    if (image.width <= 0 || image.height <= 0 || pixels > kMaxPixels ||
        pixels * uint64_t(std::max(header.channels, 1)) > kMaxExrSamplesPerByte * file_size) {
      throw std::runtime_error(path + ": unreadable OpenEXR file: a data window of " + std::to_string(image.width) +
                               "x" + std::to_string(image.height) + " pixels in " + std::to_string(file_size) +
                               " bytes");
    }
    Imf::FrameBuffer frame;
    image.planes.reserve(static_cast<size_t>(header.channels));
    for (auto it = channels.begin(); it != channels.end(); ++it) {
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1) {
        throw std::runtime_error(path + ": channel " + it.name() + " is subsampled (not supported)");
      }
      image.channel_names.push_back(it.name());
      image.planes.emplace_back(static_cast<size_t>(pixels), 0.0f);
      // Addressed from the data window's origin (Slice::Make does the offset arithmetic).
      frame.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, image.planes.back().data(), window, sizeof(float),
                                               sizeof(float) * static_cast<size_t>(image.width)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return image;
  });
}

void WriteExrFloat(const std::string& path, int width, int height, const std::vector<float>& values,
                   const std::string& channel, const std::string& software) {
  if (width <= 0 || height <= 0 || values.size() != static_cast<size_t>(width) * height) {
    throw std::invalid_argument(path + ": " + std::to_string(values.size()) + " values for a " + std::to_string(width) +
                                "x" + std::to_string(height) + " image");
  }
  MemoryOStream stream;
  try {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.channels().insert(channel, Imf::Channel(Imf::FLOAT));
    header.insert("software", Imf::StringAttribute(software));
    Imf::OutputFile file(stream, header);
    Imf::FrameBuffer frame;
    frame.insert(channel, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(values.data())),
                                     sizeof(float), sizeof(float) * static_cast<size_t>(width)));
    file.setFrameBuffer(frame);
    file.writePixels(height);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": cannot encode OpenEXR: " + e.what());
  }
  // The file's destructor wrote the line offsets into memory; the disk write is checked as a whole.
  WriteFileAtomic(path, stream.bytes);
}

void WritePng8(const std::string& path, int width, int height, int channels, const std::vector<uint8_t>& pixels,
               const std::string& software, int level) {
  if (width <= 0 || height <= 0 || pixels.size() != static_cast<size_t>(width) * height * channels) {
    throw std::invalid_argument(path + ": " + std::to_string(pixels.size()) + " samples for a " +
                                std::to_string(width) + "x" + std::to_string(height) + " image of " +
                                std::to_string(channels) + " channel(s)");
  }
  WriteFileAtomic(path, EncodePng(width, height, channels, 8, pixels.data(), software, level));
}

}  // namespace rovo
