#pragma once
// An MCAP file writer (the container of ROS 2 bags since Iron), written from the MCAP format
// specification, major version 0 (foxglove/mcap, website/docs/spec/index.md, "MCAP Format
// Specification"; the record registry website/docs/spec/registry.md for the `ros2` profile).
//
// Layout written:
//   <Magic><Header><Schema...><Channel...>
//   (<Chunk, compression "" (none)><Message Index per channel of the chunk>)...
//   <Data End, CRC-32 of the data section>
//   <Schema...><Channel...><Statistics><Chunk Index...>   (summary section, grouped by opcode)
//   <Summary Offset per group><Footer, CRC-32 of the summary><Magic>
// Schemas and channels sit in the data section before the first chunk and are repeated in the
// summary; every message is in a chunk that an index record finds; chunk records carry the CRC-32
// of their (uncompressed) records. CRC-32 is zlib's crc32 (the ISO-HDLC polynomial the spec means).
// Integers little-endian; strings uint32-length-prefixed UTF-8; maps uint32-byte-length-prefixed.
//
// The file is written to a temporary sibling and renamed onto its path by Close() (datasets/io.h):
// a writer destroyed without Close() leaves no file under the final name.

#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rovo {

// An MCAP string map (Channel metadata), in the order written.
using McapStringMap = std::vector<std::pair<std::string, std::string>>;

class McapWriter {
 public:
  // Opens the temporary file; throws std::runtime_error naming `path` when it cannot.
  // `chunk_bytes`: a chunk is closed once its records reach this size.
  McapWriter(std::string path, const std::string& profile, const std::string& library, uint64_t chunk_bytes = 4u << 20);
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Ids from 1 in call order. Schemas and channels must be added before the first message.
  uint16_t AddSchema(const std::string& name, const std::string& encoding, const std::string& data);
  uint16_t AddChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                      const McapStringMap& metadata);
  // A Metadata record (name, key/value pairs), written in the data section.
  void AddMetadata(const std::string& name, const McapStringMap& metadata);
  // log_time and publish_time in nanoseconds.
  void WriteMessage(uint16_t channel_id, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
                    const std::string& data);
  // Writes the last chunk, the summary and the footer, and renames the file onto its path.
  void Close();

  uint64_t MessageCount() const { return message_count_; }

 private:
  struct ChunkIndex {
    uint64_t start_time = 0, end_time = 0, offset = 0, length = 0, message_index_length = 0, records_size = 0;
    std::map<uint16_t, uint64_t> message_index_offsets;
  };
  void Write(const std::string& bytes);  // to the file, updating the offset and the data CRC
  void StartDataSection();
  void FlushChunk();
  std::string SummarySection(uint64_t summary_start, std::string* offsets) const;

  std::string path_, tmp_path_;
  std::ofstream out_;
  uint64_t chunk_bytes_;
  uint64_t offset_ = 0;
  uint32_t data_crc_ = 0;
  bool data_started_ = false, closed_ = false;
  std::vector<std::string> schema_records_, channel_records_;
  std::string metadata_records_;
  // The open chunk: its records, time span, and per channel the (log_time, offset) of its messages.
  std::string chunk_;
  uint64_t chunk_start_time_ = 0, chunk_end_time_ = 0;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_messages_;
  std::vector<ChunkIndex> chunk_indexes_;
  std::map<uint16_t, uint64_t> channel_counts_;
  uint64_t message_count_ = 0, start_time_ = 0, end_time_ = 0;
  uint32_t metadata_count_ = 0;
};

// Little-endian serialisation of the spec's field types, shared by the writer and its tests.
namespace mcap_bytes {
void PutU8(std::string* out, uint8_t v);
void PutU16(std::string* out, uint16_t v);
void PutU32(std::string* out, uint32_t v);
void PutU64(std::string* out, uint64_t v);
void PutString(std::string* out, const std::string& s);  // uint32 length + bytes
void PutRecord(std::string* out, uint8_t opcode, const std::string& content);
}  // namespace mcap_bytes

inline constexpr char kMcapMagic[8] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

}  // namespace rovo
