#include "saloam/io/ply.hpp"

#include <cstring>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/binary_file.hpp"
#include "saloam/io/text_records.hpp"

namespace saloam {
namespace {

// One vertex record as write_ply writes it: 12 + 3 + 2 + 2 + 4 = 23 bytes, packed.
constexpr std::size_t kRecordBytes = 23;
constexpr std::size_t kMaxHeaderLines = 4096;
constexpr std::size_t kMaxProperties = 1024;
constexpr std::size_t kMaxElements = 64;

template <class T>
void put(char*& dst, T value) {
  std::memcpy(dst, &value, sizeof(T));
  dst += sizeof(T);
}

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PointField> properties;  ///< scalar properties, offsets packed
  std::size_t stride = 0;
  bool has_list = false;
  std::size_t header_line = 0;
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;
  std::size_t lines = 0;  ///< header lines, for ASCII line numbers
};

std::optional<ScalarType> ply_scalar(std::string_view name) {
  if (name == "char" || name == "int8") return ScalarType::kInt8;
  if (name == "uchar" || name == "uint8") return ScalarType::kUint8;
  if (name == "short" || name == "int16") return ScalarType::kInt16;
  if (name == "ushort" || name == "uint16") return ScalarType::kUint16;
  if (name == "int" || name == "int32") return ScalarType::kInt32;
  if (name == "uint" || name == "uint32") return ScalarType::kUint32;
  if (name == "int64") return ScalarType::kInt64;
  if (name == "uint64") return ScalarType::kUint64;
  if (name == "float" || name == "float32") return ScalarType::kFloat32;
  if (name == "double" || name == "float64") return ScalarType::kFloat64;
  return std::nullopt;
}

ScalarType checked_scalar(const TextRecords& text, std::string_view name) {
  const auto type = ply_scalar(name);
  if (!type) throw text.error(fmt::format("unknown property type '{}'", name.substr(0, 40)));
  return *type;
}

void add_property(PlyHeader& header, const std::vector<std::string>& words, const TextRecords& text) {
  if (header.elements.empty()) throw text.error("property before any element");
  PlyElement& e = header.elements.back();
  if (e.properties.size() >= kMaxProperties) throw text.error(fmt::format("more than {} properties", kMaxProperties));
  if (words.size() == 5 && words[1] == "list") {
    checked_scalar(text, words[2]);
    checked_scalar(text, words[3]);
    e.has_list = true;
    return;
  }
  if (words.size() != 3) throw text.error("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
  const ScalarType type = checked_scalar(text, words[1]);
  e.properties.push_back({words[2], type, e.stride, 1});
  e.stride += scalar_size(type);
}

void set_format(PlyHeader& header, const std::vector<std::string>& words, const TextRecords& text) {
  if (words.size() != 3) throw text.error("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
  if (words[1] == "ascii") {
    header.encoding = PlyEncoding::kAscii;
  } else if (words[1] == "binary_little_endian") {
    header.encoding = PlyEncoding::kBinaryLittleEndian;
  } else if (words[1] == "binary_big_endian") {
    header.encoding = PlyEncoding::kBinaryBigEndian;
  } else {
    throw text.error(fmt::format("unknown format '{}'", words[1].substr(0, 40)));
  }
}

PlyHeader parse_header(std::span<const std::byte> bytes, const std::filesystem::path& file) {
  TextRecords text(bytes, file, "header line");
  std::string_view line;
  if (!text.next_line(line) || line != "ply") throw InputError(file, "not a PLY file (missing 'ply' magic)");
  PlyHeader header;
  bool has_format = false;
  while (text.next_line(line)) {
    if (text.line_number() > kMaxHeaderLines) throw InputError(file, "no end_header in the first 4096 lines");
    const auto words = split_words(line);
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "end_header") {
      if (!has_format) throw InputError(file, "PLY header has no format line");
      header.data_offset = text.offset();
      header.lines = text.line_number();
      return header;
    }
    if (words[0] == "format") {
      set_format(header, words, text);
      has_format = true;
    } else if (words[0] == "element") {
      if (words.size() != 3) throw text.error("expected 'element NAME COUNT'");
      if (header.elements.size() >= kMaxElements) throw text.error(fmt::format("more than {} elements", kMaxElements));
      header.elements.push_back({words[1], TextRecords::unsigned_at(words[2], file, text.line_number(), "element count"),
                                 {}, 0, false, text.line_number()});
    } else if (words[0] == "property") {
      add_property(header, words, text);
    } else {
      throw text.error(fmt::format("unknown header keyword '{}'", words[0].substr(0, 40)));
    }
  }
  throw InputError(file, "PLY header has no end_header (cut off?)");
}

/// Skips the elements before `vertex` in binary data: the offset of the vertex data.
std::size_t skip_binary_elements(const PlyHeader& header, std::size_t vertex, std::size_t data_size,
                                 const std::filesystem::path& file) {
  std::size_t offset = 0;
  for (std::size_t k = 0; k < vertex; ++k) {
    const PlyElement& e = header.elements[k];
    if (e.has_list) {
      throw InputError(file, fmt::format("element '{}' before the vertices has a list property: not supported in binary PLY", e.name));
    }
    if (e.stride > 0 && e.count > (data_size - offset) / e.stride) {
      throw InputError(file, fmt::format("truncated: element '{}' needs more bytes than the file has", e.name));
    }
    offset += e.count * e.stride;
  }
  return offset;
}

void decode_binary(std::span<const std::byte> data, const PlyHeader& header, std::size_t vertex,
                   CloudAssembler& out, const std::filesystem::path& file) {
  const std::size_t offset = skip_binary_elements(header, vertex, data.size(), file);
  const PlyElement& v = header.elements[vertex];
  const std::size_t available = data.size() - offset;
  if (v.count > available / std::max<std::size_t>(v.stride, 1)) {
    throw InputError(file, fmt::format("truncated PLY: {} vertices of {} bytes, {} bytes of data", v.count, v.stride, available));
  }
  const bool big = header.encoding == PlyEncoding::kBinaryBigEndian;
  check_byte_order(v.count, [&](std::size_t i) { return data.data() + offset + i * v.stride; }, v.properties,
                   FieldRoles::find(v.properties, file), big, file);
  for (std::size_t i = 0; i < v.count; ++i) out.add_binary(data.data() + offset + i * v.stride, big);
}

void decode_ascii(std::span<const std::byte> data, const PlyHeader& header, std::size_t vertex, CloudAssembler& out,
                  const std::filesystem::path& file) {
  TextRecords text(data, file, "line", header.lines + 1);
  std::string_view line;
  const auto next_record = [&](const PlyElement& e) {
    do {
      if (!text.next_line(line)) throw InputError(file, fmt::format("truncated PLY: fewer '{}' lines than {}", e.name, e.count));
    } while (split_words(line).empty());
  };
  for (std::size_t k = 0; k < vertex; ++k) {
    for (std::size_t i = 0; i < header.elements[k].count; ++i) next_record(header.elements[k]);
  }
  const PlyElement& v = header.elements[vertex];
  std::vector<double> values(v.properties.size());
  for (std::size_t i = 0; i < v.count; ++i) {
    next_record(v);
    const auto words = split_words(line);
    if (words.size() != values.size()) {
      throw text.error(fmt::format("{} values, the header declares {} vertex properties", words.size(), values.size()));
    }
    for (std::size_t p = 0; p < values.size(); ++p) values[p] = text.number(words[p]);
    out.add_values(values);
  }
}

}  // namespace

DecodedCloud parse_ply(std::span<const std::byte> bytes, const std::filesystem::path& file,
                       std::optional<double> scan_stamp) {
  const PlyHeader header = parse_header(bytes, file);
  std::size_t vertex = 0;
  while (vertex < header.elements.size() && header.elements[vertex].name != "vertex") ++vertex;
  if (vertex == header.elements.size()) throw InputError(file, "PLY file has no 'vertex' element");
  const PlyElement& v = header.elements[vertex];
  if (v.has_list) throw InputError(file, "the 'vertex' element has a list property: not a point cloud");
  const FieldRoles roles = FieldRoles::find(v.properties, file);
  const auto data = bytes.subspan(header.data_offset);
  const std::size_t capacity = header.encoding == PlyEncoding::kAscii ? data.size() / 2 : data.size() / std::max<std::size_t>(v.stride, 1);
  CloudAssembler out(v.properties, roles, std::min(v.count, capacity));
  if (header.encoding == PlyEncoding::kAscii) {
    decode_ascii(data, header, vertex, out, file);
  } else {
    decode_binary(data, header, vertex, out, file);
  }
  return out.decoded(v.count, scan_stamp, file);
}

DecodedCloud read_ply_cloud(const std::filesystem::path& file, std::optional<double> scan_stamp) {
  return parse_ply(read_file_bytes(file, "PLY file"), file, scan_stamp);
}

LabelledCloud read_ply(const std::filesystem::path& file) { return read_ply_cloud(file).cloud; }

void write_ply(const std::filesystem::path& file, const LabelledCloud& cloud, const Pose& transform) {
  AtomicFile file_out(file);
  std::ostream& out = file_out.stream();
  out << "ply\nformat binary_little_endian 1.0\ncomment saloam labelled point cloud (SemanticKITTI classes)\n"
      << "element vertex " << cloud.size() << '\n'
      << "property float x\nproperty float y\nproperty float z\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "property ushort label\nproperty ushort instance\nproperty float remission\nend_header\n";
  const Eigen::Affine3f T = transform.cast<float>();
  std::vector<char> buffer(cloud.size() * kRecordBytes);
  char* dst = buffer.data();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = T * cloud.points[i];
    const Rgb c = class_color(cloud.label[i]);
    put(dst, p.x());
    put(dst, p.y());
    put(dst, p.z());
    put(dst, c.r);
    put(dst, c.g);
    put(dst, c.b);
    put(dst, cloud.label[i]);
    put(dst, cloud.instance[i]);
    put(dst, cloud.remission[i]);
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  file_out.commit();
}

void write_ply_scan(const std::filesystem::path& file, const LabelledCloud& cloud, PlyEncoding encoding) {
  const ScanRecordLayout layout = ScanRecordLayout::of(cloud);
  const std::vector<PointField>& fields = layout.fields;
  const std::size_t stride = layout.stride;
  const char* format = encoding == PlyEncoding::kAscii                ? "ascii"
                       : encoding == PlyEncoding::kBinaryLittleEndian ? "binary_little_endian"
                                                                      : "binary_big_endian";
  std::string text = fmt::format("ply\nformat {} 1.0\ncomment saloam scan\nelement vertex {}\n", format, cloud.size());
  for (const auto& f : fields) text += fmt::format("property {} {}\n", f.type == ScalarType::kUint16 ? "ushort" : "float", f.name);
  text += "end_header\n";
  std::vector<std::byte> body;
  if (encoding == PlyEncoding::kAscii) {
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      for (std::size_t f = 0; f < fields.size(); ++f) {
        if (f > 0) text += ' ';
        fmt::format_to(std::back_inserter(text), "{}", static_cast<float>(ScanRecordLayout::value(cloud, i, f)));
      }
      text += '\n';
    }
  } else {
    body.resize(cloud.size() * stride);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      for (std::size_t f = 0; f < fields.size(); ++f) {
        write_scalar(body.data() + i * stride + fields[f].offset, fields[f].type, ScanRecordLayout::value(cloud, i, f),
                     encoding == PlyEncoding::kBinaryBigEndian);
      }
    }
  }
  std::vector<std::byte> all(text.size() + body.size());
  std::memcpy(all.data(), text.data(), text.size());
  if (!body.empty()) std::memcpy(all.data() + text.size(), body.data(), body.size());
  write_file_bytes(file, all);
}

}  // namespace saloam
