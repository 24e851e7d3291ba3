#include "saloam/sources/rosbag_source.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/pointcloud2.hpp"
#include "saloam/io/rosbag_structure.hpp"

#ifdef SALOAM_HAVE_ROSBAG
#include <rosbag/bag.h>
#include <rosbag/view.h>

namespace saloam::detail {
/// A message whose serialised form is given as bytes: rosbag writes and
/// reads PointCloud2 messages through it, so that io/pointcloud2.cpp alone
/// interprets (and checks) their content.
struct SerializedPointCloud2 {
  std::vector<std::byte> bytes;
};
}  // namespace saloam::detail

namespace ros::message_traits {
template <>
struct MD5Sum<saloam::detail::SerializedPointCloud2> {
  static const char* value() { return saloam::kPointCloud2Md5.data(); }
  static const char* value(const saloam::detail::SerializedPointCloud2&) { return value(); }
};
template <>
struct DataType<saloam::detail::SerializedPointCloud2> {
  static const char* value() { return saloam::kPointCloud2Type.data(); }
  static const char* value(const saloam::detail::SerializedPointCloud2&) { return value(); }
};
template <>
struct Definition<saloam::detail::SerializedPointCloud2> {
  static const char* value() { return saloam::kPointCloud2Definition; }
  static const char* value(const saloam::detail::SerializedPointCloud2&) { return value(); }
};
}  // namespace ros::message_traits

namespace ros::serialization {
template <>
struct Serializer<saloam::detail::SerializedPointCloud2> {
  template <typename Stream>
  static void write(Stream& stream, const saloam::detail::SerializedPointCloud2& m) {
    std::memcpy(stream.advance(static_cast<std::uint32_t>(m.bytes.size())), m.bytes.data(), m.bytes.size());
  }
  static std::uint32_t serializedLength(const saloam::detail::SerializedPointCloud2& m) {
    return static_cast<std::uint32_t>(m.bytes.size());
  }
};
}  // namespace ros::serialization
#endif

namespace fs = std::filesystem;

namespace saloam {
namespace {

[[noreturn, maybe_unused]] void not_built(const fs::path& bag) {
  throw InputError(bag, "ROS 1 bags are not built into this saloam (install librosbag-storage-dev and rebuild)");
}

/// InputError unless `bag` starts with the bag magic (before rosbag sees it).
void check_magic(const fs::path& bag) {
  std::ifstream in(bag, std::ios::binary);
  if (!in) throw InputError(bag, fs::exists(bag) ? "cannot open the bag" : "bag not found");
  std::string head(kRosbagMagic.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  if (head != kRosbagMagic) {
    throw InputError(bag, head.starts_with("#ROSBAG") ? "not a ROS 1 bag of format 2.0 (" + head.substr(0, head.find('\n')) + ")"
                                                      : "not a ROS 1 bag (no '#ROSBAG V2.0' magic)");
  }
}

}  // namespace

std::string bag_topics_text(const std::vector<BagTopic>& topics) {
  std::string out;
  for (const auto& t : topics) out += fmt::format("{} {} ({}, {} messages)", out.empty() ? "" : ";", t.topic, t.type, t.messages);
  return out.empty() ? " none" : out;
}

std::string choose_cloud_topic(const std::vector<BagTopic>& topics, const std::string& wanted, std::string_view cloud_type,
                               const fs::path& bag) {
  std::vector<BagTopic> clouds;
  std::copy_if(topics.begin(), topics.end(), std::back_inserter(clouds), [&](const BagTopic& t) { return t.type == cloud_type; });
  if (!wanted.empty()) {
    const auto it = std::find_if(topics.begin(), topics.end(), [&](const BagTopic& t) { return t.topic == wanted; });
    if (it == topics.end()) throw InputError(bag, fmt::format("no topic '{}'; the bag holds:{}", wanted, bag_topics_text(topics)));
    if (it->type != cloud_type) throw InputError(bag, fmt::format("topic '{}' holds {}, not {}", wanted, it->type, cloud_type));
    return wanted;
  }
  if (clouds.size() == 1) return clouds.front().topic;
  if (clouds.empty()) throw InputError(bag, fmt::format("no {} topic; the bag holds:{}", cloud_type, bag_topics_text(topics)));
  throw InputError(bag, fmt::format("{} {} topics: pick one with --topic:{}", clouds.size(), cloud_type, bag_topics_text(clouds)));
}

bool rosbag_available() {
#ifdef SALOAM_HAVE_ROSBAG
  return true;
#else
  return false;
#endif
}

#ifdef SALOAM_HAVE_ROSBAG

namespace {

/// Runs `f`, turning rosbag's exceptions into an InputError naming the bag.
/// rosbag's own console messages are off: the error says what went wrong.
template <class F>
auto guarded(const fs::path& bag, F&& f) {
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  try {
    return f();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(bag, fmt::format("unreadable ROS 1 bag: {}", e.what()));
  }
}


/// The message's serialised bytes; InputError when the bag claims more
/// bytes than it holds (checked before allocating).
std::vector<std::byte> message_bytes(const rosbag::MessageInstance& m, const fs::path& bag) {
  std::error_code ec;
  const auto file_size = fs::file_size(bag, ec);
  const std::uint32_t size = m.size();
  // Compressed chunks may hold more than the file; a point cloud compresses far less than 100:1.
  if (ec || size > file_size * 100) throw InputError(bag, fmt::format("a message of {} bytes in a bag of {}: corrupt", size, file_size));
  std::vector<std::byte> bytes(size);
  ros::serialization::OStream stream(reinterpret_cast<std::uint8_t*>(bytes.data()), static_cast<std::uint32_t>(bytes.size()));
  m.write(stream);
  return bytes;
}

std::vector<BagTopic> topics_of(const rosbag::Bag& bag) {
  std::map<std::string, BagTopic> by_topic;
  rosbag::View view(bag);
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    BagTopic& t = by_topic[c->topic];
    t.topic = c->topic;
    t.type = c->datatype;
  }
  for (auto& [name, t] : by_topic) t.messages = rosbag::View(bag, rosbag::TopicQuery(name)).size();
  std::vector<BagTopic> out;
  for (auto& [name, t] : by_topic) out.push_back(std::move(t));
  return out;
}

}  // namespace

struct RosbagSource::Impl {
  rosbag::Bag bag;
  std::string topic;
  std::string frame_id;
  std::vector<rosbag::MessageInstance> messages;
};

std::vector<BagTopic> list_bag_topics(const fs::path& bag) {
  check_magic(bag);
  check_rosbag_structure(bag);
  return guarded(bag, [&] {
    rosbag::Bag b(bag.string(), rosbag::bagmode::Read);
    return topics_of(b);
  });
}

RosbagSource::RosbagSource(fs::path bag, const SourceOptions& options)
    : bag_(std::move(bag)), impl_(std::make_unique<Impl>()) {
  check_magic(bag_);
  check_rosbag_structure(bag_);  // every length and position, before rosbag trusts them
  guarded(bag_, [&] {
    impl_->bag.open(bag_.string(), rosbag::bagmode::Read);
    impl_->topic = choose_cloud_topic(topics_of(impl_->bag), options.topic, kPointCloud2Type, bag_);
    rosbag::View view(impl_->bag, rosbag::TopicQuery(impl_->topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto bytes = message_bytes(m, bag_);
      const RosHeader header =
          parse_ros_header(bytes, bag_, fmt::format("topic {}, message {}", impl_->topic, impl_->messages.size()));
      if (!info_.times.empty() && !(header.stamp > info_.times.back())) {
        throw InputError(bag_, fmt::format("topic {}, message {}: header stamp {:.9f} is not after the previous {:.9f}",
                                           impl_->topic, impl_->messages.size(), header.stamp, info_.times.back()));
      }
      if (impl_->messages.empty()) impl_->frame_id = header.frame_id;
      info_.times.push_back(header.stamp);
      impl_->messages.push_back(m);
    }
    if (impl_->messages.empty()) throw InputError(bag_, fmt::format("topic {} has no messages", impl_->topic));
    return 0;
  });
  info_.name = fmt::format("{} (topic {})", bag_.string(), impl_->topic);
  info_.format = "rosbag";
  const PointCloud2Scan first = parse(0);
  info_.point_fields = first.decoded.fields;
  intensity_ = choose_intensity_scale(options.intensity_scale, first.decoded.intensity_type, first.decoded.cloud.remission);
  info_.notes = {fmt::format("topic: {} ({} messages), frame '{}'", impl_->topic, impl_->messages.size(), impl_->frame_id),
                 "times: the messages' header stamps", "calibration: none: runs in the LiDAR frame",
                 "reference: none (a bag of point clouds)", intensity_.note()};
}

PointCloud2Scan RosbagSource::parse(std::size_t i) const {
  const auto bytes = guarded(bag_, [&] { return message_bytes(impl_->messages.at(i), bag_); });
  return parse_pointcloud2(bytes, bag_, fmt::format("topic {}, message {}", impl_->topic, i));
}

LabelledCloud RosbagSource::scan(std::size_t i) {
  LabelledCloud cloud = std::move(parse(i).decoded.cloud);
  intensity_.apply(cloud);
  return cloud;
}

const std::string& RosbagSource::topic() const { return impl_->topic; }

struct PointCloud2BagWriter::Impl {
  fs::path path;
  rosbag::Bag bag;
  std::string topic, frame_id;
  std::uint32_t seq = 0;
};

PointCloud2BagWriter::PointCloud2BagWriter(const fs::path& bag, std::string topic, std::string frame_id,
                                           BagCompression compression)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = bag;
  impl_->topic = std::move(topic);
  impl_->frame_id = std::move(frame_id);
  guarded(bag, [&] {
    impl_->bag.open(bag.string(), rosbag::bagmode::Write);
    impl_->bag.setCompression(compression == BagCompression::kBz2   ? rosbag::compression::BZ2
                              : compression == BagCompression::kLz4 ? rosbag::compression::LZ4
                                                                    : rosbag::compression::Uncompressed);
    return 0;
  });
}

PointCloud2BagWriter::~PointCloud2BagWriter() {
  try {
    close();
  } catch (const std::exception&) {
    // A destructor must not throw; close() explicitly to see the error.
  }
}

void PointCloud2BagWriter::write(const LabelledCloud& cloud, double stamp, const std::string& topic) {
  detail::SerializedPointCloud2 message{serialize_pointcloud2(cloud, stamp, impl_->frame_id, impl_->seq++)};
  guarded(impl_->path, [&] {
    // A bag's record times start at ros::TIME_MIN (1 ns); the header keeps the stamp as given.
    const ros::Time record_time = stamp >= 1e-9 ? ros::Time(stamp) : ros::TIME_MIN;
    impl_->bag.write(topic.empty() ? impl_->topic : topic, record_time, message);
    return 0;
  });
}

void PointCloud2BagWriter::close() {
  guarded(impl_->path, [&] {
    impl_->bag.close();
    return 0;
  });
}

#else  // without rosbag_storage

struct RosbagSource::Impl {};
struct PointCloud2BagWriter::Impl {};

std::vector<BagTopic> list_bag_topics(const fs::path& bag) {
  check_magic(bag);
  not_built(bag);
}
RosbagSource::RosbagSource(fs::path bag, const SourceOptions&) : bag_(std::move(bag)) {
  check_magic(bag_);
  not_built(bag_);
}
LabelledCloud RosbagSource::scan(std::size_t) { not_built(bag_); }
const std::string& RosbagSource::topic() const {
  static const std::string none;
  return none;
}
PointCloud2BagWriter::PointCloud2BagWriter(const fs::path& bag, std::string, std::string, BagCompression) { not_built(bag); }
PointCloud2BagWriter::~PointCloud2BagWriter() = default;
void PointCloud2BagWriter::write(const LabelledCloud&, double, const std::string&) {}
void PointCloud2BagWriter::close() {}

#endif

RosbagSource::~RosbagSource() = default;

}  // namespace saloam
