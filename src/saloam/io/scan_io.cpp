#include "saloam/io/scan_io.hpp"

#include <cmath>
#include <cstring>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/semantic_classes.hpp"

namespace saloam {
namespace {

// A scan or label file may have at most this many bytes (a 64-beam KITTI scan: 2 MB).
constexpr std::size_t kMaxScanFileBytes = std::size_t{1} << 30;

std::string read_bytes(const std::filesystem::path& file) { return read_file(file, kMaxScanFileBytes); }

void write_bytes(const std::filesystem::path& file, const void* data, std::size_t size) {
  write_file_atomically(file, std::string_view(static_cast<const char*>(data), size));
}

constexpr std::size_t kPointBytes = 4 * sizeof(float);

void check_scan_size(std::size_t size, const std::filesystem::path& bin_file) {
  if (size == 0) throw InputError(bin_file, "empty scan (0 bytes)");
  if (size % kPointBytes != 0) {
    throw InputError(bin_file,
                     fmt::format("size {} bytes is not a multiple of 16 (x, y, z, remission as float32): "
                                 "truncated or not a KITTI .bin scan",
                                 size));
  }
}

}  // namespace

std::vector<std::uint32_t> parse_label_bytes(std::span<const std::byte> bytes, const std::filesystem::path& label_file) {
  if (bytes.size() % sizeof(std::uint32_t) != 0) {
    throw InputError(label_file, fmt::format("size {} bytes is not a multiple of 4 (truncated label file?)",
                                             bytes.size()));
  }
  std::vector<std::uint32_t> labels(bytes.size() / sizeof(std::uint32_t));
  if (!labels.empty()) std::memcpy(labels.data(), bytes.data(), bytes.size());
  return labels;
}

std::vector<std::uint32_t> read_label_file(const std::filesystem::path& label_file) {
  const auto bytes = read_bytes(label_file);
  return parse_label_bytes(std::as_bytes(std::span<const char>(bytes)), label_file);
}

LabelledCloud parse_scan(std::span<const std::byte> bin, const std::filesystem::path& bin_file,
                         std::optional<std::span<const std::byte>> label_bytes,
                         const std::filesystem::path& label_file, ScanReadStats* stats) {
  check_scan_size(bin.size(), bin_file);
  const std::size_t n = bin.size() / kPointBytes;
  std::vector<float> raw(n * 4);
  std::memcpy(raw.data(), bin.data(), bin.size());

  std::vector<std::uint32_t> labels;
  if (label_bytes) {
    labels = parse_label_bytes(*label_bytes, label_file);
    if (labels.size() != n) {
      throw InputError(label_file, fmt::format("{} labels for {} points in {}", labels.size(), n,
                                               bin_file.filename().string()));
    }
  }

  ScanReadStats local;
  local.points_in_file = n;
  PointCheckCounts checks;
  LabelledCloud cloud;
  cloud.has_labels = label_bytes.has_value();
  cloud.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float* p = &raw[4 * i];
    if (!keep_coordinates(p[0], p[1], p[2], checks)) continue;
    const float remission = std::isfinite(p[3]) ? p[3] : 0.0f;
    std::uint16_t cls = 0, inst = 0;
    if (!labels.empty()) {
      cls = static_cast<std::uint16_t>(labels[i] & 0xFFFFu);
      inst = static_cast<std::uint16_t>(labels[i] >> 16);
      if (!find_semantic_class(cls)) ++local.unknown_labels;
    }
    cloud.push_back({p[0], p[1], p[2]}, remission, cls, inst);
  }
  if (cloud.empty()) {
    throw InputError(bin_file, fmt::format("no finite point within {:g} m among {} points", kMaxScanCoordinate, n));
  }
  local.dropped_nonfinite = checks.nonfinite;
  local.dropped_out_of_range = checks.out_of_range;
  warn_point_checks(bin_file, n, checks);
  if (local.unknown_labels > 0) {
    spdlog::warn("{}: {} points carry class ids unknown to SemanticKITTI", label_file.string(),
                 local.unknown_labels);
  }
  if (stats) *stats = local;
  return cloud;
}

LabelledCloud read_scan(const std::filesystem::path& bin_file,
                        const std::optional<std::filesystem::path>& label_file, ScanReadStats* stats) {
  const auto bin = read_bytes(bin_file);
  check_scan_size(bin.size(), bin_file);  // the .bin file's problems first, then the .label file's
  std::optional<std::string> labels;
  if (label_file) labels = read_bytes(*label_file);
  std::optional<std::span<const std::byte>> label_bytes;
  if (labels) label_bytes = std::as_bytes(std::span<const char>(*labels));
  return parse_scan(std::as_bytes(std::span<const char>(bin)), bin_file, label_bytes,
                    label_file.value_or(std::filesystem::path{}), stats);
}

void write_scan_bin(const std::filesystem::path& bin_file, const LabelledCloud& cloud) {
  std::vector<float> raw(cloud.size() * 4);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    raw[4 * i + 0] = cloud.points[i].x();
    raw[4 * i + 1] = cloud.points[i].y();
    raw[4 * i + 2] = cloud.points[i].z();
    raw[4 * i + 3] = cloud.remission[i];
  }
  write_bytes(bin_file, raw.data(), raw.size() * sizeof(float));
}

void write_scan_labels(const std::filesystem::path& label_file, const std::vector<std::uint16_t>& labels,
                       const std::vector<std::uint16_t>& instances) {
  if (labels.size() != instances.size()) {
    throw std::invalid_argument(fmt::format("{}: {} labels but {} instance ids", label_file.string(), labels.size(),
                                            instances.size()));
  }
  std::vector<std::uint32_t> raw(labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i) {
    raw[i] = static_cast<std::uint32_t>(labels[i]) | (static_cast<std::uint32_t>(instances[i]) << 16);
  }
  write_bytes(label_file, raw.data(), raw.size() * sizeof(std::uint32_t));
}

void write_scan_labels(const std::filesystem::path& label_file, const LabelledCloud& cloud) {
  write_scan_labels(label_file, cloud.label, cloud.instance);
}

}  // namespace saloam
