#include "saloam/io/pointcloud2.hpp"

#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {

const char* const kPointCloud2Definition =
    "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool    is_bigendian\n"
    "uint32  point_step\nuint32  row_step\nuint8[] data\nbool is_dense\n"
    "================================================================================\n"
    "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n"
    "================================================================================\n"
    "MSG: sensor_msgs/PointField\nuint8 INT8    = 1\nuint8 UINT8   = 2\nuint8 INT16   = 3\nuint8 UINT16  = 4\n"
    "uint8 INT32   = 5\nuint8 UINT32  = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\n\nstring name\nuint32 offset\n"
    "uint8  datatype\nuint32 count\n";

namespace {

constexpr std::size_t kMaxFields = 1024;
constexpr std::size_t kMaxFrameId = 4096;

/// Reads ROS 1 serialised values in order; every read is checked against
/// the bytes left.
class Cursor {
 public:
  Cursor(std::span<const std::byte> bytes, const std::filesystem::path& file, std::string_view context)
      : bytes_(bytes), file_(file), context_(context) {}

  [[nodiscard]] InputError error(const std::string& problem) const {
    return InputError(file_, fmt::format("{}: {}", context_, problem));
  }
  std::span<const std::byte> take(std::size_t n, std::string_view what) {
    if (n > bytes_.size() - at_) {
      throw error(fmt::format("cut off in {} ({} bytes needed at byte {}, {} left)", what, n, at_, bytes_.size() - at_));
    }
    const auto out = bytes_.subspan(at_, n);
    at_ += n;
    return out;
  }
  std::uint32_t u32(std::string_view what) {
    std::uint32_t v;
    std::memcpy(&v, take(4, what).data(), 4);
    return v;
  }
  std::uint8_t u8(std::string_view what) { return static_cast<std::uint8_t>(take(1, what)[0]); }
  std::string string(std::string_view what, std::size_t max_length) {
    const std::size_t n = u32(what);
    if (n > max_length) throw error(fmt::format("{} of {} bytes: longer than {}", what, n, max_length));
    const auto bytes = take(n, what);
    return {reinterpret_cast<const char*>(bytes.data()), n};
  }
  [[nodiscard]] std::size_t left() const { return bytes_.size() - at_; }

 private:
  std::span<const std::byte> bytes_;
  const std::filesystem::path& file_;
  std::string_view context_;
  std::size_t at_ = 0;
};

RosHeader read_header(Cursor& in) {
  RosHeader h;
  h.seq = in.u32("header.seq");
  const std::uint32_t sec = in.u32("header.stamp");
  const std::uint32_t nsec = in.u32("header.stamp");
  h.stamp = static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec);
  h.frame_id = in.string("header.frame_id", kMaxFrameId);
  return h;
}

std::optional<ScalarType> ros_datatype(std::uint8_t datatype) {
  switch (datatype) {
    case 1: return ScalarType::kInt8;
    case 2: return ScalarType::kUint8;
    case 3: return ScalarType::kInt16;
    case 4: return ScalarType::kUint16;
    case 5: return ScalarType::kInt32;
    case 6: return ScalarType::kUint32;
    case 7: return ScalarType::kFloat32;
    case 8: return ScalarType::kFloat64;
    default: return std::nullopt;
  }
}

std::uint8_t ros_datatype(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8: return 1;
    case ScalarType::kUint8: return 2;
    case ScalarType::kInt16: return 3;
    case ScalarType::kUint16: return 4;
    case ScalarType::kInt32: return 5;
    case ScalarType::kUint32: return 6;
    case ScalarType::kFloat32: return 7;
    default: return 8;
  }
}

/// The fields of known datatype, each checked to lie inside `point_step`
/// (which is read after them, so checked by the caller via the returned list).
std::vector<PointField> read_fields(Cursor& in) {
  const std::size_t n = in.u32("fields");
  if (n > kMaxFields || n > in.left() / 13) throw in.error(fmt::format("{} point fields: more than the message holds", n));
  std::vector<PointField> fields;
  for (std::size_t i = 0; i < n; ++i) {
    std::string name = in.string("field name", kMaxFrameId);
    const std::size_t offset = in.u32("field offset");
    const auto type = ros_datatype(in.u8("field datatype"));
    const std::size_t count = in.u32("field count");
    if (type) fields.push_back({std::move(name), *type, offset, std::max<std::size_t>(count, 1)});
  }
  return fields;
}

void check_layout(const Cursor& in, const std::vector<PointField>& fields, std::size_t point_step) {
  for (const auto& f : fields) {
    // Only the first element is read: it must lie inside the point.
    if (f.offset > point_step || scalar_size(f.type) > point_step - f.offset) {
      throw in.error(fmt::format("field '{}' at offset {} does not fit in point_step {}", f.name.substr(0, 40), f.offset, point_step));
    }
  }
}

}  // namespace

RosHeader parse_ros_header(std::span<const std::byte> message, const std::filesystem::path& file,
                           std::string_view context) {
  Cursor in(message, file, context);
  return read_header(in);
}

PointCloud2Scan parse_pointcloud2(std::span<const std::byte> message, const std::filesystem::path& file,
                                  std::string_view context) {
  Cursor in(message, file, context);
  PointCloud2Scan scan;
  scan.header = read_header(in);
  scan.height = in.u32("height");
  scan.width = in.u32("width");
  const std::vector<PointField> fields = read_fields(in);
  const bool big_endian = in.u8("is_bigendian") != 0;
  const std::size_t point_step = in.u32("point_step");
  const std::size_t row_step = in.u32("row_step");
  const std::size_t data_size = in.u32("data");
  const auto data = in.take(data_size, "data");
  check_layout(in, fields, point_step);
  const FieldRoles roles = [&] {
    try {
      return FieldRoles::find(fields, file);
    } catch (const InputError& e) {
      throw in.error(std::string(e.what()).substr(file.string().size() + 2));
    }
  }();
  if (scan.width > 0 && scan.height > 0) {
    if (point_step == 0 || scan.width > row_step / point_step) {
      throw in.error(fmt::format("row_step {} is shorter than width {} x point_step {}", row_step, scan.width, point_step));
    }
    if (scan.height - 1 > data_size / std::max<std::size_t>(row_step, 1) ||
        (scan.height - 1) * row_step + scan.width * point_step > data_size) {
      throw in.error(fmt::format("data of {} bytes is shorter than height {} x row_step {}", data_size, scan.height, row_step));
    }
  }
  if (scan.width > 0 && scan.height > 0) {
    try {
      check_byte_order(
          scan.width * scan.height,
          [&](std::size_t i) { return data.data() + (i / scan.width) * row_step + (i % scan.width) * point_step; },
          fields, roles, big_endian, file);
    } catch (const InputError& e) {
      throw in.error(std::string(e.what()).substr(file.string().size() + 2));
    }
  }
  CloudAssembler out(fields, roles, scan.width * scan.height);
  for (std::size_t r = 0; r < scan.height && scan.width > 0; ++r) {
    for (std::size_t c = 0; c < scan.width; ++c) out.add_binary(data.data() + r * row_step + c * point_step, big_endian);
  }
  try {
    scan.decoded = out.decoded(scan.width * scan.height, scan.header.stamp, file);
  } catch (const InputError& e) {
    throw in.error(std::string(e.what()).substr(file.string().size() + 2));
  }
  return scan;
}

namespace {

void put_u32(std::vector<std::byte>& out, std::uint32_t v) {
  const auto at = out.size();
  out.resize(at + 4);
  std::memcpy(out.data() + at, &v, 4);
}

void put_string(std::vector<std::byte>& out, std::string_view s) {
  put_u32(out, static_cast<std::uint32_t>(s.size()));
  const auto at = out.size();
  out.resize(at + s.size());
  std::memcpy(out.data() + at, s.data(), s.size());
}

}  // namespace

std::vector<std::byte> serialize_pointcloud2(const LabelledCloud& cloud, double stamp, std::string_view frame_id,
                                             std::uint32_t seq) {
  const ScanRecordLayout layout = ScanRecordLayout::of(cloud);
  const std::vector<PointField>& fields = layout.fields;
  const std::size_t step = layout.stride;
  std::vector<std::byte> out;
  const double sec = std::floor(stamp);
  put_u32(out, seq);
  put_u32(out, static_cast<std::uint32_t>(sec));
  put_u32(out, static_cast<std::uint32_t>(std::min(std::lround((stamp - sec) * 1e9), 999999999L)));
  put_string(out, frame_id);
  put_u32(out, 1);
  put_u32(out, static_cast<std::uint32_t>(cloud.size()));
  put_u32(out, static_cast<std::uint32_t>(fields.size()));
  for (const auto& f : fields) {
    put_string(out, f.name);
    put_u32(out, static_cast<std::uint32_t>(f.offset));
    out.push_back(static_cast<std::byte>(ros_datatype(f.type)));
    put_u32(out, 1);
  }
  out.push_back(std::byte{0});  // little-endian
  put_u32(out, static_cast<std::uint32_t>(step));
  put_u32(out, static_cast<std::uint32_t>(step * cloud.size()));
  put_u32(out, static_cast<std::uint32_t>(step * cloud.size()));
  const std::size_t data_at = out.size();
  out.resize(data_at + step * cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::byte* rec = out.data() + data_at + i * step;
    for (std::size_t f = 0; f < fields.size(); ++f) {
      write_scalar(rec + fields[f].offset, fields[f].type, ScanRecordLayout::value(cloud, i, f), false);
    }
  }
  out.push_back(std::byte{1});  // is_dense
  return out;
}

}  // namespace saloam
