// MCAP writer (mcap_writer.h), records as the MCAP specification defines them.
#include "datasets/exchange/mcap_writer.h"

#include <zlib.h>

#include <filesystem>
#include <stdexcept>

#include "datasets/io.h"

namespace rovo {
namespace mcap_bytes {

void PutU8(std::string* out, uint8_t v) { out->push_back(static_cast<char>(v)); }
void PutU16(std::string* out, uint16_t v) {
  for (int i = 0; i < 2; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void PutU32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void PutU64(std::string* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void PutString(std::string* out, const std::string& s) {
  PutU32(out, static_cast<uint32_t>(s.size()));
  out->append(s);
}
void PutRecord(std::string* out, uint8_t opcode, const std::string& content) {
  PutU8(out, opcode);
  PutU64(out, content.size());
  out->append(content);
}

}  // namespace mcap_bytes

namespace {

using namespace mcap_bytes;  // NOLINT(google-build-using-namespace): the spec's field writers

enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

uint32_t Crc32(uint32_t crc, const std::string& bytes) {
  return static_cast<uint32_t>(
      crc32(crc, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

std::string MapBytes(const McapStringMap& map) {
  std::string entries;
  for (const auto& [key, value] : map) {
    PutString(&entries, key);
    PutString(&entries, value);
  }
  std::string out;
  PutU32(&out, static_cast<uint32_t>(entries.size()));
  return out + entries;
}

}  // namespace

McapWriter::McapWriter(std::string path, const std::string& profile, const std::string& library, uint64_t chunk_bytes)
    : path_(std::move(path)), tmp_path_(TempPathFor(path_)), chunk_bytes_(chunk_bytes) {
  std::filesystem::create_directories(std::filesystem::path(path_).parent_path());
  out_.open(tmp_path_, std::ios::binary | std::ios::trunc);
  if (!out_) throw std::runtime_error(path_ + ": cannot open " + tmp_path_ + " for writing");
  std::string header;
  PutString(&header, profile);
  PutString(&header, library);
  std::string bytes(kMcapMagic, sizeof(kMcapMagic));
  PutRecord(&bytes, kHeader, header);
  Write(bytes);
}

McapWriter::~McapWriter() {
  if (!closed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(tmp_path_, ec);
  }
}

void McapWriter::Write(const std::string& bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out_) throw std::runtime_error(path_ + ": write failed at byte " + std::to_string(offset_));
  data_crc_ = Crc32(data_crc_, bytes);
  offset_ += bytes.size();
}

uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  if (data_started_) throw std::logic_error("McapWriter::AddSchema after the first message");
  const auto id = static_cast<uint16_t>(schema_records_.size() + 1);
  std::string content;
  PutU16(&content, id);
  PutString(&content, name);
  PutString(&content, encoding);
  PutString(&content, data);  // uint32-length-prefixed bytes
  schema_records_.push_back(content);
  return id;
}

uint16_t McapWriter::AddChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                                const McapStringMap& metadata) {
  if (data_started_) throw std::logic_error("McapWriter::AddChannel after the first message");
  const auto id = static_cast<uint16_t>(channel_records_.size() + 1);
  std::string content;
  PutU16(&content, id);
  PutU16(&content, schema_id);
  PutString(&content, topic);
  PutString(&content, message_encoding);
  content += MapBytes(metadata);
  channel_records_.push_back(content);
  channel_counts_[id] = 0;
  return id;
}

void McapWriter::AddMetadata(const std::string& name, const McapStringMap& metadata) {
  if (data_started_) throw std::logic_error("McapWriter::AddMetadata after the first message");
  std::string content;
  PutString(&content, name);
  content += MapBytes(metadata);
  PutRecord(&metadata_records_, kMetadata, content);
  ++metadata_count_;
}

void McapWriter::StartDataSection() {
  std::string bytes;
  for (const std::string& s : schema_records_) PutRecord(&bytes, kSchema, s);
  for (const std::string& c : channel_records_) PutRecord(&bytes, kChannel, c);
  bytes += metadata_records_;
  Write(bytes);
  data_started_ = true;
}

void McapWriter::WriteMessage(uint16_t channel_id, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
                              const std::string& data) {
  if (closed_) throw std::logic_error("McapWriter::WriteMessage after Close");
  if (channel_id == 0 || channel_id > channel_records_.size()) {
    throw std::logic_error("McapWriter::WriteMessage: unknown channel " + std::to_string(channel_id));
  }
  if (!data_started_) StartDataSection();
  if (chunk_.empty() || log_time < chunk_start_time_) chunk_start_time_ = log_time;
  if (chunk_.empty() || log_time > chunk_end_time_) chunk_end_time_ = log_time;
  chunk_messages_[channel_id].emplace_back(log_time, chunk_.size());
  std::string content;
  PutU16(&content, channel_id);
  PutU32(&content, sequence);
  PutU64(&content, log_time);
  PutU64(&content, publish_time);
  content += data;
  PutRecord(&chunk_, kMessage, content);
  if (message_count_ == 0 || log_time < start_time_) start_time_ = log_time;
  if (message_count_ == 0 || log_time > end_time_) end_time_ = log_time;
  ++message_count_;
  ++channel_counts_[channel_id];
  if (chunk_.size() >= chunk_bytes_) FlushChunk();
}

void McapWriter::FlushChunk() {
  if (chunk_.empty()) return;
  ChunkIndex index;
  index.start_time = chunk_start_time_;
  index.end_time = chunk_end_time_;
  index.offset = offset_;
  index.records_size = chunk_.size();
  std::string content;
  PutU64(&content, chunk_start_time_);
  PutU64(&content, chunk_end_time_);
  PutU64(&content, chunk_.size());     // uncompressed_size
  PutU32(&content, Crc32(0, chunk_));  // uncompressed_crc
  PutString(&content, "");             // compression: none
  PutU64(&content, chunk_.size());     // records, uint64-length-prefixed
  content += chunk_;
  std::string bytes;
  PutRecord(&bytes, kChunk, content);
  index.length = bytes.size();
  for (const auto& [channel, entries] : chunk_messages_) {
    index.message_index_offsets[channel] = offset_ + bytes.size();
    std::string record;
    PutU16(&record, channel);
    PutU32(&record, static_cast<uint32_t>(entries.size() * 16));
    for (const auto& [time, at] : entries) {
      PutU64(&record, time);
      PutU64(&record, at);
    }
    const size_t before = bytes.size();
    PutRecord(&bytes, kMessageIndex, record);
    index.message_index_length += bytes.size() - before;
  }
  Write(bytes);
  chunk_indexes_.push_back(index);
  chunk_.clear();
  chunk_messages_.clear();
}

std::string McapWriter::SummarySection(uint64_t summary_start, std::string* offsets) const {
  std::string summary;
  auto group = [&](uint8_t opcode, const std::string& records) {
    if (records.empty()) return;
    std::string offset_record;
    PutU8(&offset_record, opcode);
    PutU64(&offset_record, summary_start + summary.size());
    PutU64(&offset_record, records.size());
    PutRecord(offsets, kSummaryOffset, offset_record);
    summary += records;
  };
  std::string schemas, channels, statistics, chunk_indexes;
  for (const std::string& s : schema_records_) PutRecord(&schemas, kSchema, s);
  for (const std::string& c : channel_records_) PutRecord(&channels, kChannel, c);
  std::string stats;
  PutU64(&stats, message_count_);
  PutU16(&stats, static_cast<uint16_t>(schema_records_.size()));
  PutU32(&stats, static_cast<uint32_t>(channel_records_.size()));
  PutU32(&stats, 0);  // attachments
  PutU32(&stats, metadata_count_);
  PutU32(&stats, static_cast<uint32_t>(chunk_indexes_.size()));
  PutU64(&stats, start_time_);
  PutU64(&stats, end_time_);
  PutU32(&stats, static_cast<uint32_t>(channel_counts_.size() * 10));
  for (const auto& [channel, count] : channel_counts_) {
    PutU16(&stats, channel);
    PutU64(&stats, count);
  }
  PutRecord(&statistics, kStatistics, stats);
  for (const ChunkIndex& c : chunk_indexes_) {
    std::string record;
    PutU64(&record, c.start_time);
    PutU64(&record, c.end_time);
    PutU64(&record, c.offset);
    PutU64(&record, c.length);
    PutU32(&record, static_cast<uint32_t>(c.message_index_offsets.size() * 10));
    for (const auto& [channel, at] : c.message_index_offsets) {
      PutU16(&record, channel);
      PutU64(&record, at);
    }
    PutU64(&record, c.message_index_length);
    PutString(&record, "");
    PutU64(&record, c.records_size);  // compressed_size
    PutU64(&record, c.records_size);  // uncompressed_size
    PutRecord(&chunk_indexes, kChunkIndex, record);
  }
  group(kSchema, schemas);
  group(kChannel, channels);
  group(kStatistics, statistics);
  group(kChunkIndex, chunk_indexes);
  return summary;
}

void McapWriter::Close() {
  if (closed_) return;
  if (!data_started_) StartDataSection();
  FlushChunk();
  std::string data_end;
  PutU32(&data_end, data_crc_);
  std::string bytes;
  PutRecord(&bytes, kDataEnd, data_end);
  Write(bytes);
  const uint64_t summary_start = offset_;
  std::string offsets;
  const std::string summary = SummarySection(summary_start, &offsets);
  const uint64_t summary_offset_start = summary_start + summary.size();
  // Footer: its CRC covers the summary, the summary offsets and the footer up to summary_offset_start.
  std::string footer_prefix;
  PutU8(&footer_prefix, kFooter);
  PutU64(&footer_prefix, 8 + 8 + 4);
  PutU64(&footer_prefix, summary_start);
  PutU64(&footer_prefix, summary_offset_start);
  const uint32_t summary_crc = Crc32(Crc32(Crc32(0, summary), offsets), footer_prefix);
  std::string tail = summary + offsets + footer_prefix;
  PutU32(&tail, summary_crc);
  tail.append(kMcapMagic, sizeof(kMcapMagic));
  Write(tail);
  out_.close();
  if (!out_) throw std::runtime_error(path_ + ": cannot close " + tmp_path_);
  CommitTempFile(tmp_path_, path_);
  closed_ = true;
}

}  // namespace rovo
