#include "saloam/io/rosbag_structure.hpp"

#include <array>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"

namespace saloam {
namespace {

constexpr std::uint64_t kMagicSize = 13;             // "#ROSBAG V2.0\n"
constexpr std::uint32_t kMaxHeader = 1u << 20;       // real headers hold a few fields
constexpr std::uint64_t kMaxChunkRatio = 100;        // point clouds compress far less
constexpr std::uint64_t kChunkSlack = 64ull << 20;
constexpr std::uint8_t kMessageData = 0x02, kBagHeader = 0x03, kIndexData = 0x04, kChunk = 0x05, kChunkInfo = 0x06,
                       kConnection = 0x07;

struct Record {
  std::uint64_t at = 0;
  std::uint8_t op = 0;
  std::map<std::string, std::string> fields;
  std::uint64_t data_at = 0;
  std::uint32_t data_len = 0;
  [[nodiscard]] std::uint64_t end() const { return data_at + data_len; }
};

class BagWalker {
 public:
  BagWalker(std::istream& in, std::uint64_t size, const std::filesystem::path& file)
      : in_(in), size_(size), file_(file) {}

  void walk();

 private:
  [[nodiscard]] InputError error(std::uint64_t at, const std::string& problem) const {
    return InputError(file_, fmt::format("corrupt ROS bag: record at byte {}: {}", at, problem));
  }
  void read(std::uint64_t at, void* out, std::size_t n) {
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(at));
    if (!in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n))) throw error(at, "read failed");
  }
  std::uint32_t u32_at(std::uint64_t at) {
    std::uint32_t v;
    read(at, &v, 4);
    return v;
  }
  Record record(std::uint64_t at, std::uint64_t limit);
  std::map<std::string, std::string> header_fields(std::uint64_t at, std::uint32_t len);
  template <class T>
  T field(const Record& r, const std::string& name) const;
  void chunk(const Record& r);
  void walk_chunk_records(const Record& chunk);
  void index_data(const Record& r);
  void chunk_info(const Record& r);
  void finish();

  std::istream& in_;
  const std::uint64_t size_;
  const std::filesystem::path& file_;
  std::uint64_t index_pos_ = 0;
  std::uint32_t conn_count_ = 0, chunk_count_ = 0;
  std::set<std::uint64_t> records_, chunks_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> chunk_positions_;  ///< (chunk info at, chunk_pos)
  std::set<std::uint32_t> connections_;                                  ///< ids of top-level connection records
  std::vector<std::pair<std::uint64_t, std::uint32_t>> used_connections_; ///< (record at, conn id)
  std::size_t connections_after_index_ = 0, chunk_infos_after_index_ = 0;
  std::optional<std::uint64_t> last_chunk_size_;
};

std::map<std::string, std::string> BagWalker::header_fields(std::uint64_t at, std::uint32_t len) {
  std::string header(len, '\0');
  read(at + 4, header.data(), len);
  std::map<std::string, std::string> fields;
  std::size_t pos = 0;
  while (pos < header.size()) {
    if (header.size() - pos < 4) throw error(at, "header field cut off");
    std::uint32_t n;
    std::memcpy(&n, header.data() + pos, 4);
    pos += 4;
    if (n > header.size() - pos) throw error(at, fmt::format("header field of {} bytes runs past its header", n));
    const std::string text = header.substr(pos, n);
    pos += n;
    const auto eq = text.find('=');
    if (eq == std::string::npos) throw error(at, "header field without '='");
    fields[text.substr(0, eq)] = text.substr(eq + 1);
  }
  return fields;
}

Record BagWalker::record(std::uint64_t at, std::uint64_t limit) {
  if (limit < at || limit - at < 8) throw error(at, "cut off (no room for its lengths)");
  const std::uint32_t header_len = u32_at(at);
  if (header_len > kMaxHeader || header_len > limit - at - 8) {
    throw error(at, fmt::format("header of {} bytes runs past its end ({} bytes left)", header_len, limit - at - 8));
  }
  Record r;
  r.at = at;
  r.fields = header_fields(at, header_len);
  r.data_len = u32_at(at + 4 + header_len);
  r.data_at = at + 8 + header_len;
  if (r.data_len > limit - r.data_at) throw error(at, fmt::format("data of {} bytes runs past its end ({} bytes left)", r.data_len, limit - r.data_at));
  const auto op = r.fields.find("op");
  if (op == r.fields.end() || op->second.size() != 1) throw error(at, "no one-byte 'op' field");
  r.op = static_cast<std::uint8_t>(op->second[0]);
  return r;
}

template <class T>
T BagWalker::field(const Record& r, const std::string& name) const {
  const auto it = r.fields.find(name);
  if (it == r.fields.end() || it->second.size() != sizeof(T)) {
    throw error(r.at, fmt::format("no {}-byte '{}' field", sizeof(T), name));
  }
  T v;
  std::memcpy(&v, it->second.data(), sizeof(T));
  return v;
}

void BagWalker::walk_chunk_records(const Record& chunk) {
  for (std::uint64_t pos = chunk.data_at; pos < chunk.end();) {
    const Record r = record(pos, chunk.end());
    if (r.op != kMessageData && r.op != kConnection) throw error(pos, fmt::format("op {} inside a chunk", r.op));
    pos = r.end();
  }
}

void BagWalker::chunk(const Record& r) {
  const auto compression = r.fields.find("compression");
  if (compression == r.fields.end()) throw error(r.at, "chunk without a 'compression' field");
  const std::uint64_t size = field<std::uint32_t>(r, "size");
  if (compression->second == "none") {
    if (size != r.data_len) throw error(r.at, fmt::format("uncompressed chunk of size {} holds {} bytes", size, r.data_len));
    walk_chunk_records(r);
  } else if (compression->second == "bz2" || compression->second == "lz4") {
    if (size > kMaxChunkRatio * r.data_len + kChunkSlack) {
      throw error(r.at, fmt::format("{} bytes cannot come from {} compressed bytes", size, r.data_len));
    }
  } else {
    throw error(r.at, fmt::format("unknown chunk compression '{}'", compression->second.substr(0, 20)));
  }
  chunks_.insert(r.at);
  last_chunk_size_ = size;
}

void BagWalker::index_data(const Record& r) {
  if (!last_chunk_size_) throw error(r.at, "index data before any chunk");
  const std::uint32_t count = field<std::uint32_t>(r, "count");
  if (static_cast<std::uint64_t>(count) * 12 != r.data_len) throw error(r.at, fmt::format("{} index entries in {} bytes", count, r.data_len));
  used_connections_.emplace_back(r.at, field<std::uint32_t>(r, "conn"));
  std::array<char, 12> entry{};
  for (std::uint32_t k = 0; k < count; ++k) {
    read(r.data_at + 12ull * k, entry.data(), entry.size());
    std::uint32_t offset;
    std::memcpy(&offset, entry.data() + 8, 4);
    if (static_cast<std::uint64_t>(offset) + 8 > *last_chunk_size_) {
      throw error(r.at, fmt::format("index entry {} points to byte {} of a chunk of {}", k, offset, *last_chunk_size_));
    }
  }
}

void BagWalker::chunk_info(const Record& r) {
  const std::uint32_t count = field<std::uint32_t>(r, "count");
  if (static_cast<std::uint64_t>(count) * 8 != r.data_len) throw error(r.at, fmt::format("{} connection counts in {} bytes", count, r.data_len));
  chunk_positions_.emplace_back(r.at, field<std::uint64_t>(r, "chunk_pos"));
  for (std::uint32_t k = 0; k < count; ++k) used_connections_.emplace_back(r.at, u32_at(r.data_at + 8ull * k));
}

void BagWalker::walk() {
  if (size_ < kMagicSize + 8) throw InputError(file_, "corrupt ROS bag: no record after the magic");
  for (std::uint64_t pos = kMagicSize; pos < size_;) {
    const Record r = record(pos, size_);
    if (pos == kMagicSize) {
      if (r.op != kBagHeader) throw error(pos, "the first record is not the bag header");
      index_pos_ = field<std::uint64_t>(r, "index_pos");
      conn_count_ = field<std::uint32_t>(r, "conn_count");
      chunk_count_ = field<std::uint32_t>(r, "chunk_count");
    } else if (r.op == kChunk) {
      chunk(r);
    } else if (r.op == kIndexData) {
      index_data(r);
    } else if (r.op == kChunkInfo) {
      chunk_info(r);
      chunk_infos_after_index_ += pos >= index_pos_;
    } else if (r.op == kConnection) {
      connections_.insert(field<std::uint32_t>(r, "conn"));
      connections_after_index_ += pos >= index_pos_;
    } else {
      throw error(pos, r.op == kBagHeader ? std::string("a second bag header") : fmt::format("op {} outside a chunk", r.op));
    }
    records_.insert(pos);
    pos = r.end();
  }
  finish();
}

void BagWalker::finish() {
  if (index_pos_ != 0 && !records_.contains(index_pos_)) {
    throw InputError(file_, fmt::format("corrupt ROS bag: index_pos {} is not the start of a record", index_pos_));
  }
  if (index_pos_ != 0 && (conn_count_ > connections_after_index_ || chunk_count_ > chunk_infos_after_index_)) {
    throw InputError(file_, fmt::format("corrupt ROS bag: the header announces {} connections and {} chunks, the index "
                                        "holds {} and {}",
                                        conn_count_, chunk_count_, connections_after_index_, chunk_infos_after_index_));
  }
  for (const auto& [at, chunk_pos] : chunk_positions_) {
    if (!chunks_.contains(chunk_pos)) throw error(at, fmt::format("chunk_pos {} is not the start of a chunk", chunk_pos));
  }
  for (const auto& [at, conn] : used_connections_) {
    if (!connections_.contains(conn)) throw error(at, fmt::format("connection {} is not in the bag's index", conn));
  }
}

}  // namespace

void check_rosbag_structure(std::istream& in, std::uint64_t size, const std::filesystem::path& file) {
  BagWalker(in, size, file).walk();
}

void check_rosbag_structure(const std::filesystem::path& file) {
  require_file(file, "bag");
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(file, fmt::format("cannot read size: {}", ec.message()));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open the bag");
  check_rosbag_structure(in, size, file);
}

}  // namespace saloam
