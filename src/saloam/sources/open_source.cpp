#include "saloam/sources/open_source.hpp"

#include <array>
#include <fstream>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/mcap.hpp"
#include "saloam/io/sequence_source.hpp"
#include "saloam/sensors/pcap_reader.hpp"
#include "saloam/sources/kitti_raw_drive.hpp"
#include "saloam/sources/live_udp_source.hpp"
#include "saloam/sources/pcap_source.hpp"
#include "saloam/sources/point_cloud_folder.hpp"
#include "saloam/sources/ros2_bag_source.hpp"
#include "saloam/sources/rosbag_source.hpp"
#include "saloam/sources/scan_files.hpp"
#include "saloam/sources/sensor_rings_source.hpp"
#include "saloam/sources/udp_socket.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr std::array<std::pair<ScanFormat, std::string_view>, 9> kNames{{{ScanFormat::kAuto, "auto"},
                                                                        {ScanFormat::kSemanticKitti, "semantickitti"},
                                                                        {ScanFormat::kKittiRaw, "kitti-raw"},
                                                                        {ScanFormat::kPcd, "pcd"},
                                                                        {ScanFormat::kPly, "ply"},
                                                                        {ScanFormat::kRosbag, "rosbag"},
                                                                        {ScanFormat::kRosbag2, "rosbag2"},
                                                                        {ScanFormat::kMcap, "mcap"},
                                                                        {ScanFormat::kPcap, "pcap"}}};

bool starts_with(const fs::path& file, std::string_view magic) {
  std::ifstream in(file, std::ios::binary);
  std::string head(magic.size(), '\0');
  return in.read(head.data(), static_cast<std::streamsize>(head.size())) && head == magic;
}

ScanFormat detect_file(const fs::path& file) {
  const auto ext = file.extension();
  if (starts_with(file, kRosbagMagic) || ext == ".bag") return ScanFormat::kRosbag;
  if (starts_with(file, kMcapMagic) || ext == ".mcap") return ScanFormat::kMcap;
  if (starts_with(file, kSqliteMagic) || ext == ".db3") return ScanFormat::kRosbag2;
  if (has_pcap_magic(file) || ext == ".pcap" || ext == ".pcapng") return ScanFormat::kPcap;
  if (ext == ".pcd") return ScanFormat::kPcd;
  if (ext == ".ply") return ScanFormat::kPly;
  throw InputError(file, "not a scan source saloam reads: expected a ROS 1 bag (.bag), an MCAP file (.mcap), a rosbag2 "
                         "database (.db3), a packet capture (.pcap), a .pcd or .ply file, or a folder");
}

ScanFormat detect_folder(const fs::path& folder) {
  std::error_code ec;
  if (fs::is_directory(folder / "velodyne", ec)) return ScanFormat::kSemanticKitti;
  if (fs::is_regular_file(folder / "metadata.yaml", ec)) return ScanFormat::kRosbag2;
  if (fs::is_directory(folder / "velodyne_points" / "data", ec)) return ScanFormat::kKittiRaw;
  const bool pcd = has_files_with_extension(folder, ".pcd");
  const bool ply = has_files_with_extension(folder, ".ply");
  if (pcd && ply) throw InputError(folder, "holds both .pcd and .ply files: name the format with --format pcd|ply");
  if (pcd) return ScanFormat::kPcd;
  if (ply) return ScanFormat::kPly;
  throw InputError(folder, "no scans found: expected velodyne/*.bin (SemanticKITTI), velodyne_points/data/*.bin "
                           "(KITTI raw), *.pcd or *.ply files, metadata.yaml (rosbag2), or a ROS 1 bag or MCAP file");
}

std::unique_ptr<FrameSource> open_semantic_kitti(const fs::path& path, const SourceOptions& options) {
  SequenceOptions sequence;
  sequence.labels_dir = options.labels;
  sequence.ignore_labels = options.ignore_labels;
  return std::make_unique<SequenceFolderSource>(SequenceReader(path, sequence), !options.ignore_calib,
                                                options.intensity_scale);
}

}  // namespace

std::string_view format_name(ScanFormat format) {
  for (const auto& [f, name] : kNames) {
    if (f == format) return name;
  }
  return "?";
}

std::optional<ScanFormat> scan_format_from_name(std::string_view name) {
  for (const auto& [f, n] : kNames) {
    if (n == name) return f;
  }
  return std::nullopt;
}

const std::vector<std::string>& scan_format_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& [f, n] : kNames) out.emplace_back(n);
    return out;
  }();
  return names;
}

ScanFormat detect_scan_format(const fs::path& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) throw InputError(path, "not found");
  if (status.type() == fs::file_type::directory) return detect_folder(path);
  if (status.type() == fs::file_type::regular) return detect_file(path);
  throw InputError(path, ec ? fmt::format("cannot access: {}", ec.message()) : std::string("is not a file or folder"));
}

std::unique_ptr<FrameSource> open_reader(const fs::path& path, const SourceOptions& given) {
  SourceOptions options = given;
  options.ignore_labels = given.ignore_labels || given.segmentation.has_value();
  if (is_udp_url(path.string())) return std::make_unique<LiveUdpSource>(path.string(), options);
  const ScanFormat format = options.format == ScanFormat::kAuto ? detect_scan_format(path) : options.format;
  switch (format) {
    case ScanFormat::kSemanticKitti: return open_semantic_kitti(path, options);
    case ScanFormat::kKittiRaw: return std::make_unique<KittiRawDrive>(path, options);
    case ScanFormat::kPcd:
    case ScanFormat::kPly: return std::make_unique<PointCloudFolder>(path, format, options);
    case ScanFormat::kRosbag: return std::make_unique<RosbagSource>(path, options);
    case ScanFormat::kRosbag2:
    case ScanFormat::kMcap: return std::make_unique<Ros2BagSource>(path, format, options);
    case ScanFormat::kPcap: return std::make_unique<PcapSource>(path, options);
    case ScanFormat::kAuto: break;
  }
  throw InputError(path, "no scan format");
}

std::unique_ptr<FrameSource> add_stages(std::unique_ptr<FrameSource> source, const SourceOptions& options) {
  if (options.sensor_lasers > 0) source = std::make_unique<SensorRingsSource>(std::move(source), options.sensor_lasers);
  // A live source's size is not known: any bound given is its frame limit.
  const bool bounded = source->info().live ? options.frames.end != FrameRange{}.end : options.frames.end < source->size();
  if (options.frames.first > 0 || bounded) {
    source = std::make_unique<FrameRangeSource>(std::move(source), options.frames);
  }
  if (options.segmentation) source = std::make_unique<SegmentedSource>(std::move(source), *options.segmentation);
  return source;
}

std::unique_ptr<FrameSource> open_source(const fs::path& path, const SourceOptions& options) {
  return add_stages(open_reader(path, options), options);
}

}  // namespace saloam
