#pragma once
// A ROS 2 recording as a FrameSource, read without ROS: the
// sensor_msgs/msg/PointCloud2 messages (CDR, io/pointcloud2.hpp) of one
// topic, from
//   a rosbag2 folder   metadata.yaml naming its .db3 (sqlite3 storage) or
//                      .mcap files, read one after the other;
//   one .db3 file      rosbag2's sqlite3 storage (io/db3.hpp);
//   one .mcap file     (io/mcap.hpp): indexed through its summary when it
//                      has one, else read linearly up to its last whole
//                      message (a recording cut short), with a warning.
// The topic is picked as in a ROS 1 bag (sources/rosbag_source.hpp:
// --topic, else the only PointCloud2 topic; the error lists them). Times are
// the messages' header stamps (seconds since the epoch), which must
// increase; opening reads every header of the topic once (a message's first
// bytes; an MCAP chunk is decompressed for them). Scans are in the message's
// frame (header.frame_id, said in info().notes); a recording has no
// reference poses and no calibration: it runs in the LiDAR frame.
// info().notes list every topic of the recording with its type and message
// count. The intensity range comes from the first message, as for ROS 1 bags.

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/io/intensity_scale.hpp"
#include "saloam/io/message_storage.hpp"
#include "saloam/io/pointcloud2.hpp"
#include "saloam/sources/rosbag_source.hpp"
#include "saloam/sources/source_options.hpp"

namespace saloam {

/// The first 16 bytes of every SQLite database ("SQLite format 3" and NUL).
inline constexpr std::string_view kSqliteMagic{"SQLite format 3\0", 16};

/// The files of a recording, opened: `path` is a rosbag2 folder (its
/// metadata.yaml names the storage), or one file: MCAP when `format` is
/// kMcap or the name ends in .mcap, else a .db3. InputError naming the file
/// that cannot be read.
std::vector<std::unique_ptr<MessageStorage>> open_ros2_storage(const std::filesystem::path& path, ScanFormat format);

/// The topics of a ROS 2 recording with their types and message counts
/// (summed over its files), by name.
std::vector<BagTopic> list_ros2_topics(const std::vector<std::unique_ptr<MessageStorage>>& files);

class Ros2BagSource final : public FrameSource {
 public:
  /// Opens the recording at `path` (`format` kRosbag2 or kMcap) and picks
  /// the topic. InputError naming the file for what cannot be read, for a
  /// topic that is not there or not a PointCloud2 topic, for several topics
  /// and none named, for messages that are not CDR, and for header stamps
  /// that do not increase.
  Ros2BagSource(std::filesystem::path path, ScanFormat format, const SourceOptions& options);
  ~Ros2BagSource() override;

  /// name: the recording and its topic.
  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override;
  [[nodiscard]] const std::string& topic() const { return topic_; }

 private:
  struct Frame {
    std::size_t file = 0;  ///< into files_
    std::size_t k = 0;     ///< the file's k-th selected message
  };
  void select_messages();
  [[nodiscard]] std::string context(std::size_t i) const;
  [[nodiscard]] PointCloud2Scan parse(std::size_t i);

  std::filesystem::path path_;
  std::vector<std::unique_ptr<MessageStorage>> files_;
  std::string topic_, frame_id_;
  std::vector<Frame> frames_;
  IntensityScale intensity_;
  SourceInfo info_;
};

}  // namespace saloam
