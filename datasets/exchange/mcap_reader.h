#pragma once
// An MCAP file reader, written from the MCAP format specification, major version 0 (foxglove/mcap,
// website/docs/spec/index.md). It reads the data section from start to end (no index needed):
// Header, Schema, Channel, Message, Chunk (uncompressed, compression ""; its records read the same
// way), Metadata and Data End; Message Index, Attachment and private records are skipped, and so
// is the summary section. It checks the magic at both ends, every length against the bytes that
// remain, every chunk's CRC-32 and the data section's CRC-32 (a stored 0 means none), that each
// message's channel and each channel's schema came earlier, and that duplicated ids are identical.
// A compressed chunk (zstd, lz4) is refused with its compression named.
//
// Errors are std::runtime_error "<what>: record at byte N (<Record>): <field>: <problem>", with N the
// offset of the record in the file, or "... in the chunk at byte M" for records inside a chunk.

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "datasets/exchange/mcap_writer.h"

namespace rovo {

struct McapSchema {
  uint16_t id = 0;
  std::string name, encoding, data;
  bool operator==(const McapSchema& o) const {
    return id == o.id && name == o.name && encoding == o.encoding && data == o.data;
  }
};

struct McapChannel {
  uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
  McapStringMap metadata;
  bool operator==(const McapChannel& o) const {
    return id == o.id && schema_id == o.schema_id && topic == o.topic && message_encoding == o.message_encoding &&
           metadata == o.metadata;
  }
};

struct McapMessage {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0, publish_time = 0;  // ns
  std::string_view data;                    // points into the bytes given to ReadMcap
  std::string where;                        // "<what>: record at byte N (Message)" for the decoder's errors
};

struct McapMetadata {
  std::string name;
  McapStringMap metadata;
};

struct McapContents {
  std::string profile, library;
  std::map<uint16_t, McapSchema> schemas;
  std::map<uint16_t, McapChannel> channels;
  std::vector<McapMetadata> metadata;
  uint64_t message_count = 0;
  int chunk_count = 0;
};

// Reads the whole file `bytes` (named `what` in errors), calling `on_message` for every message in
// file order with its channel and that channel's schema (nullptr for schema id 0).
using McapMessageCallback = std::function<void(const McapSchema*, const McapChannel&, const McapMessage&)>;
McapContents ReadMcap(std::string_view bytes, const std::string& what, const McapMessageCallback& on_message);

}  // namespace rovo
