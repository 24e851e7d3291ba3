#pragma once
// PLY export of labelled clouds: binary little-endian with float x, y, z,
// uchar red, green, blue (class colour), ushort label, ushort instance and
// float remission. Readable by CloudCompare, Open3D, MeshLab.

#include <filesystem>

#include "saloam/core/types.hpp"

namespace saloam {

/// Writes `cloud`, transformed by `transform` (identity by default).
void write_ply(const std::filesystem::path& file, const LabelledCloud& cloud,
               const Pose& transform = Pose::Identity());
/// Reads a PLY file written by write_ply (or any binary little-endian PLY
/// with float x, y, z and optionally label/instance/remission properties).
LabelledCloud read_ply(const std::filesystem::path& file);

}  // namespace saloam
