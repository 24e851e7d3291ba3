#pragma once
// Reading and writing single scans in the SemanticKITTI binary formats:
// `.bin` = float32 x, y, z, remission per point; `.label` = uint32 per point,
// low 16 bits class id, high 16 bits instance id.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/point_checks.hpp"  // kMaxScanCoordinate: the checks every reader makes

namespace saloam {


struct ScanReadStats {
  std::size_t points_in_file = 0;
  std::size_t dropped_nonfinite = 0;     ///< points with NaN/Inf coordinates, dropped
  std::size_t dropped_out_of_range = 0;  ///< points with a coordinate beyond kMaxScanCoordinate, dropped
  std::size_t unknown_labels = 0;     ///< class ids outside the SemanticKITTI table (kept)
};

/// Reads a .bin scan and, if given, its .label file. Points with non-finite
/// coordinates or a coordinate beyond kMaxScanCoordinate (1e30 in a broken
/// file) are dropped (counted in `stats`, warned once per file); a
/// non-finite remission reads as 0.
/// Throws InputError for a missing, truncated or odd-sized file, a label
/// count that differs from the point count, or an empty scan.
LabelledCloud read_scan(const std::filesystem::path& bin_file,
                        const std::optional<std::filesystem::path>& label_file = std::nullopt,
                        ScanReadStats* stats = nullptr);

/// read_scan on bytes already in memory: `bin` holds a .bin file's content,
/// `labels` (when given) its .label file's; `bin_file` and `label_file` name
/// them in errors. The same checks and InputErrors as read_scan.
LabelledCloud parse_scan(std::span<const std::byte> bin, const std::filesystem::path& bin_file,
                         std::optional<std::span<const std::byte>> labels = std::nullopt,
                         const std::filesystem::path& label_file = {}, ScanReadStats* stats = nullptr);

/// Writes the points as a KITTI .bin file.
void write_scan_bin(const std::filesystem::path& bin_file, const LabelledCloud& cloud);
/// Writes the labels (class | instance << 16) as a .label file.
void write_scan_labels(const std::filesystem::path& label_file, const LabelledCloud& cloud);
/// The same from separate label and instance arrays (equal lengths).
void write_scan_labels(const std::filesystem::path& label_file, const std::vector<std::uint16_t>& labels,
                       const std::vector<std::uint16_t>& instances);

/// Reads only a .label file: one uint32 per point. InputError when it is
/// missing or its size is not a multiple of 4.
std::vector<std::uint32_t> read_label_file(const std::filesystem::path& label_file);
/// read_label_file on the file's bytes (`label_file` names it in errors).
std::vector<std::uint32_t> parse_label_bytes(std::span<const std::byte> bytes, const std::filesystem::path& label_file);

}  // namespace saloam
