#pragma once
// A ROS 1 bag (format 2.0) as a FrameSource: the sensor_msgs/PointCloud2
// messages of one topic, in the bag's time order. Read through Debian's
// rosbag_storage (librosbag-storage-dev: chunks, bz2/lz4 compression,
// indexes, connections), with each message's bytes parsed and checked by
// io/pointcloud2.hpp. Times are the messages' header stamps (seconds since
// the epoch); opening the bag reads every message of the topic once for them.
// Before rosbag reads a bag, io/rosbag_structure.hpp checks every record
// length and position in it (rosbag trusts them: a corrupt length made it
// allocate 4 GB under the fuzzer).
// Scans are in the message's frame (header.frame_id, said in info().notes); a
// bag has no reference poses and no calibration: it runs in the LiDAR frame.
// info().point_fields are the first message's (parsed when the bag is opened),
// and so is the intensity range every scan's remission is divided by (its
// field's type or values, io/intensity_scale.hpp), unless SourceOptions gives it.
//
// Built only when rosbag_storage is found (rosbag_available()); otherwise
// opening a bag is an InputError saying so.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "saloam/io/frame_source.hpp"
#include "saloam/io/intensity_scale.hpp"
#include "saloam/io/pointcloud2.hpp"
#include "saloam/sources/source_options.hpp"

namespace saloam {

/// True when this build reads and writes ROS 1 bags.
[[nodiscard]] bool rosbag_available();

/// The "#ROSBAG V2.0\n" magic at the start of a bag.
inline constexpr std::string_view kRosbagMagic = "#ROSBAG V2.0\n";

struct BagTopic {
  std::string topic;
  std::string type;  ///< "sensor_msgs/PointCloud2"
  std::size_t messages = 0;
};

/// The topic a bag source reads: `wanted` when given (InputError naming
/// `bag` when it is not among `topics` or is not of `cloud_type`), else the
/// only topic of `cloud_type` (InputError when there is none, or several:
/// the message lists them, with their types and message counts).
std::string choose_cloud_topic(const std::vector<BagTopic>& topics, const std::string& wanted, std::string_view cloud_type,
                               const std::filesystem::path& bag);
/// " /a (type, 3 messages); /b (...)", or " none": what a bag holds, for messages.
std::string bag_topics_text(const std::vector<BagTopic>& topics);

/// The topics of a bag with their types and message counts, by topic name.
/// InputError naming the bag when it is not a readable ROS 1 bag.
std::vector<BagTopic> list_bag_topics(const std::filesystem::path& bag);

class RosbagSource final : public FrameSource {
 public:
  /// Opens `bag` and picks `options.topic`, or the only PointCloud2 topic.
  /// InputError naming the bag when it is unreadable, when the topic is not
  /// a PointCloud2 topic of the bag or there is none, or when there are
  /// several and none was named (the message lists them).
  RosbagSource(std::filesystem::path bag, const SourceOptions& options);
  ~RosbagSource() override;
  RosbagSource(const RosbagSource&) = delete;
  RosbagSource& operator=(const RosbagSource&) = delete;

  /// name: the bag and its topic.
  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override;

  [[nodiscard]] const std::string& topic() const;

 private:
  /// Message i's cloud, parsed and checked by io/pointcloud2.hpp.
  [[nodiscard]] PointCloud2Scan parse(std::size_t i) const;

  struct Impl;
  std::filesystem::path bag_;
  std::unique_ptr<Impl> impl_;
  IntensityScale intensity_;
  SourceInfo info_;
};

enum class BagCompression { kNone, kBz2, kLz4 };

/// Writes PointCloud2 messages on one topic into a new bag (an existing file
/// is replaced). The bag is complete when the writer is closed or destroyed.
class PointCloud2BagWriter {
 public:
  PointCloud2BagWriter(const std::filesystem::path& bag, std::string topic, std::string frame_id,
                       BagCompression compression = BagCompression::kNone);
  ~PointCloud2BagWriter();
  PointCloud2BagWriter(const PointCloud2BagWriter&) = delete;
  PointCloud2BagWriter& operator=(const PointCloud2BagWriter&) = delete;

  /// `stamp` [s since the epoch, >= 0] is the header stamp and the record
  /// time (at least 1 ns, a bag's earliest); `topic` another topic than the
  /// writer's, when given.
  void write(const LabelledCloud& cloud, double stamp, const std::string& topic = {});
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saloam
