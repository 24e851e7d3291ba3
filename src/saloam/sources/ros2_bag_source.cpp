#include "saloam/sources/ros2_bag_source.hpp"

#include <map>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/io/db3.hpp"
#include "saloam/io/mcap.hpp"
#include "saloam/io/rosbag2_metadata.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

/// Enough of a message for its header: encapsulation, stamp, a frame_id of
/// the longest length the parser takes.
constexpr std::size_t kHeaderBytes = 4 + 8 + 4 + 4096 + 1;

std::unique_ptr<MessageStorage> open_file(const fs::path& file, bool mcap) {
  if (mcap) return std::make_unique<McapReader>(file);
  return std::make_unique<Db3Reader>(file);
}

std::string storage_note(const fs::path& path, const std::vector<std::unique_ptr<MessageStorage>>& files) {
  std::string names;
  for (const auto& f : files) names += fmt::format("{}{} ({})", names.empty() ? "" : ", ", f->file().filename().string(), f->kind());
  return fmt::format("storage: {}{}", fs::is_directory(path) ? "rosbag2 folder of " : "", names);
}

}  // namespace

std::vector<std::unique_ptr<MessageStorage>> open_ros2_storage(const fs::path& path, ScanFormat format) {
  std::vector<std::unique_ptr<MessageStorage>> files;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const Rosbag2Metadata metadata = read_rosbag2_metadata(path);
    for (const auto& file : metadata.files) files.push_back(open_file(file, metadata.storage == "mcap"));
  } else {
    files.push_back(open_file(path, format == ScanFormat::kMcap || path.extension() == ".mcap"));
  }
  return files;
}

std::vector<BagTopic> list_ros2_topics(const std::vector<std::unique_ptr<MessageStorage>>& files) {
  std::map<std::string, BagTopic> by_name;
  for (const auto& f : files) {
    for (const StoredTopic& t : f->topics()) {
      BagTopic& out = by_name[t.name];
      out.topic = t.name;
      out.type = t.type;
      out.messages += t.messages;
    }
  }
  std::vector<BagTopic> out;
  for (auto& [name, t] : by_name) out.push_back(std::move(t));
  return out;
}

Ros2BagSource::Ros2BagSource(fs::path path, ScanFormat format, const SourceOptions& options)
    : path_(std::move(path)), files_(open_ros2_storage(path_, format)) {
  const std::vector<BagTopic> topics = list_ros2_topics(files_);
  topic_ = choose_cloud_topic(topics, options.topic, kRos2PointCloud2Type, path_);
  select_messages();
  info_.name = fmt::format("{} (topic {})", path_.string(), topic_);
  info_.format = format == ScanFormat::kMcap ? "mcap" : "rosbag2";
  const PointCloud2Scan first = parse(0);
  info_.point_fields = first.decoded.fields;
  intensity_ = choose_intensity_scale(options.intensity_scale, first.decoded.intensity_type, first.decoded.cloud.remission);
  info_.notes = {fmt::format("topic: {} ({} messages), frame '{}'", topic_, frames_.size(), frame_id_),
                 fmt::format("topics:{}", bag_topics_text(topics)), storage_note(path_, files_),
                 "times: the messages' header stamps", "calibration: none: runs in the LiDAR frame",
                 "reference: none (a recording of point clouds)", intensity_.note()};
  for (const auto& f : files_) {
    for (const auto& note : f->notes()) {
      spdlog::warn("{}: {}", f->file().string(), note);
      info_.notes.push_back(note);
    }
  }
}

Ros2BagSource::~Ros2BagSource() = default;

std::string Ros2BagSource::context(std::size_t i) const { return fmt::format("topic {}, message {}", topic_, i); }

void Ros2BagSource::select_messages() {
  for (std::size_t f = 0; f < files_.size(); ++f) {
    for (const StoredTopic& t : files_[f]->topics()) {
      if (t.name == topic_ && t.encoding != "cdr") {
        throw InputError(files_[f]->file(), fmt::format("topic {} is serialised as '{}': saloam reads cdr", topic_, t.encoding.substr(0, 40)));
      }
    }
    const std::size_t count = files_[f]->select(topic_).size();
    for (std::size_t k = 0; k < count; ++k) {
      const fs::path& file = files_[f]->file();
      const RosHeader header = parse_ros2_header(files_[f]->message(k, kHeaderBytes), file, context(frames_.size()));
      if (!info_.times.empty() && !(header.stamp > info_.times.back())) {
        throw InputError(file, fmt::format("{}: header stamp {:.9f} is not after the previous {:.9f}", context(frames_.size()),
                                           header.stamp, info_.times.back()));
      }
      if (frames_.empty()) frame_id_ = header.frame_id;
      info_.times.push_back(header.stamp);
      frames_.push_back({f, k});
    }
  }
  if (frames_.empty()) throw InputError(path_, fmt::format("topic {} has no messages", topic_));
}

PointCloud2Scan Ros2BagSource::parse(std::size_t i) {
  const Frame& frame = frames_.at(i);
  MessageStorage& file = *files_[frame.file];
  return parse_pointcloud2_cdr(file.message(frame.k), file.file(), context(i));
}

LabelledCloud Ros2BagSource::scan(std::size_t i) {
  LabelledCloud cloud = std::move(parse(i).decoded.cloud);
  intensity_.apply(cloud);
  return cloud;
}

}  // namespace saloam
