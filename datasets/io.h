#pragma once
// File helpers shared by every part: atomic writes (temp file in the same folder, then rename, so
// a killed process never leaves a half-written file under the final name) and JSON loading with
// errors that name the file.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace rovo {

// Temporary sibling path for `path` (same folder, unique per process and call).
std::string TempPathFor(const std::string& path);
// Renames `tmp_path` onto `path` (atomic on POSIX within one file system); throws on failure.
void CommitTempFile(const std::string& tmp_path, const std::string& path);
// Writes `content` to `path` atomically; creates missing parent folders. Throws std::runtime_error
// naming the path on failure.
void WriteFileAtomic(const std::string& path, const std::string& content);
// Whole file as a string; throws std::runtime_error naming the path.
std::string ReadFile(const std::string& path);
// Parses a JSON file; throws std::runtime_error "<path>: <parser message>".
nlohmann::json ReadJsonFile(const std::string& path);
void WriteJsonFileAtomic(const std::string& path, const nlohmann::json& json);
// Creates a folder and its parents; throws naming the folder when it cannot be created or written.
void EnsureWritableDir(const std::string& dir);
// For a file that starts with the PNG signature: why its chunk list is broken (a chunk longer than the
// rest of the file, no IHDR first), or "" when it is sound or not a PNG. Checked before libpng reads a
// PNG: libpng allocates a chunk's stated length before reading it (1.7 GB for a corrupt tEXt).
std::string PngChunkProblem(const std::string& path);
// The same for a PNG file's bytes.
std::string PngChunkProblem(const uint8_t* data, size_t size);
// FNV-1a 64-bit hash of bytes, as 16 hex digits (content hashes for caching and provenance).
std::string HashHex(const void* data, size_t size, uint64_t seed = 0);

}  // namespace rovo
