// MCAP reader (mcap_reader.h): a linear scan of the data section.
#include "datasets/exchange/mcap_reader.h"

#include <zlib.h>

#include <cstring>
#include <stdexcept>

namespace rovo {
namespace {

uint32_t Crc32(std::string_view bytes) {
  // zlib takes at most UINT_MAX bytes per call.
  uLong crc = crc32(0, nullptr, 0);
  for (size_t at = 0; at < bytes.size();) {
    const size_t n = std::min<size_t>(bytes.size() - at, 1u << 30);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + at), static_cast<uInt>(n));
    at += n;
  }
  return static_cast<uint32_t>(crc);
}

const char* RecordName(uint8_t opcode) {
  switch (opcode) {
    case 0x01:
      return "Header";
    case 0x02:
      return "Footer";
    case 0x03:
      return "Schema";
    case 0x04:
      return "Channel";
    case 0x05:
      return "Message";
    case 0x06:
      return "Chunk";
    case 0x07:
      return "Message Index";
    case 0x09:
      return "Attachment";
    case 0x0C:
      return "Metadata";
    case 0x0F:
      return "Data End";
    default:
      return opcode >= 0x80 ? "private record" : "unknown record";
  }
}

// Reads the spec's field types from one record's content; errors name the record and the field.
class Fields {
 public:
  Fields(std::string_view bytes, std::string where) : bytes_(bytes), where_(std::move(where)) {}
  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    throw std::runtime_error(where_ + ": " + field + ": " + problem);
  }
  std::string_view Take(size_t n, const char* field) {
    if (n > bytes_.size() - pos_) {
      Fail(field,
           "needs " + std::to_string(n) + " bytes, the record has " + std::to_string(bytes_.size() - pos_) + " left");
    }
    const std::string_view out = bytes_.substr(pos_, n);
    pos_ += n;
    return out;
  }
  uint64_t Uint(int width, const char* field) {
    const std::string_view b = Take(static_cast<size_t>(width), field);
    uint64_t v = 0;
    for (int i = width - 1; i >= 0; --i) v = (v << 8) | static_cast<uint8_t>(b[static_cast<size_t>(i)]);
    return v;
  }
  uint16_t U16(const char* field) { return static_cast<uint16_t>(Uint(2, field)); }
  uint32_t U32(const char* field) { return static_cast<uint32_t>(Uint(4, field)); }
  uint64_t U64(const char* field) { return Uint(8, field); }
  std::string String(const char* field) {
    const uint32_t n = U32(field);
    return std::string(Take(n, field));
  }
  McapStringMap Map(const char* field) {
    const uint32_t n = U32(field);
    Fields entries(Take(n, field), where_);
    McapStringMap out;
    while (!entries.AtEnd()) {
      std::string key = entries.String(field);
      std::string value = entries.String(field);
      out.emplace_back(std::move(key), std::move(value));
    }
    return out;
  }
  std::string_view Rest() { return Take(bytes_.size() - pos_, "data"); }
  bool AtEnd() const { return pos_ == bytes_.size(); }
  const std::string& where() const { return where_; }

 private:
  std::string_view bytes_;
  size_t pos_ = 0;
  std::string where_;
};

class Reader {
 public:
  Reader(std::string_view file, std::string what, const McapMessageCallback& on_message)
      : file_(file), what_(std::move(what)), on_message_(on_message) {}

  McapContents Read() {
    const size_t magic = sizeof(kMcapMagic);
    if (file_.size() < 2 * magic || std::memcmp(file_.data(), kMcapMagic, magic) != 0) {
      throw std::runtime_error(what_ + ": byte 0: not an MCAP file (magic \\x89MCAP0\\r\\n missing)");
    }
    if (std::memcmp(file_.data() + file_.size() - magic, kMcapMagic, magic) != 0) {
      throw std::runtime_error(what_ + ": byte " + std::to_string(file_.size() - magic) +
                               ": the trailing magic is missing (a truncated file?)");
    }
    ReadRecords(file_.substr(0, file_.size() - magic), magic, "");
    if (!seen_header_) throw std::runtime_error(what_ + ": byte 8: no Header record");
    if (!seen_end_) throw std::runtime_error(what_ + ": no Footer record before the trailing magic");
    return std::move(contents_);
  }

 private:
  // Records of `bytes` (the file, or a chunk's records at `base` offset when `chunk` names it).
  void ReadRecords(std::string_view bytes, size_t start, const std::string& chunk) {
    size_t pos = start;
    while (pos < bytes.size() && !seen_end_) {
      const std::string at = what_ + ": record at byte " + std::to_string(pos) + chunk;
      if (bytes.size() - pos < 9) throw std::runtime_error(at + ": opcode and length: the file ends inside them");
      const auto opcode = static_cast<uint8_t>(bytes[pos]);
      uint64_t length = 0;
      for (int i = 7; i >= 0; --i)
        length = (length << 8) | static_cast<uint8_t>(bytes[pos + 1 + static_cast<size_t>(i)]);
      const std::string where = at + " (" + RecordName(opcode) + ")";
      if (length > bytes.size() - pos - 9) {
        throw std::runtime_error(where + ": length: " + std::to_string(length) + " bytes, but only " +
                                 std::to_string(bytes.size() - pos - 9) + " remain");
      }
      if (opcode == 0) throw std::runtime_error(where + ": opcode: 0 is not a valid opcode");
      Fields fields(bytes.substr(pos + 9, length), where);
      if (!chunk.empty() && opcode != 0x03 && opcode != 0x04 && opcode != 0x05 && opcode < 0x80) {
        fields.Fail("opcode", "a chunk holds only Schema, Channel and Message records");
      }
      if (chunk.empty() && !seen_header_ && opcode != 0x01) fields.Fail("opcode", "the first record must be a Header");
      Dispatch(opcode, fields, pos);
      pos += 9 + length;
    }
  }

  void Dispatch(uint8_t opcode, Fields& f, size_t pos) {
    switch (opcode) {
      case 0x01:
        if (seen_header_) f.Fail("opcode", "a second Header record");
        contents_.profile = f.String("profile");
        contents_.library = f.String("library");
        seen_header_ = true;
        break;
      case 0x03:
        ReadSchema(f);
        break;
      case 0x04:
        ReadChannel(f);
        break;
      case 0x05:
        ReadMessage(f);
        break;
      case 0x06:
        ReadChunk(f, pos);
        break;
      case 0x0C: {
        McapMetadata m;
        m.name = f.String("name");
        m.metadata = f.Map("metadata");
        contents_.metadata.push_back(std::move(m));
        break;
      }
      case 0x0F:
        ReadDataEnd(f, pos);
        break;
      case 0x02:
        seen_end_ = true;  // a file without Data End: the footer closes the data section
        break;
      default:  // Message Index, Attachment, ... and private records: not needed for a linear read
        break;
    }
  }

  void ReadSchema(Fields& f) {
    McapSchema s;
    s.id = f.U16("id");
    s.name = f.String("name");
    s.encoding = f.String("encoding");
    s.data = f.String("data");
    if (s.id == 0) return;  // invalid, ignored by readers (spec)
    const auto [it, added] = contents_.schemas.emplace(s.id, s);
    if (!added && !(it->second == s)) f.Fail("id", "schema " + std::to_string(s.id) + " defined twice, differently");
  }

  void ReadChannel(Fields& f) {
    McapChannel c;
    c.id = f.U16("id");
    c.schema_id = f.U16("schema_id");
    c.topic = f.String("topic");
    c.message_encoding = f.String("message_encoding");
    c.metadata = f.Map("metadata");
    if (c.schema_id != 0 && contents_.schemas.count(c.schema_id) == 0) {
      f.Fail("schema_id", std::to_string(c.schema_id) + " names no earlier Schema record");
    }
    const auto [it, added] = contents_.channels.emplace(c.id, c);
    if (!added && !(it->second == c)) f.Fail("id", "channel " + std::to_string(c.id) + " defined twice, differently");
  }

  void ReadMessage(Fields& f) {
    McapMessage m;
    m.channel_id = f.U16("channel_id");
    m.sequence = f.U32("sequence");
    m.log_time = f.U64("log_time");
    m.publish_time = f.U64("publish_time");
    m.data = f.Rest();
    m.where = f.where();
    const auto channel = contents_.channels.find(m.channel_id);
    if (channel == contents_.channels.end()) {
      f.Fail("channel_id", std::to_string(m.channel_id) + " names no earlier Channel record");
    }
    const auto schema = contents_.schemas.find(channel->second.schema_id);
    ++contents_.message_count;
    if (on_message_) on_message_(schema == contents_.schemas.end() ? nullptr : &schema->second, channel->second, m);
  }

  void ReadChunk(Fields& f, size_t pos) {
    f.U64("message_start_time");
    f.U64("message_end_time");
    const uint64_t uncompressed_size = f.U64("uncompressed_size");
    const uint32_t crc = f.U32("uncompressed_crc");
    const std::string compression = f.String("compression");
    const uint64_t size = f.U64("records");
    if (size > static_cast<uint64_t>(SIZE_MAX)) f.Fail("records", "too long");
    const std::string_view records = f.Take(static_cast<size_t>(size), "records");
    if (!compression.empty()) {
      f.Fail("compression", "'" + compression + "' chunks are not read (only uncompressed chunks, compression \"\")");
    }
    if (uncompressed_size != records.size()) {
      f.Fail("uncompressed_size", std::to_string(uncompressed_size) + ", but the records field holds " +
                                      std::to_string(records.size()) + " bytes");
    }
    if (crc != 0 && Crc32(records) != crc) f.Fail("uncompressed_crc", "the CRC-32 of the records differs");
    ++contents_.chunk_count;
    ReadRecords(records, 0, " in the chunk at byte " + std::to_string(pos));
  }

  void ReadDataEnd(Fields& f, size_t pos) {
    const uint32_t crc = f.U32("data_section_crc");
    if (crc != 0 && Crc32(file_.substr(0, pos)) != crc) {
      f.Fail("data_section_crc", "the CRC-32 of the data section differs");
    }
    seen_end_ = true;
  }

  std::string_view file_;
  std::string what_;
  const McapMessageCallback& on_message_;
  McapContents contents_;
  bool seen_header_ = false, seen_end_ = false;
};

}  // namespace

McapContents ReadMcap(std::string_view bytes, const std::string& what, const McapMessageCallback& on_message) {
  return Reader(bytes, what, on_message).Read();
}

}  // namespace rovo
