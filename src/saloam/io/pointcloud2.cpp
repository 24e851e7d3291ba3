#include "saloam/io/pointcloud2.hpp"

#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/cdr.hpp"

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

const char* const kRos2PointCloud2Definition =
    "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool    is_bigendian\n"
    "uint32  point_step\nuint32  row_step\nuint8[] data\nbool is_dense\n"
    "================================================================================\n"
    "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
    "================================================================================\n"
    "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
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

/// What the two serialisations share once read: the layout and the bytes.
struct CloudBody {
  std::size_t height = 0, width = 0;
  std::vector<PointField> fields;
  bool big_endian = false;
  std::size_t point_step = 0, row_step = 0;
  std::span<const std::byte> data;
};

InputError context_error(const std::filesystem::path& file, std::string_view context, const std::string& problem) {
  return InputError(file, fmt::format("{}: {}", context, problem));
}

/// Runs `f`, giving an InputError it throws (which names `file`) the context.
template <class F>
auto in_context(const std::filesystem::path& file, std::string_view context, F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    throw context_error(file, context, std::string(e.what()).substr(file.string().size() + 2));
  }
}

void check_layout(const CloudBody& body, const std::filesystem::path& file, std::string_view context) {
  for (const auto& f : body.fields) {
    // Only the first element is read: it must lie inside the point.
    if (f.offset > body.point_step || scalar_size(f.type) > body.point_step - f.offset) {
      throw context_error(file, context, fmt::format("field '{}' at offset {} does not fit in point_step {}",
                                                     f.name.substr(0, 40), f.offset, body.point_step));
    }
  }
  if (body.width == 0 || body.height == 0) return;
  if (body.point_step == 0 || body.width > body.row_step / body.point_step) {
    throw context_error(file, context, fmt::format("row_step {} is shorter than width {} x point_step {}", body.row_step,
                                                   body.width, body.point_step));
  }
  const std::size_t size = body.data.size();
  if (body.height - 1 > size / std::max<std::size_t>(body.row_step, 1) ||
      (body.height - 1) * body.row_step + body.width * body.point_step > size) {
    throw context_error(file, context, fmt::format("data of {} bytes is shorter than height {} x row_step {}", size,
                                                   body.height, body.row_step));
  }
}

/// The points of a checked body, through point_fields.hpp.
DecodedCloud decode_body(const CloudBody& body, double stamp, const std::filesystem::path& file, std::string_view context) {
  check_layout(body, file, context);
  const FieldRoles roles = in_context(file, context, [&] { return FieldRoles::find(body.fields, file); });
  const std::size_t points = body.width * body.height;
  const auto record = [&](std::size_t i) {
    return body.data.data() + (i / body.width) * body.row_step + (i % body.width) * body.point_step;
  };
  if (points > 0) {
    in_context(file, context, [&] {
      check_byte_order(points, record, body.fields, roles, body.big_endian, file);
      return 0;
    });
  }
  CloudAssembler out(body.fields, roles, points);
  for (std::size_t i = 0; i < points; ++i) out.add_binary(record(i), body.big_endian);
  return in_context(file, context, [&] { return out.decoded(points, stamp, file); });
}

/// PointField sequences of either serialisation: unknown datatypes are skipped.
template <class Reader>
std::vector<PointField> read_fields(Reader& in, std::size_t min_field_bytes) {
  const std::size_t n = in.u32("fields");
  if (n > kMaxFields || n > in.left() / min_field_bytes) {
    throw in.error(fmt::format("{} point fields: more than the message holds", n));
  }
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

/// The body after the header, in either serialisation.
template <class Reader>
CloudBody read_body(Reader& in, std::size_t min_field_bytes) {
  CloudBody body;
  body.height = in.u32("height");
  body.width = in.u32("width");
  body.fields = read_fields(in, min_field_bytes);
  body.big_endian = in.u8("is_bigendian") != 0;
  body.point_step = in.u32("point_step");
  body.row_step = in.u32("row_step");
  const std::size_t data_size = in.u32("data");
  body.data = in.take(data_size, "data");
  return body;
}

RosHeader read_ros2_header(CdrReader& in) {
  RosHeader h;
  const std::int32_t sec = in.i32("header.stamp");
  const std::uint32_t nanosec = in.u32("header.stamp");
  if (nanosec > 999999999u) throw in.error(fmt::format("header.stamp.nanosec {} is not below 1e9", nanosec));
  h.stamp = static_cast<double>(sec) + 1e-9 * static_cast<double>(nanosec);
  h.frame_id = in.string("header.frame_id", kMaxFrameId);
  return h;
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
  const CloudBody body = read_body(in, 13);
  scan.height = body.height;
  scan.width = body.width;
  scan.decoded = decode_body(body, scan.header.stamp, file, context);
  return scan;
}

RosHeader parse_ros2_header(std::span<const std::byte> message, const std::filesystem::path& file,
                            std::string_view context) {
  CdrReader in(message, file, context);
  return read_ros2_header(in);
}

PointCloud2Scan parse_pointcloud2_cdr(std::span<const std::byte> message, const std::filesystem::path& file,
                                      std::string_view context) {
  CdrReader in(message, file, context);
  PointCloud2Scan scan;
  scan.header = read_ros2_header(in);
  const CloudBody body = read_body(in, 13);
  scan.height = body.height;
  scan.width = body.width;
  scan.decoded = decode_body(body, scan.header.stamp, file, context);
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

/// The packed records of `cloud` (ScanRecordLayout) at `out`.
void write_records(std::byte* out, const LabelledCloud& cloud, const ScanRecordLayout& layout, bool big_endian) {
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::byte* rec = out + i * layout.stride;
    for (std::size_t f = 0; f < layout.fields.size(); ++f) {
      write_scalar(rec + layout.fields[f].offset, layout.fields[f].type, ScanRecordLayout::value(cloud, i, f), big_endian);
    }
  }
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
  write_records(out.data() + data_at, cloud, layout, false);
  out.push_back(std::byte{1});  // is_dense
  return out;
}

std::vector<std::byte> serialize_pointcloud2_cdr(const LabelledCloud& cloud, double stamp, std::string_view frame_id,
                                                 bool big_endian) {
  const ScanRecordLayout layout = ScanRecordLayout::of(cloud);
  CdrWriter out(big_endian);
  const double sec = std::floor(stamp);
  out.i32(static_cast<std::int32_t>(sec));
  out.u32(static_cast<std::uint32_t>(std::min(std::lround((stamp - sec) * 1e9), 999999999L)));
  out.string(frame_id);
  out.u32(1);
  out.u32(static_cast<std::uint32_t>(cloud.size()));
  out.u32(static_cast<std::uint32_t>(layout.fields.size()));
  for (const auto& f : layout.fields) {
    out.string(f.name);
    out.u32(static_cast<std::uint32_t>(f.offset));
    out.u8(ros_datatype(f.type));
    out.u32(1);
  }
  out.u8(big_endian ? 1 : 0);
  out.u32(static_cast<std::uint32_t>(layout.stride));
  out.u32(static_cast<std::uint32_t>(layout.stride * cloud.size()));
  out.u32(static_cast<std::uint32_t>(layout.stride * cloud.size()));
  write_records(out.extend(layout.stride * cloud.size()), cloud, layout, big_endian);
  out.u8(1);  // is_dense
  return std::move(out).take();
}

}  // namespace saloam
