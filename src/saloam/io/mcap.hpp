#pragma once
// MCAP files (https://mcap.dev/spec, major version 0), read and written here
// with zstd (libzstd-dev) and LZ4 frames (liblz4-dev) for the chunks, no
// MCAP library. A file is
//   magic "\x89MCAP0\r\n", Header (op 0x01), the data section (Schema 0x03,
//   Channel 0x04, Message 0x05, Chunk 0x06 holding those compressed with
//   "zstd", "lz4" or "" (none), Message Index 0x07 after each chunk, ...,
//   Data End 0x0F), an optional summary section (Schema, Channel, Chunk
//   Index 0x08, Statistics 0x0B, ...) and summary offsets (0x0E), Footer
//   (0x02: summary_start, summary_offset_start, summary_crc), magic.
// Each record: uint8 op, uint64 length, content; integers little-endian,
// strings and maps with a uint32 byte length, times uint64 ns.
//
// McapReader: with a footer whose summary holds chunk indexes, the chunks
// and their message indexes are found through it (nothing else is read when
// the file is opened; message counts from the indexes; a chunk indexed
// without message indexes is decompressed and read through); otherwise (no
// summary, or a file cut short: no footer) the data section is read from
// the start, chunk by chunk, up to the last whole record; a chunk cut off is
// decompressed as far as its bytes go. A file cut short is noted (notes()).
// Every length and offset is checked against its record, chunk or the file
// before it is used or allocated (a chunk's stated size at most 100 times
// its compressed bytes plus 64 MiB), chunk CRCs are checked when written;
// anything that does not fit is an InputError naming the file, "corrupt MCAP
// file: ...", with the record's byte position.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/io/message_storage.hpp"

namespace saloam {

inline constexpr std::string_view kMcapMagic{"\x89MCAP0\r\n", 8};

enum class McapCompression { kNone, kZstd, kLz4 };

class McapReader final : public MessageStorage {
 public:
  explicit McapReader(std::filesystem::path file);
  ~McapReader() override;
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  [[nodiscard]] const std::filesystem::path& file() const override { return file_; }
  [[nodiscard]] const std::vector<StoredTopic>& topics() const override { return topics_; }
  std::vector<std::int64_t> select(const std::string& topic) override;
  std::vector<std::byte> message(std::size_t k, std::size_t max_bytes) override;
  [[nodiscard]] std::vector<std::string> notes() const override { return notes_; }
  /// "MCAP, indexed (2 chunks)" or "MCAP, read from the start (2 chunks)".
  [[nodiscard]] std::string kind() const override;
  /// True when the messages were found through the summary's chunk indexes.
  [[nodiscard]] bool indexed() const;

 private:
  struct Impl;
  std::filesystem::path file_;
  std::unique_ptr<Impl> impl_;
  std::vector<StoredTopic> topics_;
  std::vector<std::string> notes_;
};

/// Writes a new MCAP file (an existing one is an InputError): messages in
/// chunks of about `chunk_bytes` (uncompressed), each followed by its
/// message indexes; on close() a summary with the schemas, channels,
/// statistics and chunk indexes, summary offsets, the footer. CRCs of chunks
/// and of the summary are written. `chunk_bytes` 0: no chunks, the records
/// straight in the data section (no compression, no index: what a reader
/// reads from the start).
class McapWriter {
 public:
  McapWriter(std::filesystem::path file, McapCompression compression, std::size_t chunk_bytes = 1u << 20);
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  std::uint16_t add_schema(const std::string& name, const std::string& encoding, std::string_view data);
  std::uint16_t add_channel(const std::string& topic, std::uint16_t schema_id, const std::string& message_encoding);
  void write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::span<const std::byte> data);
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saloam
