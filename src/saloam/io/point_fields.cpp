#include "saloam/io/point_fields.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <array>
#include <limits>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"

namespace saloam {
namespace {

template <class T>
T load(const std::byte* p, bool big_endian) {
  std::array<std::byte, sizeof(T)> bytes;
  std::memcpy(bytes.data(), p, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(bytes.begin(), bytes.end());
  T value;
  std::memcpy(&value, bytes.data(), sizeof(T));
  return value;
}

template <class T>
void store(std::byte* p, T value, bool big_endian) {
  std::array<std::byte, sizeof(T)> bytes;
  std::memcpy(bytes.data(), &value, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(bytes.begin(), bytes.end());
  std::memcpy(p, bytes.data(), sizeof(T));
}

/// `value` converted to the integer type T, saturating (and NaN -> 0), so
/// that a conversion is never undefined behaviour.
template <class T>
T saturate(double value) {
  if (std::isnan(value)) return 0;
  if (value <= static_cast<double>(std::numeric_limits<T>::lowest())) return std::numeric_limits<T>::lowest();
  if (value >= static_cast<double>(std::numeric_limits<T>::max())) return std::numeric_limits<T>::max();
  return static_cast<T>(value);
}

std::optional<std::size_t> find_field(const std::vector<PointField>& fields, std::initializer_list<std::string_view> names) {
  for (const std::string_view name : names) {
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (fields[i].name == name) return i;
    }
  }
  return std::nullopt;
}

float to_float(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(v);
  if (std::abs(v) > std::numeric_limits<float>::max()) return v > 0 ? std::numeric_limits<float>::infinity()
                                                                    : -std::numeric_limits<float>::infinity();
  return static_cast<float>(v);
}

}  // namespace

std::size_t scalar_size(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
    case ScalarType::kUint8: return 1;
    case ScalarType::kInt16:
    case ScalarType::kUint16: return 2;
    case ScalarType::kInt32:
    case ScalarType::kUint32:
    case ScalarType::kFloat32: return 4;
    case ScalarType::kInt64:
    case ScalarType::kUint64:
    case ScalarType::kFloat64: return 8;
  }
  return 0;
}

bool is_floating(ScalarType type) { return type == ScalarType::kFloat32 || type == ScalarType::kFloat64; }

std::string_view scalar_name(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8: return "int8";
    case ScalarType::kUint8: return "uint8";
    case ScalarType::kInt16: return "int16";
    case ScalarType::kUint16: return "uint16";
    case ScalarType::kInt32: return "int32";
    case ScalarType::kUint32: return "uint32";
    case ScalarType::kInt64: return "int64";
    case ScalarType::kUint64: return "uint64";
    case ScalarType::kFloat32: return "float32";
    case ScalarType::kFloat64: return "float64";
  }
  return "?";
}

double read_scalar(const std::byte* p, ScalarType type, bool big_endian) {
  switch (type) {
    case ScalarType::kInt8: return load<std::int8_t>(p, big_endian);
    case ScalarType::kUint8: return load<std::uint8_t>(p, big_endian);
    case ScalarType::kInt16: return load<std::int16_t>(p, big_endian);
    case ScalarType::kUint16: return load<std::uint16_t>(p, big_endian);
    case ScalarType::kInt32: return load<std::int32_t>(p, big_endian);
    case ScalarType::kUint32: return load<std::uint32_t>(p, big_endian);
    case ScalarType::kInt64: return static_cast<double>(load<std::int64_t>(p, big_endian));
    case ScalarType::kUint64: return static_cast<double>(load<std::uint64_t>(p, big_endian));
    case ScalarType::kFloat32: return load<float>(p, big_endian);
    case ScalarType::kFloat64: return load<double>(p, big_endian);
  }
  return 0.0;
}

void write_scalar(std::byte* p, ScalarType type, double value, bool big_endian) {
  switch (type) {
    case ScalarType::kInt8: return store(p, saturate<std::int8_t>(value), big_endian);
    case ScalarType::kUint8: return store(p, saturate<std::uint8_t>(value), big_endian);
    case ScalarType::kInt16: return store(p, saturate<std::int16_t>(value), big_endian);
    case ScalarType::kUint16: return store(p, saturate<std::uint16_t>(value), big_endian);
    case ScalarType::kInt32: return store(p, saturate<std::int32_t>(value), big_endian);
    case ScalarType::kUint32: return store(p, saturate<std::uint32_t>(value), big_endian);
    case ScalarType::kInt64: return store(p, saturate<std::int64_t>(value), big_endian);
    case ScalarType::kUint64: return store(p, saturate<std::uint64_t>(value), big_endian);
    case ScalarType::kFloat32: return store(p, to_float(value), big_endian);
    case ScalarType::kFloat64: return store(p, value, big_endian);
  }
}

FieldRoles FieldRoles::find(const std::vector<PointField>& fields, const std::filesystem::path& file) {
  const auto x = find_field(fields, {"x"});
  const auto y = find_field(fields, {"y"});
  const auto z = find_field(fields, {"z"});
  if (!x || !y || !z) {
    std::vector<std::string> names;
    for (const auto& f : fields) names.push_back(f.name);
    throw InputError(file, fmt::format("no x, y, z fields (fields: {})", names.empty() ? "none" : fmt::format("{}", fmt::join(names, " "))));
  }
  FieldRoles roles;
  roles.x = *x;
  roles.y = *y;
  roles.z = *z;
  roles.intensity = find_field(fields, {"intensity", "remission"});
  roles.ring = find_field(fields, {"ring"});
  roles.time = find_field(fields, {"time", "t", "timestamp", "offset_time"});
  roles.label = find_field(fields, {"label"});
  roles.instance = find_field(fields, {"instance"});
  return roles;
}

std::string FieldRoles::describe(const std::vector<PointField>& fields) const {
  std::string out = "x y z";
  for (const auto& role : {intensity, ring, time, label, instance}) {
    if (role) out += " " + fields[*role].name;
  }
  return out;
}

CloudAssembler::CloudAssembler(const std::vector<PointField>& fields, const FieldRoles& roles,
                               std::size_t expected_points)
    : fields_(fields), roles_(roles) {
  cloud_.reserve(expected_points);
  cloud_.has_labels = roles_.label.has_value();
  if (roles_.ring) cloud_.ring.reserve(expected_points);
  if (roles_.time) {
    raw_times_.reserve(expected_points);
    if (!is_floating(fields_[*roles_.time].type)) time_scale_ = 1e-9;  // integer times are nanoseconds
  }
}

void CloudAssembler::add_binary(const std::byte* record, bool big_endian) {
  const auto value = [&](std::optional<std::size_t> role) {
    if (!role) return 0.0;
    const PointField& f = fields_[*role];
    return read_scalar(record + f.offset, f.type, big_endian);
  };
  add(value(roles_.x), value(roles_.y), value(roles_.z), value(roles_.intensity), value(roles_.ring),
      value(roles_.time), value(roles_.label), value(roles_.instance));
}

void CloudAssembler::add_values(std::span<const double> values) {
  const auto value = [&](std::optional<std::size_t> role) { return role ? values[*role] : 0.0; };
  add(value(roles_.x), value(roles_.y), value(roles_.z), value(roles_.intensity), value(roles_.ring),
      value(roles_.time), value(roles_.label), value(roles_.instance));
}

void CloudAssembler::add(double x, double y, double z, double intensity, double ring, double time, double label,
                         double instance) {
  ++points_seen_;
  if (!keep_coordinates(x, y, z, checks_) || (roles_.ring && !keep_ring(ring, checks_))) return;
  const Eigen::Vector3f p(to_float(x), to_float(y), to_float(z));
  const float remission = std::isfinite(intensity) ? to_float(intensity) : 0.0f;
  cloud_.points.push_back(p);
  cloud_.remission.push_back(std::isfinite(remission) ? remission : 0.0f);
  cloud_.label.push_back(saturate<std::uint16_t>(std::fmod(label, 65536.0)));
  cloud_.instance.push_back(saturate<std::uint16_t>(std::fmod(instance, 65536.0)));
  if (roles_.ring) cloud_.ring.push_back(saturate<std::uint16_t>(ring));
  if (roles_.time) raw_times_.push_back(time * time_scale_);
}

DecodedCloud CloudAssembler::decoded(std::size_t points_in_file, std::optional<double> scan_stamp,
                                     const std::filesystem::path& file) {
  DecodedCloud decoded;
  decoded.points_in_file = points_in_file;
  decoded.fields = roles_.describe(fields_);
  decoded.cloud = finish(scan_stamp, file);
  decoded.time_reference = absolute_reference_;
  if (roles_.intensity) decoded.intensity_type = fields_[*roles_.intensity].type;
  decoded.checks = checks_;
  return decoded;
}

ScanRecordLayout ScanRecordLayout::of(const LabelledCloud& cloud) {
  ScanRecordLayout layout;
  layout.fields = {{"x", ScalarType::kFloat32, 0, 1},
                   {"y", ScalarType::kFloat32, 4, 1},
                   {"z", ScalarType::kFloat32, 8, 1},
                   {"intensity", ScalarType::kFloat32, 12, 1}};
  layout.stride = 16;
  if (cloud.has_rings()) {
    layout.fields.push_back({"ring", ScalarType::kUint16, layout.stride, 1});
    layout.stride += 2;
  }
  if (cloud.has_times()) {
    layout.fields.push_back({"time", ScalarType::kFloat32, layout.stride, 1});
    layout.stride += 4;
  }
  return layout;
}

double ScanRecordLayout::value(const LabelledCloud& cloud, std::size_t i, std::size_t field) {
  switch (field) {
    case 0: return cloud.points[i].x();
    case 1: return cloud.points[i].y();
    case 2: return cloud.points[i].z();
    case 3: return cloud.remission[i];
    default: break;
  }
  if (field == 4 && cloud.has_rings()) return cloud.ring[i];
  return cloud.time[i];
}

LabelledCloud CloudAssembler::finish(std::optional<double> scan_stamp, const std::filesystem::path& file) {
  if (cloud_.empty()) {
    throw InputError(file, checks_.dropped() > 0
                               ? fmt::format("no point with finite coordinates within {:g} m (and a ring within "
                                             "0..{:g}) among {} points",
                                             kMaxScanCoordinate, kMaxRings - 1, checks_.dropped())
                               : std::string("no points"));
  }
  if (roles_.time) {
    double earliest = std::numeric_limits<double>::infinity(), largest = 0.0;
    for (const double t : raw_times_) {
      if (!std::isfinite(t)) continue;
      earliest = std::min(earliest, t);
      largest = std::max(largest, std::abs(t));
    }
    double reference = 0.0;
    if (largest > kAbsoluteTimeThreshold) {
      reference = scan_stamp.value_or(earliest);
      absolute_reference_ = reference;
    }
    cloud_.time.resize(raw_times_.size());
    for (std::size_t i = 0; i < raw_times_.size(); ++i) {
      cloud_.time[i] = checked_time(raw_times_[i] - reference, checks_);
    }
  }
  warn_point_checks(file, points_seen_, checks_, true);
  return std::move(cloud_);
}

std::optional<double> parse_number(std::string_view token) {
  if (token.empty()) return std::nullopt;
  double value = 0.0;
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (*first == '+') ++first;
  const auto [end, ec] = std::from_chars(first, last, value);
  if (ec == std::errc::result_out_of_range && end == last) {
    return std::strtod(std::string(token).c_str(), nullptr);  // overflow to +-inf, underflow to 0 (or a denormal)
  }
  if (ec != std::errc() || end != last) return std::nullopt;
  return value;
}

}  // namespace saloam
