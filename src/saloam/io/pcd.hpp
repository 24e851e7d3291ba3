#pragma once
// PCD point cloud files (PCL's format, version 0.7 and the older 0.5/0.6
// headers): a text header (VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT,
// VIEWPOINT, POINTS, DATA) and the points as
//   ascii              one point per line, the values of every field in order
//   binary             packed records, the fields in order, little-endian
//   binary_compressed  uint32 compressed size, uint32 size, then LZF data
//                      holding the fields one after another (each field's
//                      values for all points, then the next field's)
// Fields of any order and numeric type are read as point_fields.hpp says
// (x, y, z; intensity/remission; ring; time/t/timestamp/offset_time); `_`
// padding fields and element counts above 1 are skipped over. Points are in
// the sensor frame, metres; VIEWPOINT is ignored (every PCD we met has the
// identity).
//
// Library choice: this small reader rather than PCL's pcl_io (Debian
// libpcl-dev): pcl_io would bring about 300 packages (VTK, Qt, Boost) and
// minutes of compile time per file that includes it, for the one format
// whose header is a few lines; its reader also allocates what a header
// says before checking it against the file. The LZF decompression of
// binary_compressed is Debian's liblzf (the same algorithm PCL embeds), with
// its input checks on. Without liblzf at build time, binary_compressed files
// are an error saying so.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <span>

#include "saloam/core/types.hpp"
#include "saloam/io/point_fields.hpp"

namespace saloam {

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };

/// True when this build reads and writes binary_compressed PCD (liblzf).
[[nodiscard]] bool pcd_compression_available();

/// Parses a whole PCD file's bytes; `file` names it in errors. `scan_stamp`:
/// the scan's timestamp, when known, for absolute per-point times. Throws
/// InputError for a malformed header (unknown type or size, counts that do
/// not match, sizes beyond the data), truncated or corrupt data, no x/y/z
/// fields, or no finite point. Never allocates more than a small multiple
/// of the input's size.
DecodedCloud parse_pcd(std::span<const std::byte> bytes, const std::filesystem::path& file,
                       std::optional<double> scan_stamp = std::nullopt);
/// parse_pcd of a file's content.
DecodedCloud read_pcd(const std::filesystem::path& file, std::optional<double> scan_stamp = std::nullopt);

/// Writes `cloud` with fields x y z intensity (float32), and ring (uint16)
/// and time (float32, seconds relative to the scan) when the cloud has them.
void write_pcd(const std::filesystem::path& file, const LabelledCloud& cloud, PcdEncoding encoding);

}  // namespace saloam
