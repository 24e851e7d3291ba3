#pragma once
// One file of a ROS 2 recording as a list of stored messages, whatever the
// container: a rosbag2 sqlite3 database (.db3, io/db3.hpp) or an MCAP file
// (io/mcap.hpp). What sources/ros2_bag_source.hpp reads PointCloud2
// messages through. Times are the recorder's log times [ns since the epoch];
// a message's own time is in its header.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace saloam {

struct StoredTopic {
  std::string name;      ///< "/points"
  std::string type;      ///< "sensor_msgs/msg/PointCloud2"
  std::string encoding;  ///< "cdr"
  std::size_t messages = 0;
};

class MessageStorage {
 public:
  virtual ~MessageStorage() = default;
  [[nodiscard]] virtual const std::filesystem::path& file() const = 0;
  /// Every topic of the file, by name, with its message count.
  [[nodiscard]] virtual const std::vector<StoredTopic>& topics() const = 0;
  /// Makes `topic`'s messages the ones message() serves, in log-time order
  /// (ties in storage order); returns their log times [ns].
  virtual std::vector<std::int64_t> select(const std::string& topic) = 0;
  /// The bytes of the k-th selected message, at most `max_bytes` of them
  /// (a prefix: enough for a header). InputError naming the file when the
  /// file cannot give them.
  virtual std::vector<std::byte> message(std::size_t k,
                                         std::size_t max_bytes = std::numeric_limits<std::size_t>::max()) = 0;
  /// The container, for `saloam info`: "sqlite3", "MCAP, indexed (3 zstd chunks)", ...
  [[nodiscard]] virtual std::string kind() const = 0;
  /// What the reader found worth saying once (a file cut short, read up to
  /// its last whole message), one line each; empty for a sound file.
  [[nodiscard]] virtual std::vector<std::string> notes() const = 0;
};

}  // namespace saloam
