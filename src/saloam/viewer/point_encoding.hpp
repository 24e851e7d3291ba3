#pragma once
// Compact encodings of the viewer's data, decoded by viewer.html:
//   map   uint16 x, y, z per point (origin + q * scale), then one uint8 class index per point
//   scan  int16 x, y, z per point in the scan's LiDAR frame (q * kScanScale), then the class indices
//   poses float32 arrays
// Class index: position in semantic_kitti_classes(), or kUnknownClassIndex.
// Binary data go into the page as base64, or as bytes from the server.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "saloam/core/types.hpp"

namespace saloam {

inline constexpr double kScanScale = 0.005;  ///< [m] scan quantisation: +-163 m around the sensor

struct MapQuantization {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double scale = 1e-3;  ///< [m] per step
};

/// Index of a raw SemanticKITTI id in semantic_kitti_classes(); kUnknownClassIndex for others.
std::uint8_t class_index(std::uint16_t raw_id);
std::uint8_t unknown_class_index();

/// The cloud's bounding box in 65536 steps per axis (the largest extent decides the step).
MapQuantization map_quantization(const LabelledCloud& cloud);
/// 7 bytes per point (see above).
std::string encode_map(const LabelledCloud& cloud, const MapQuantization& quantization);
/// 7 bytes per point; points farther than the int16 range from the sensor are left out.
std::string encode_scan(const LabelledCloud& scan);
/// Float32 values as bytes (little-endian, as the browser reads them).
std::string encode_floats(const std::vector<float>& values);
/// Poses from `first` on as float32 [R|t] rows (12 a pose), base64, as the pages read them.
std::string poses_base64(const std::vector<Pose>& poses, std::size_t first = 0);

/// Standard base64 (RFC 4648, with padding).
std::string base64(std::string_view bytes);

}  // namespace saloam
