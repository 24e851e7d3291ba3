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

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr std::uint8_t kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06,
                       kMessageIndex = 0x07, kChunkIndex = 0x08, kStatistics = 0x0B, kSummaryOffset = 0x0E,
                       kDataEnd = 0x0F;
constexpr std::uint64_t kRecordHead = 9;          // op, uint64 length
constexpr std::uint64_t kFooterRecord = 9 + 20;   // summary_start, summary_offset_start, summary_crc
constexpr std::uint64_t kMessageHead = 2 + 4 + 8 + 8;  // channel_id, sequence, log_time, publish_time
constexpr std::uint64_t kMaxChunkRatio = 100;      // point clouds compress far less
constexpr std::uint64_t kChunkSlack = 64ull << 20;
constexpr std::size_t kNoChunk = std::numeric_limits<std::size_t>::max();
/// Asked for fewer bytes of a message (a header), a chunk is decompressed
/// only as far as them, and not kept.
constexpr std::size_t kWholeChunkFrom = 1u << 16;

std::uint32_t crc32(std::span<const std::byte> bytes, std::uint32_t crc = 0) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (const std::byte b : bytes) crc = table[(crc ^ static_cast<std::uint8_t>(b)) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

/// Where in the file a problem is, for its message.
struct Place {
  const fs::path& file;
  std::string where;  ///< "chunk at byte 1234"
  [[nodiscard]] InputError error(const std::string& problem) const {
    return InputError(file, fmt::format("corrupt MCAP file: {}: {}", where, problem));
  }
};

/// Reads the little-endian fields of one record's content, each checked
/// against the bytes left.
class Fields {
 public:
  Fields(std::span<const std::byte> bytes, Place place) : bytes_(bytes), place_(std::move(place)) {}
  std::span<const std::byte> take(std::uint64_t n, std::string_view what) {
    if (n > bytes_.size() - at_) {
      throw place_.error(fmt::format("{} of {} bytes runs past its record ({} left)", what, n, bytes_.size() - at_));
    }
    const auto out = bytes_.subspan(at_, n);
    at_ += n;
    return out;
  }
  template <class T>
  T integer(std::string_view what) {
    T v;
    std::memcpy(&v, take(sizeof(T), what).data(), sizeof(T));
    return v;
  }
  std::string string(std::string_view what) {
    const auto bytes = take(integer<std::uint32_t>(what), what);
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }
  /// A uint32-length-prefixed field, as bytes (maps, arrays, schema data).
  std::span<const std::byte> prefixed(std::string_view what) { return take(integer<std::uint32_t>(what), what); }
  [[nodiscard]] std::span<const std::byte> rest() { return take(bytes_.size() - at_, "rest"); }

 private:
  std::span<const std::byte> bytes_;
  Place place_;  ///< a copy: callers pass temporaries (at(pos, "message"))
  std::size_t at_ = 0;
};

struct Channel {
  std::uint16_t schema_id = 0;
  std::string topic, encoding;
};

struct Chunk {
  std::uint64_t at = 0;  ///< the chunk record's opcode in the file
  bool cut_off = false;  ///< the file ends inside it
  std::uint64_t length = 0;  ///< of the whole record, as its chunk index says (0: not indexed)
};

/// A message: in a chunk (offset of its record in the decompressed records)
/// or in the data section (offset of its record in the file).
struct MessageRef {
  std::uint64_t log_time = 0;
  std::uint16_t channel = 0;
  std::size_t chunk = kNoChunk;
  std::uint64_t offset = 0;
};

std::vector<std::byte> zstd_decompress(std::span<const std::byte> in, std::uint64_t size, bool cut_off, const Place& place) {
  std::vector<std::byte> out(size);
  if (!cut_off) {
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), in.data(), in.size());
    if (ZSTD_isError(n)) throw place.error(fmt::format("zstd: {}", ZSTD_getErrorName(n)));
    if (n != size) throw place.error(fmt::format("zstd gave {} bytes, the chunk says {}", n, size));
    return out;
  }
  ZSTD_DCtx* ctx = ZSTD_createDCtx();
  ZSTD_inBuffer src{in.data(), in.size(), 0};
  ZSTD_outBuffer dst{out.data(), out.size(), 0};
  while (src.pos < src.size && dst.pos < dst.size) {
    const std::size_t rc = ZSTD_decompressStream(ctx, &dst, &src);
    if (ZSTD_isError(rc) || rc == 0) break;  // as far as the bytes go
  }
  ZSTD_freeDCtx(ctx);
  out.resize(dst.pos);
  return out;
}

std::vector<std::byte> lz4_decompress(std::span<const std::byte> in, std::uint64_t size, bool cut_off, const Place& place) {
  std::vector<std::byte> out(size);
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) throw place.error("lz4: no decompression context");
  std::size_t in_at = 0, out_at = 0, rc = 1;
  while (in_at < in.size() && rc != 0) {
    std::size_t src_size = in.size() - in_at, dst_size = out.size() - out_at;
    rc = LZ4F_decompress(ctx, out.data() + out_at, &dst_size, in.data() + in_at, &src_size, nullptr);
    if (LZ4F_isError(rc)) {
      LZ4F_freeDecompressionContext(ctx);
      if (cut_off) break;
      throw place.error(fmt::format("lz4: {}", LZ4F_getErrorName(rc)));
    }
    in_at += src_size;
    out_at += dst_size;
    if (src_size == 0 && dst_size == 0) break;  // no progress: output full
  }
  if (!LZ4F_isError(rc)) LZ4F_freeDecompressionContext(ctx);
  if (!cut_off && (out_at != size || rc != 0)) throw place.error(fmt::format("lz4 gave {} bytes, the chunk says {}", out_at, size));
  out.resize(out_at);
  return out;
}

std::vector<std::byte> decompress(const std::string& compression, std::span<const std::byte> in, std::uint64_t size,
                                  bool cut_off, const Place& place) {
  if (compression.empty()) {
    if (!cut_off && in.size() != size) throw place.error(fmt::format("uncompressed records of {} bytes, the chunk says {}", in.size(), size));
    return {in.begin(), in.begin() + static_cast<std::ptrdiff_t>(std::min<std::uint64_t>(in.size(), size))};
  }
  if (compression == "zstd") return zstd_decompress(in, size, cut_off, place);
  if (compression == "lz4") return lz4_decompress(in, size, cut_off, place);
  throw place.error(fmt::format("unknown compression '{}' (saloam reads zstd, lz4 and none)", compression.substr(0, 20)));
}

}  // namespace

struct McapReader::Impl {
  const fs::path& file;
  std::ifstream in;
  std::uint64_t size = 0;
  std::map<std::uint16_t, std::string> schemas;  ///< id -> name
  std::map<std::uint16_t, Channel> channels;
  std::vector<Chunk> chunks;
  std::vector<MessageRef> messages;  ///< all, in file order
  bool indexed = false;
  bool cut_short = false;
  std::vector<MessageRef> selected;
  std::size_t cached_chunk = kNoChunk;
  std::vector<std::byte> cache;

  explicit Impl(const fs::path& f) : file(f) {}
  [[nodiscard]] Place at(std::uint64_t pos, std::string_view what = "record") const {
    return {file, fmt::format("{} at byte {}", what, pos)};
  }
  std::vector<std::byte> read(std::uint64_t pos, std::uint64_t n, std::string_view what) {
    if (pos > size || n > size - pos) throw at(pos, what).error(fmt::format("{} bytes run past the end of the file ({} bytes)", n, size));
    std::vector<std::byte> out(n);
    in.clear();
    in.seekg(static_cast<std::streamoff>(pos));
    if (!in.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(n))) throw at(pos, what).error("read failed");
    return out;
  }
  /// op and content length of the record at `pos` (9 bytes must be there).
  std::pair<std::uint8_t, std::uint64_t> record_head(std::uint64_t pos) {
    const auto head = read(pos, kRecordHead, "record");
    std::uint64_t length;
    std::memcpy(&length, head.data() + 1, 8);
    return {static_cast<std::uint8_t>(head[0]), length};
  }

  void open();
  bool read_summary();
  void read_chunk_index(std::span<const std::byte> content, const Place& place);
  void read_message_index(std::uint64_t pos, std::size_t chunk);
  void scan_linearly();
  void scan_chunk(std::size_t chunk);
  void scan_cut_off_chunk_too(std::size_t chunk);
  void schema(std::span<const std::byte> content, const Place& place);
  void channel(std::span<const std::byte> content, const Place& place);
  std::span<const std::byte> chunk_records(std::size_t chunk);
  std::vector<std::byte> decode_chunk(std::size_t chunk, std::uint64_t limit);
  std::vector<std::byte> message(const MessageRef& ref, std::size_t max_bytes);
};

void McapReader::Impl::schema(std::span<const std::byte> content, const Place& place) {
  Fields f(content, place);
  const auto id = f.integer<std::uint16_t>("schema id");
  schemas[id] = f.string("schema name");
}

void McapReader::Impl::channel(std::span<const std::byte> content, const Place& place) {
  Fields f(content, place);
  const auto id = f.integer<std::uint16_t>("channel id");
  Channel c;
  c.schema_id = f.integer<std::uint16_t>("schema id");
  c.topic = f.string("topic");
  c.encoding = f.string("message encoding");
  channels[id] = std::move(c);
}

void McapReader::Impl::open() {
  in.open(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open the MCAP file");
  std::error_code ec;
  size = fs::file_size(file, ec);
  if (ec) throw InputError(file, fmt::format("cannot read size: {}", ec.message()));
  if (size < kMcapMagic.size() + kRecordHead) throw InputError(file, fmt::format("not an MCAP file ({} bytes)", size));
  const auto magic = read(0, kMcapMagic.size(), "magic");
  if (std::memcmp(magic.data(), kMcapMagic.data(), kMcapMagic.size()) != 0) throw InputError(file, "not an MCAP file (no MCAP magic)");
  if (record_head(kMcapMagic.size()).first != kHeader) throw at(kMcapMagic.size()).error("the first record is not the header");
  indexed = read_summary();
  if (!indexed) scan_linearly();
}

/// The messages through the summary's chunk and message indexes; false
/// when the file has no footer, no summary or no chunk index in it.
bool McapReader::Impl::read_summary() {
  if (size < 2 * kMcapMagic.size() + kRecordHead + kFooterRecord) return false;
  const std::uint64_t footer_at = size - kMcapMagic.size() - kFooterRecord;
  const auto tail = read(footer_at, kFooterRecord + kMcapMagic.size(), "footer");
  if (std::memcmp(tail.data() + kFooterRecord, kMcapMagic.data(), kMcapMagic.size()) != 0 || static_cast<std::uint8_t>(tail[0]) != kFooter) return false;
  const Place place = at(footer_at, "footer");
  Fields footer{std::span<const std::byte>(tail).subspan(kRecordHead, 20), place};
  const auto summary_start = footer.integer<std::uint64_t>("summary_start");
  const auto offsets_start = footer.integer<std::uint64_t>("summary_offset_start");
  const auto summary_crc = footer.integer<std::uint32_t>("summary_crc");
  if (summary_start == 0) return false;
  const std::uint64_t summary_end = offsets_start != 0 ? offsets_start : footer_at;
  if (summary_start < kMcapMagic.size() || summary_start > summary_end || summary_end > footer_at) {
    throw place.error(fmt::format("summary from byte {} to {} is not inside the file", summary_start, summary_end));
  }
  const auto summary = read(summary_start, footer_at + kRecordHead + 16 - summary_start, "summary");
  if (summary_crc != 0 && crc32(summary) != summary_crc) throw place.error("the summary's CRC does not match");
  const auto records = std::span(summary).first(summary_end - summary_start);
  bool chunk_indexes = false;
  for (std::uint64_t pos = 0; pos < records.size();) {
    const Place here = at(summary_start + pos);
    if (records.size() - pos < kRecordHead) throw here.error("cut off");
    std::uint64_t length;
    std::memcpy(&length, records.data() + pos + 1, 8);
    if (length > records.size() - pos - kRecordHead) throw here.error(fmt::format("{} bytes run past the summary", length));
    const auto op = static_cast<std::uint8_t>(records[pos]);
    const auto content = records.subspan(pos + kRecordHead, length);
    if (op == kSchema) schema(content, here);
    if (op == kChannel) channel(content, here);
    if (op == kChunkIndex) {
      read_chunk_index(content, here);
      chunk_indexes = true;
    }
    pos += kRecordHead + length;
  }
  if (!chunk_indexes) {
    schemas.clear();
    channels.clear();
  }
  return chunk_indexes;
}

void McapReader::Impl::read_chunk_index(std::span<const std::byte> content, const Place& place) {
  Fields f(content, place);
  f.integer<std::uint64_t>("message_start_time");
  f.integer<std::uint64_t>("message_end_time");
  const auto chunk_at = f.integer<std::uint64_t>("chunk_start_offset");
  const auto chunk_length = f.integer<std::uint64_t>("chunk_length");
  if (chunk_at < kMcapMagic.size() || chunk_at > size || chunk_length > size - chunk_at) {
    throw place.error(fmt::format("chunk of {} bytes at byte {} is not inside the file", chunk_length, chunk_at));
  }
  chunks.push_back({chunk_at, false, chunk_length});
  const auto offsets = f.prefixed("message_index_offsets");
  if (offsets.size() % 10 != 0) throw place.error(fmt::format("message_index_offsets of {} bytes", offsets.size()));
  if (offsets.empty()) return scan_chunk(chunks.size() - 1);  // a chunk without message indexes: its records say
  for (std::size_t k = 0; k < offsets.size(); k += 10) {
    std::uint64_t pos;
    std::memcpy(&pos, offsets.data() + k + 2, 8);
    read_message_index(pos, chunks.size() - 1);
  }
}

void McapReader::Impl::read_message_index(std::uint64_t pos, std::size_t chunk) {
  const Place place = at(pos, "message index");
  if (pos > size || size - pos < kRecordHead) throw place.error("not inside the file");
  const auto [op, length] = record_head(pos);
  if (op != kMessageIndex) throw place.error(fmt::format("op {} where the chunk index points to a message index", op));
  const auto content = read(pos + kRecordHead, length, "message index");
  Fields f(content, place);
  const auto channel_id = f.integer<std::uint16_t>("channel id");
  if (!channels.contains(channel_id)) throw place.error(fmt::format("channel {} is not in the summary", channel_id));
  const auto entries = f.prefixed("records");
  if (entries.size() % 16 != 0) throw place.error(fmt::format("records of {} bytes", entries.size()));
  for (std::size_t k = 0; k < entries.size(); k += 16) {
    MessageRef ref;
    std::memcpy(&ref.log_time, entries.data() + k, 8);
    std::memcpy(&ref.offset, entries.data() + k + 8, 8);
    ref.channel = channel_id;
    ref.chunk = chunk;
    messages.push_back(ref);
  }
}

/// The data section from the start, up to the Data End record, the footer
/// or the last whole record of a file cut short.
void McapReader::Impl::scan_linearly() {
  std::uint64_t pos = kMcapMagic.size();
  while (true) {
    if (size - pos < kRecordHead) {
      cut_short = true;
      return;
    }
    const auto [op, length] = record_head(pos);
    const bool whole = length <= size - pos - kRecordHead;
    if (op == kChunk) {
      chunks.push_back({pos, !whole, 0});
      scan_cut_off_chunk_too(chunks.size() - 1);
    } else if (!whole) {
      cut_short = true;
      return;
    } else if (op == kSchema || op == kChannel) {
      const auto content = read(pos + kRecordHead, length, "record");
      op == kSchema ? schema(content, at(pos)) : channel(content, at(pos));
    } else if (op == kMessage) {
      const auto head = read(pos + kRecordHead, std::min<std::uint64_t>(length, kMessageHead), "message");
      Fields f(head, at(pos, "message"));
      MessageRef ref;
      ref.channel = f.integer<std::uint16_t>("channel id");
      f.integer<std::uint32_t>("sequence");
      ref.log_time = f.integer<std::uint64_t>("log_time");
      ref.offset = pos;
      if (!channels.contains(ref.channel)) throw at(pos, "message").error(fmt::format("channel {} was not defined before", ref.channel));
      messages.push_back(ref);
    } else if (op == kDataEnd || op == kFooter) {
      return;
    }
    if (!whole) {
      cut_short = true;
      return;
    }
    pos += kRecordHead + length;
  }
}

/// scan_chunk; a chunk the file ends in that gives no record (cut off
/// before its records begin, or in its first) gives nothing.
void McapReader::Impl::scan_cut_off_chunk_too(std::size_t chunk) {
  if (!chunks[chunk].cut_off) return scan_chunk(chunk);
  try {
    scan_chunk(chunk);
  } catch (const InputError&) {
    std::erase_if(messages, [&](const MessageRef& m) { return m.chunk == chunk; });
  }
}

/// Registers the schemas, channels and messages of a chunk (of a cut-off
/// chunk: of its whole records).
void McapReader::Impl::scan_chunk(std::size_t chunk) {
  const auto records = chunk_records(chunk);
  const std::string where = fmt::format("chunk at byte {}", chunks[chunk].at);
  for (std::uint64_t pos = 0; pos < records.size();) {
    const Place here{file, fmt::format("record at byte {} of the {}", pos, where)};
    std::uint64_t length = 0;
    if (records.size() - pos >= kRecordHead) std::memcpy(&length, records.data() + pos + 1, 8);
    if (records.size() - pos < kRecordHead || length > records.size() - pos - kRecordHead) {
      if (chunks[chunk].cut_off) return;
      throw here.error("runs past its chunk");
    }
    const auto op = static_cast<std::uint8_t>(records[pos]);
    const auto content = records.subspan(pos + kRecordHead, length);
    if (op == kSchema) schema(content, here);
    if (op == kChannel) channel(content, here);
    if (op == kMessage) {
      Fields f(content, here);
      MessageRef ref;
      ref.channel = f.integer<std::uint16_t>("channel id");
      f.integer<std::uint32_t>("sequence");
      ref.log_time = f.integer<std::uint64_t>("log_time");
      ref.chunk = chunk;
      ref.offset = pos;
      if (!channels.contains(ref.channel)) throw here.error(fmt::format("channel {} was not defined before", ref.channel));
      messages.push_back(ref);
    }
    pos += kRecordHead + length;
  }
}

/// The decompressed records of a chunk (the last one asked for is kept).
std::span<const std::byte> McapReader::Impl::chunk_records(std::size_t chunk) {
  if (cached_chunk == chunk) return cache;
  cached_chunk = kNoChunk;
  cache = decode_chunk(chunk, std::numeric_limits<std::uint64_t>::max());
  cached_chunk = chunk;
  return cache;
}

/// The first `limit` bytes of a chunk's records (all of them when it holds
/// fewer; only those the file holds of a chunk cut off). The CRC is checked
/// when all are decoded.
std::vector<std::byte> McapReader::Impl::decode_chunk(std::size_t chunk, std::uint64_t limit) {
  const Chunk& c = chunks.at(chunk);
  const Place place = at(c.at, "chunk");
  const auto [op, length] = record_head(c.at);
  if (op != kChunk) throw place.error(fmt::format("op {} where a chunk should be", op));
  if (!c.cut_off && length > size - c.at - kRecordHead) throw place.error(fmt::format("{} bytes run past the end of the file", length));
  if (c.length != 0 && c.length != length + kRecordHead) {
    throw place.error(fmt::format("{} bytes long, its chunk index says {}", length + kRecordHead, c.length));
  }
  const std::uint64_t available = std::min(length, size - c.at - kRecordHead);
  const auto content = read(c.at + kRecordHead, available, "chunk");
  Fields f(content, place);
  f.integer<std::uint64_t>("message_start_time");
  f.integer<std::uint64_t>("message_end_time");
  const auto uncompressed = f.integer<std::uint64_t>("uncompressed_size");
  const auto crc = f.integer<std::uint32_t>("uncompressed_crc");
  const std::string compression = f.string("compression");
  const auto compressed = f.integer<std::uint64_t>("records length");
  if (compressed > length || uncompressed > kMaxChunkRatio * compressed + kChunkSlack) {
    throw place.error(fmt::format("{} bytes cannot come from {} compressed bytes", uncompressed, compressed));
  }
  const auto stored = c.cut_off ? f.rest() : f.take(compressed, "records");
  const bool whole = !c.cut_off && limit >= uncompressed;
  auto records = decompress(compression, stored.first(std::min<std::uint64_t>(stored.size(), compressed)),
                            std::min(uncompressed, limit), !whole, place);
  if (whole && crc != 0 && crc32(records) != crc) throw place.error("the records' CRC does not match");
  return records;
}

std::vector<std::byte> McapReader::Impl::message(const MessageRef& ref, std::size_t max_bytes) {
  std::vector<std::byte> record;
  std::span<const std::byte> from;
  std::uint64_t pos = ref.offset;
  std::string where;
  if (ref.chunk == kNoChunk) {
    const auto [op, length] = record_head(pos);
    const std::uint64_t wanted = max_bytes >= length ? length : std::min<std::uint64_t>(length, kMessageHead + max_bytes);
    record = read(pos, kRecordHead + wanted, "message");
    from = record;
    pos = 0;
    where = fmt::format("message at byte {}", ref.offset);
  } else if (cached_chunk == ref.chunk || max_bytes >= kWholeChunkFrom) {
    from = chunk_records(ref.chunk);
    where = fmt::format("message at byte {} of the chunk at byte {}", ref.offset, chunks[ref.chunk].at);
  } else {  // a header: the chunk decompressed only as far as the message's first bytes
    record = decode_chunk(ref.chunk, ref.offset + kRecordHead + kMessageHead + max_bytes);
    from = record;
    where = fmt::format("message at byte {} of the chunk at byte {}", ref.offset, chunks[ref.chunk].at);
  }
  const Place place{file, where};
  if (pos > from.size() || from.size() - pos < kRecordHead) throw place.error("not inside its chunk");
  std::uint64_t length;
  std::memcpy(&length, from.data() + pos + 1, 8);
  if (static_cast<std::uint8_t>(from[pos]) != kMessage) throw place.error(fmt::format("op {}, not a message", static_cast<unsigned>(from[pos])));
  const auto content = from.subspan(pos + kRecordHead, std::min<std::uint64_t>(length, from.size() - pos - kRecordHead));
  const std::uint64_t needed = max_bytes >= length ? length : std::min<std::uint64_t>(length, kMessageHead + max_bytes);
  if (content.size() < needed) {
    throw place.error(fmt::format("{} bytes run past its chunk", length));
  }
  Fields f(content, place);
  if (f.integer<std::uint16_t>("channel id") != ref.channel) throw place.error("not on the channel its index says");
  f.take(kMessageHead - 2, "message header");
  const auto data = f.rest();
  return {data.begin(), data.begin() + static_cast<std::ptrdiff_t>(std::min<std::uint64_t>(data.size(), max_bytes))};
}

McapReader::McapReader(fs::path file) : file_(std::move(file)), impl_(std::make_unique<Impl>(file_)) {
  require_file(file_, "MCAP file");
  impl_->open();
  std::map<std::string, StoredTopic> by_name;
  for (const auto& [id, c] : impl_->channels) {
    StoredTopic& t = by_name[c.topic];
    t.name = c.topic;
    t.encoding = c.encoding;
    const auto schema = impl_->schemas.find(c.schema_id);
    t.type = schema != impl_->schemas.end() ? schema->second : std::string();
  }
  for (const auto& m : impl_->messages) ++by_name[impl_->channels[m.channel].topic].messages;
  for (auto& [name, t] : by_name) topics_.push_back(std::move(t));
  if (impl_->cut_short) {
    notes_.push_back(fmt::format("the MCAP file ends without its footer (a recording cut short?): read from the start up "
                                 "to its last whole message ({} messages)",
                                 impl_->messages.size()));
  }
}

McapReader::~McapReader() = default;

bool McapReader::indexed() const { return impl_->indexed; }

std::string McapReader::kind() const {
  return fmt::format("MCAP, {} ({} chunks)", impl_->indexed ? "indexed by its summary" : "read from the start", impl_->chunks.size());
}

std::vector<std::int64_t> McapReader::select(const std::string& topic) {
  impl_->selected.clear();
  for (const auto& m : impl_->messages) {
    if (impl_->channels[m.channel].topic == topic) impl_->selected.push_back(m);
  }
  std::stable_sort(impl_->selected.begin(), impl_->selected.end(),
                   [](const MessageRef& a, const MessageRef& b) { return a.log_time < b.log_time; });
  std::vector<std::int64_t> times;
  for (const auto& m : impl_->selected) times.push_back(static_cast<std::int64_t>(m.log_time));
  return times;
}

std::vector<std::byte> McapReader::message(std::size_t k, std::size_t max_bytes) {
  return impl_->message(impl_->selected.at(k), max_bytes);
}

namespace {

/// Little-endian fields appended to a byte buffer.
class Out {
 public:
  explicit Out(std::vector<std::byte>& bytes) : bytes_(bytes) {}
  template <class T>
  Out& integer(T v) {
    const auto at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &v, sizeof(T));
    return *this;
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
