#include "datasets/io.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rovo {
namespace fs = std::filesystem;

std::string TempPathFor(const std::string& path) {
  static std::atomic<uint64_t> counter{0};
  std::ostringstream out;
  out << path << ".tmp." << ::getpid() << "." << counter.fetch_add(1);
  return out.str();
}

void CommitTempFile(const std::string& tmp_path, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp_path, path, ec);
  if (ec) {
    fs::remove(tmp_path, ec);
    throw std::runtime_error(path + ": cannot move temporary file into place: " + ec.message());
  }
}

void WriteFileAtomic(const std::string& path, const std::string& content) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) EnsureWritableDir(parent.string());
  const std::string tmp = TempPathFor(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error(path + ": cannot open for writing");
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error(path + ": write failed");
    }
  }
  CommitTempFile(tmp, path);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

nlohmann::json ReadJsonFile(const std::string& path) {
  const std::string text = ReadFile(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // parse_error, and out_of_range for a number that overflows (e.g. 1e99999999999).
    throw std::runtime_error(path + ": malformed JSON: " + e.what());
  }
}

void WriteJsonFileAtomic(const std::string& path, const nlohmann::json& json) {
  WriteFileAtomic(path, json.dump(2) + "\n");
}

void EnsureWritableDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create folder: " + ec.message());
  if (::access(dir.c_str(), W_OK) != 0) throw std::runtime_error(dir + ": folder is not writable");
}

namespace {

// PngChunkProblem's walk over the chunks of a PNG of `size` bytes; read8(offset, out) reads the 8
// bytes at `offset` (false when it cannot).
template <typename Read8>
std::string WalkPngChunks(uint64_t size, Read8 read8) {
  uint64_t offset = 8;
  for (int index = 0; offset < size; ++index) {
    unsigned char chunk[8];  // length (big-endian), type
    if (!read8(offset, chunk)) return "truncated chunk header at byte " + std::to_string(offset);
    const uint64_t length =
        (uint64_t{chunk[0]} << 24) | (uint64_t{chunk[1]} << 16) | (uint64_t{chunk[2]} << 8) | chunk[3];
    const std::string type(reinterpret_cast<const char*>(chunk + 4), 4);
    if (index == 0 && type != "IHDR") return "the first chunk is not IHDR";
    if (offset + 12 + length > size) {
      return "chunk " + std::to_string(index) + " claims " + std::to_string(length) +
             " bytes, beyond the end of the file";
    }
    if (type == "IEND") return "";
    offset += 12 + length;
  }
  return "";
}

const unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

}  // namespace

std::string PngChunkProblem(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[8];
  if (!in.read(reinterpret_cast<char*>(header), 8) || std::memcmp(header, kPngSignature, 8) != 0) return "";
  std::error_code ec;
  const uint64_t size = fs::file_size(path, ec);
  if (ec) return "cannot read the file size";
  return WalkPngChunks(size, [&](uint64_t offset, unsigned char* out) {
    in.seekg(static_cast<std::streamoff>(offset));
    return static_cast<bool>(in.read(reinterpret_cast<char*>(out), 8));
  });
}

std::string PngChunkProblem(const uint8_t* data, size_t size) {
  if (size < 8 || std::memcmp(data, kPngSignature, 8) != 0) return "";
  return WalkPngChunks(size, [&](uint64_t offset, unsigned char* out) {
    if (offset + 8 > size) return false;
    std::memcpy(out, data + offset, 8);
    return true;
  });
}

std::string HashHex(const void* data, size_t size, uint64_t seed) {
  uint64_t h = 1469598103934665603ull ^ seed;
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace rovo
