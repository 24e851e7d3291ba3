#pragma once
// PLY point clouds (Stanford polygon format): a text header ("ply",
// "format ascii|binary_little_endian|binary_big_endian 1.0", "element NAME
// COUNT", "property TYPE NAME", "end_header") and the elements in order.
//
// Reading: the `vertex` element's properties, of any order and scalar type
// (char/int8 ... double/float64), become a LabelledCloud as point_fields.hpp
// says (x, y, z; intensity/remission; ring; time/t/timestamp/offset_time;
// label, instance). Elements before `vertex` are skipped (in binary files
// only when they have no list properties); elements after it are not read.
// A list property in `vertex` is an error. No Debian library is worth its
// weight here: the header is a few lines and the data are fixed-size records
// (libtinyply is not packaged; libhapply, VTK and Open3D read meshes).
//
// Writing: write_ply exports labelled maps (class colours, for viewers);
// write_ply_scan writes a scan's fields for other tools and round trips.

#include <filesystem>
#include <optional>
#include <span>

#include "saloam/core/types.hpp"
#include "saloam/io/point_fields.hpp"

namespace saloam {

/// Writes `cloud`, transformed by `transform` (identity by default), as
/// binary little-endian with float x, y, z, uchar red, green, blue (class
/// colour), ushort label, ushort instance and float remission. Readable by
/// CloudCompare, Open3D, MeshLab.
void write_ply(const std::filesystem::path& file, const LabelledCloud& cloud,
               const Pose& transform = Pose::Identity());

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

/// Writes a scan: float x, y, z, intensity, and ushort ring and float time
/// (seconds relative to the scan) when the cloud has them.
void write_ply_scan(const std::filesystem::path& file, const LabelledCloud& cloud, PlyEncoding encoding);

/// Parses a whole PLY file's bytes; `file` names it in errors; `scan_stamp`
/// as for parse_pcd. InputError for a malformed header, a vertex list
/// property, truncated data, a bad ASCII value, no x/y/z, or no finite point.
DecodedCloud parse_ply(std::span<const std::byte> bytes, const std::filesystem::path& file,
                       std::optional<double> scan_stamp = std::nullopt);
/// parse_ply of a file's content.
DecodedCloud read_ply_cloud(const std::filesystem::path& file, std::optional<double> scan_stamp = std::nullopt);
/// The cloud of read_ply_cloud (labels when a `label` property exists).
LabelledCloud read_ply(const std::filesystem::path& file);

}  // namespace saloam
