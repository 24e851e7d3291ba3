// The MCAP writer (mcap.hpp): records into chunks, compressed, with the
// summary section and its indexes; the reader is mcap.cpp.
#include "saloam/io/mcap.hpp"

#include <zstd.h>
#include <lz4frame.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/io/mcap_records.hpp"

namespace fs = std::filesystem;

namespace saloam {

using namespace mcap_records;

namespace {

/// Little-endian fields appended to a byte buffer.
class Out {
 public:
  explicit Out(std::vector<std::byte>& bytes) : bytes_(bytes) {}
  template <class T>
  Out& integer(T v) {
    std::array<std::byte, sizeof(T)> little_endian;
    std::memcpy(little_endian.data(), &v, sizeof(T));
    return raw(little_endian);
  }
  Out& raw(std::span<const std::byte> b) {
    bytes_.insert(bytes_.end(), b.begin(), b.end());
    return *this;
  }
  Out& string(std::string_view s) {
    integer(static_cast<std::uint32_t>(s.size()));
    return raw(std::as_bytes(std::span(s.data(), s.size())));
  }
  /// A record: op, length, then what `content` appends.
  template <class F>
  Out& record(std::uint8_t op, F&& content) {
    integer(op);
    const auto length_at = bytes_.size();
    integer(std::uint64_t{0});
    content(*this);
    const std::uint64_t length = bytes_.size() - length_at - 8;
    std::memcpy(bytes_.data() + length_at, &length, 8);
    return *this;
  }

 private:
  std::vector<std::byte>& bytes_;
};

std::vector<std::byte> compress(McapCompression compression, std::span<const std::byte> in, const fs::path& file) {
  std::vector<std::byte> out;
  if (compression == McapCompression::kZstd) {
    out.resize(ZSTD_compressBound(in.size()));
    const std::size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3);
    if (ZSTD_isError(n)) throw InputError(file, fmt::format("zstd: {}", ZSTD_getErrorName(n)));
    out.resize(n);
  } else if (compression == McapCompression::kLz4) {
    out.resize(LZ4F_compressFrameBound(in.size(), nullptr));
    const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
    if (LZ4F_isError(n)) throw InputError(file, fmt::format("lz4: {}", LZ4F_getErrorName(n)));
    out.resize(n);
  } else {
    out.assign(in.begin(), in.end());
  }
  return out;
}

std::string_view compression_name(McapCompression c) {
  return c == McapCompression::kZstd ? "zstd" : c == McapCompression::kLz4 ? "lz4" : "";
}

struct ChunkIndexEntry {
  std::uint64_t start = 0, end = 0, at = 0, length = 0, index_length = 0, compressed = 0, uncompressed = 0;
  std::vector<std::pair<std::uint16_t, std::uint64_t>> index_offsets;
};

}  // namespace

struct McapWriter::Impl {
  fs::path file;
  std::ofstream out;
  std::uint64_t written = 0;
  McapCompression compression;
  std::size_t chunk_bytes;
  std::vector<std::byte> summary_schemas, summary_channels;
  std::vector<std::byte> chunk;  ///< the records of the open chunk
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index;  ///< channel -> (time, offset)
  std::uint64_t chunk_start = std::numeric_limits<std::uint64_t>::max(), chunk_end = 0;
  std::vector<ChunkIndexEntry> chunk_indexes;
  std::map<std::uint16_t, std::uint64_t> counts;
  std::uint64_t messages = 0, first = std::numeric_limits<std::uint64_t>::max(), last = 0;
  std::uint16_t schemas = 0, channels = 0;
  bool open = true;

  void put(std::span<const std::byte> bytes) {
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw InputError(file, "cannot write the MCAP file");
    written += bytes.size();
  }
  void flush_chunk();
  void write_summary();
  /// Where a data-section record goes: the open chunk, or (unchunked) the file.
  template <class F>
  void data_record(std::uint8_t op, F&& content) {
    if (chunk_bytes > 0) {
      Out(chunk).record(op, content);
      return;
    }
    std::vector<std::byte> bytes;
    Out(bytes).record(op, content);
    put(bytes);
  }
};

void McapWriter::Impl::flush_chunk() {
  if (chunk.empty()) return;
  const auto stored = compress(compression, chunk, file);
  ChunkIndexEntry entry;
  entry.at = written;
  entry.start = chunk_index.empty() ? 0 : chunk_start;
  entry.end = chunk_index.empty() ? 0 : chunk_end;
  entry.compressed = stored.size();
  entry.uncompressed = chunk.size();
  std::vector<std::byte> bytes;
  Out(bytes).record(kChunk, [&](Out& o) {
    o.integer(entry.start).integer(entry.end).integer(entry.uncompressed).integer(crc32(chunk));
    o.string(compression_name(compression)).integer(std::uint64_t{stored.size()}).raw(stored);
  });
  put(bytes);
  entry.length = bytes.size();
  const std::uint64_t index_at = written;
  // (No structured bindings captured by the lambdas: clang 14 cannot.)
  for (const auto& channel_entries : chunk_index) {
    const std::uint16_t channel = channel_entries.first;
    const auto& entries = channel_entries.second;
    entry.index_offsets.emplace_back(channel, written);
    std::vector<std::byte> index;
    Out(index).record(kMessageIndex, [&](Out& o) {
      o.integer(channel).integer(static_cast<std::uint32_t>(entries.size() * 16));
      for (const auto& [time, offset] : entries) o.integer(time).integer(offset);
    });
    put(index);
  }
  entry.index_length = written - index_at;
  chunk_indexes.push_back(std::move(entry));
  chunk.clear();
  chunk_index.clear();
  chunk_start = std::numeric_limits<std::uint64_t>::max();
  chunk_end = 0;
}

void McapWriter::Impl::write_summary() {
  std::vector<std::byte> data_end;
  Out(data_end).record(kDataEnd, [](Out& o) { o.integer(std::uint32_t{0}); });
  put(data_end);
  const std::uint64_t summary_start = written;
  std::vector<std::byte> summary;
  std::vector<std::pair<std::uint8_t, std::pair<std::uint64_t, std::uint64_t>>> groups;
  const auto group = [&](std::uint8_t op, auto&& add) {
    const std::uint64_t at = summary.size();
    add();
    if (summary.size() > at) groups.push_back({op, {summary_start + at, summary.size() - at}});
  };
  group(kSchema, [&] { summary.insert(summary.end(), summary_schemas.begin(), summary_schemas.end()); });
  group(kChannel, [&] { summary.insert(summary.end(), summary_channels.begin(), summary_channels.end()); });
  group(kStatistics, [&] {
    Out(summary).record(kStatistics, [&](Out& o) {
      o.integer(messages).integer(schemas).integer(std::uint32_t{channels}).integer(std::uint32_t{0}).integer(std::uint32_t{0});
      o.integer(static_cast<std::uint32_t>(chunk_indexes.size()));
      o.integer(messages ? first : 0).integer(messages ? last : 0).integer(static_cast<std::uint32_t>(counts.size() * 10));
      for (const auto& [channel, n] : counts) o.integer(channel).integer(n);
    });
  });
  group(kChunkIndex, [&] {
    for (const auto& c : chunk_indexes) {
      Out(summary).record(kChunkIndex, [&](Out& o) {
        o.integer(c.start).integer(c.end).integer(c.at).integer(c.length);
        o.integer(static_cast<std::uint32_t>(c.index_offsets.size() * 10));
        for (const auto& [channel, at] : c.index_offsets) o.integer(channel).integer(at);
        o.integer(c.index_length).string(compression_name(compression)).integer(c.compressed).integer(c.uncompressed);
      });
    }
  });
  const std::uint64_t offsets_start = summary_start + summary.size();
  for (const auto& g : groups) {
    Out(summary).record(kSummaryOffset, [&](Out& o) { o.integer(g.first).integer(g.second.first).integer(g.second.second); });
  }
  Out(summary).integer(kFooter).integer(std::uint64_t{20}).integer(summary_start).integer(offsets_start);
  Out(summary).integer(crc32(summary));
  put(summary);
  put(std::as_bytes(std::span(kMcapMagic.data(), kMcapMagic.size())));
}

McapWriter::McapWriter(fs::path file, McapCompression compression, std::size_t chunk_bytes) : impl_(std::make_unique<Impl>()) {
  impl_->file = std::move(file);
  impl_->compression = compression;
  impl_->chunk_bytes = chunk_bytes;
  std::error_code ec;
  if (fs::exists(impl_->file, ec)) throw InputError(impl_->file, "exists: write an MCAP file into a new file");
  impl_->out.open(impl_->file, std::ios::binary);
  if (!impl_->out) throw InputError(impl_->file, "cannot create the MCAP file");
  std::vector<std::byte> head(reinterpret_cast<const std::byte*>(kMcapMagic.data()),
                              reinterpret_cast<const std::byte*>(kMcapMagic.data()) + kMcapMagic.size());
  Out(head).record(kHeader, [](Out& o) { o.string("ros2").string("saloam"); });
  impl_->put(head);
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (const std::exception&) {
    // A destructor must not throw; close() explicitly to see the error.
  }
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, std::string_view data) {
  const auto id = ++impl_->schemas;
  const auto content = [&](Out& o) { o.integer(id).string(name).string(encoding).string(data); };
  impl_->data_record(kSchema, content);
  Out(impl_->summary_schemas).record(kSchema, content);
  return id;
}

std::uint16_t McapWriter::add_channel(const std::string& topic, std::uint16_t schema_id, const std::string& message_encoding) {
  const auto id = impl_->channels++;
  const auto content = [&](Out& o) {
    o.integer(id).integer(schema_id).string(topic).string(message_encoding).integer(std::uint32_t{0});
  };
  impl_->data_record(kChannel, content);
  Out(impl_->summary_channels).record(kChannel, content);
  return id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::span<const std::byte> data) {
  Impl& w = *impl_;
  if (w.chunk_bytes > 0) w.chunk_index[channel_id].emplace_back(log_time_ns, w.chunk.size());
  w.data_record(kMessage, [&](Out& o) {
    o.integer(channel_id).integer(static_cast<std::uint32_t>(w.counts[channel_id])).integer(log_time_ns).integer(log_time_ns).raw(data);
  });
  ++w.counts[channel_id];
  ++w.messages;
  w.first = std::min(w.first, log_time_ns);
  w.last = std::max(w.last, log_time_ns);
  w.chunk_start = std::min(w.chunk_start, log_time_ns);
  w.chunk_end = std::max(w.chunk_end, log_time_ns);
  if (w.chunk_bytes > 0 && w.chunk.size() >= w.chunk_bytes) w.flush_chunk();
}

void McapWriter::close() {
  if (!impl_->open) return;
  impl_->open = false;
  impl_->flush_chunk();
  impl_->write_summary();
  impl_->out.close();
  if (!impl_->out) throw InputError(impl_->file, "cannot write the MCAP file");
}

}  // namespace saloam
