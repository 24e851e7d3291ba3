#include "saloam/viewer/point_encoding.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "saloam/core/semantic_classes.hpp"

namespace saloam {

namespace {

template <class T>
void append_raw(std::string& bytes, const std::vector<T>& values) {
  const std::size_t offset = bytes.size();
  bytes.resize(offset + values.size() * sizeof(T));
  if (!values.empty()) std::memcpy(bytes.data() + offset, values.data(), values.size() * sizeof(T));
}

std::string positions_and_classes(const std::vector<std::uint16_t>& xyz_bits,
                                  const std::vector<std::uint8_t>& classes) {
  std::string bytes;
  bytes.reserve(xyz_bits.size() * 2 + classes.size());
  append_raw(bytes, xyz_bits);
  append_raw(bytes, classes);
  return bytes;
}

}  // namespace

std::uint8_t class_index(std::uint16_t raw_id) {
  const auto classes = semantic_kitti_classes();
  const auto it = std::lower_bound(classes.begin(), classes.end(), raw_id,
                                   [](const SemanticClass& c, std::uint16_t id) { return c.id < id; });
  if (it == classes.end() || it->id != raw_id) return unknown_class_index();
  return static_cast<std::uint8_t>(it - classes.begin());
}

std::uint8_t unknown_class_index() { return static_cast<std::uint8_t>(semantic_kitti_classes().size()); }

MapQuantization map_quantization(const LabelledCloud& cloud) {
  MapQuantization q;
  if (cloud.empty()) return q;
  Eigen::Vector3f lo = cloud.points.front(), hi = lo;
  for (const auto& p : cloud.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  q.origin = lo.cast<double>();
  q.scale = std::max(1e-4, static_cast<double>((hi - lo).maxCoeff()) / 65535.0);
  return q;
}

std::string encode_map(const LabelledCloud& cloud, const MapQuantization& quantization) {
  std::vector<std::uint16_t> xyz;
  std::vector<std::uint8_t> classes;
  xyz.reserve(cloud.size() * 3);
  classes.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const double steps = std::round((cloud.points[i][a] - quantization.origin[a]) / quantization.scale);
      xyz.push_back(static_cast<std::uint16_t>(std::clamp(steps, 0.0, 65535.0)));
    }
    classes.push_back(class_index(cloud.label[i]));
  }
  return positions_and_classes(xyz, classes);
}

std::string encode_scan(const LabelledCloud& scan) {
  constexpr double kLimit = std::numeric_limits<std::int16_t>::max();
  std::vector<std::uint16_t> xyz;
  std::vector<std::uint8_t> classes;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const Eigen::Vector3d steps = (scan.points[i].cast<double>() / kScanScale).array().round();
    if (steps.cwiseAbs().maxCoeff() > kLimit) continue;
    for (int a = 0; a < 3; ++a) xyz.push_back(static_cast<std::uint16_t>(static_cast<std::int16_t>(steps[a])));
    classes.push_back(class_index(scan.label[i]));
  }
  return positions_and_classes(xyz, classes);
}

std::string encode_floats(const std::vector<float>& values) {
  std::string bytes;
  append_raw(bytes, values);
  return bytes;
}

std::string base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const auto n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i]) << 16 |
                                              static_cast<unsigned char>(bytes[i + 1]) << 8 |
                                              static_cast<unsigned char>(bytes[i + 2]));
    for (const int shift : {18, 12, 6, 0}) out += kAlphabet[(n >> shift) & 63U];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16;
    if (rest == 2) n |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
    out += kAlphabet[(n >> 18) & 63U];
    out += kAlphabet[(n >> 12) & 63U];
    out += rest == 2 ? kAlphabet[(n >> 6) & 63U] : '=';
    out += '=';
  }
  return out;
}

std::string poses_base64(const std::vector<Pose>& poses, std::size_t first) {
  std::vector<float> values;
  values.reserve((poses.size() - std::min(first, poses.size())) * 12);
  for (std::size_t i = first; i < poses.size(); ++i) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) values.push_back(static_cast<float>(poses[i].matrix()(r, c)));
    }
  }
  return base64(encode_floats(values));
}

}  // namespace saloam
