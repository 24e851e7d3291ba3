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

constexpr std::uint64_t kRecordHead = 9;          // op, uint64 length
constexpr std::uint64_t kFooterRecord = 9 + 20;   // summary_start, summary_offset_start, summary_crc
constexpr std::uint64_t kMessageHead = 2 + 4 + 8 + 8;  // channel_id, sequence, log_time, publish_time
constexpr std::uint64_t kMaxChunkRatio = 100;      // point clouds compress far less
constexpr std::uint64_t kChunkSlack = 64ull << 20;
constexpr std::size_t kNoChunk = std::numeric_limits<std::size_t>::max();
/// Asked for fewer bytes of a message (a header), a chunk is decompressed
/// only as far as them, and not kept.
constexpr std::size_t kWholeChunkFrom = 1u << 16;

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

}  // namespace saloam
