#pragma once
// rosbag2's sqlite3 storage (a .db3 file), read and written through SQLite
// (Debian libsqlite3-dev), no ROS. The tables as rosbag2 (Humble) writes them:
//   schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT)
//   metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER, metadata TEXT)  the bag's metadata.yaml
//   topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, serialization_format TEXT,
//          offered_qos_profiles TEXT[, type_description_hash TEXT since Iron])
//   messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER [ns], data BLOB)
// The reader needs only topics(id, name, type, serialization_format) and
// messages; it opens the file read-only and in SQLite's defensive mode,
// reads `topics` and `messages` only as tables (a view of that name, which
// may compute anything, forever, is refused), bounds the work of its queries
// by the file's size and stops them on Ctrl-C, and checks each message's
// size against the file's before allocating (SQLite itself reports a corrupt
// database as such). Messages are read one at a
// time (incremental blob I/O), a header's prefix without the rest.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "saloam/io/message_storage.hpp"

namespace saloam {

class Db3Reader final : public MessageStorage {
 public:
  /// InputError naming `file` when it is missing, not an SQLite database or
  /// has no rosbag2 tables.
  explicit Db3Reader(std::filesystem::path file);
  ~Db3Reader() override;
  Db3Reader(const Db3Reader&) = delete;
  Db3Reader& operator=(const Db3Reader&) = delete;

  [[nodiscard]] const std::filesystem::path& file() const override { return file_; }
  [[nodiscard]] const std::vector<StoredTopic>& topics() const override { return topics_; }
  std::vector<std::int64_t> select(const std::string& topic) override;
  std::vector<std::byte> message(std::size_t k, std::size_t max_bytes) override;
  [[nodiscard]] std::vector<std::string> notes() const override { return {}; }
  [[nodiscard]] std::string kind() const override { return "sqlite3"; }

 private:
  struct Impl;
  std::filesystem::path file_;
  std::unique_ptr<Impl> impl_;
  std::vector<StoredTopic> topics_;
};

/// Writes a new .db3 file (an existing one is an InputError) in one
/// transaction, committed by close() (or the destructor).
class Db3Writer {
 public:
  explicit Db3Writer(std::filesystem::path file);
  ~Db3Writer();
  Db3Writer(const Db3Writer&) = delete;
  Db3Writer& operator=(const Db3Writer&) = delete;

  /// The id of a new topic (serialization_format "cdr", no QoS profiles).
  std::int64_t add_topic(const std::string& name, const std::string& type);
  void write(std::int64_t topic_id, std::int64_t time_ns, std::span<const std::byte> data);
  /// Stores the bag's metadata.yaml text (rosbag2 keeps a copy in the file)
  /// and commits.
  void close(const std::string& metadata_yaml);

 private:
  struct Impl;
  std::filesystem::path file_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saloam
