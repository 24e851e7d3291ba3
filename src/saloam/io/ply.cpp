#include "saloam/io/ply.hpp"

#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/semantic_classes.hpp"

namespace saloam {
namespace {

// One vertex record as written: 12 + 3 + 2 + 2 + 4 = 23 bytes, packed.
constexpr std::size_t kRecordBytes = 23;
// A map of 100 million points; larger files are not read.
constexpr std::size_t kMaxPlyBytes = std::size_t{4} << 30;

template <class T>
void put(char*& dst, T value) {
  std::memcpy(dst, &value, sizeof(T));
  dst += sizeof(T);
}

}  // namespace

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

LabelledCloud read_ply(const std::filesystem::path& file) {
  const std::string bytes = read_file(file, kMaxPlyBytes, "PLY file");
  std::istringstream in(bytes);
  std::string line;
  std::getline(in, line);
  if (line != "ply") throw InputError(file, "not a PLY file (missing 'ply' magic)");

  struct Property {
    std::string name;
    std::size_t size;
    std::size_t offset;
    std::string type;
  };
  std::vector<Property> props;
  std::size_t count = 0, stride = 0;
  bool in_vertex = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream ss(line);
    std::string word;
    ss >> word;
    if (word == "format") {
      std::string fmt_name;
      ss >> fmt_name;
      if (fmt_name != "binary_little_endian") throw InputError(file, "only binary_little_endian PLY is supported");
    } else if (word == "element") {
      std::string name;
      ss >> name >> count;
      in_vertex = name == "vertex";
      if (!in_vertex && !props.empty()) break;  // vertices come first in our files
    } else if (word == "property" && in_vertex) {
      std::string type, name;
      ss >> type >> name;
      const std::size_t size = (type == "float" || type == "int" || type == "uint" || type == "float32") ? 4
                               : (type == "double")                                                     ? 8
                               : (type == "ushort" || type == "short" || type == "uint16")              ? 2
                                                                                                        : 1;
      props.push_back({name, size, stride, type});
      stride += size;
    }
  }
  if (line != "end_header") throw InputError(file, "PLY header has no end_header");
  auto find = [&](const std::string& n) -> const Property* {
    for (const auto& p : props) {
      if (p.name == n) return &p;
    }
    return nullptr;
  };
  const Property* px = find("x");
  const Property* py = find("y");
  const Property* pz = find("z");
  if (!px || !py || !pz || px->type != "float") throw InputError(file, "PLY vertices need float x, y, z");
  const Property* plabel = find("label");
  const Property* pinst = find("instance");
  const Property* prem = find("remission");

  const std::streamoff position = in.tellg();  // -1 when the header ends the file
  const std::size_t header_end = position < 0 ? bytes.size() : static_cast<std::size_t>(position);
  if (stride == 0 || count > (bytes.size() - header_end) / stride) {
    throw InputError(file, fmt::format("truncated PLY: expected {} vertices of {} bytes", count, stride));
  }
  const std::string_view data(bytes.data() + header_end, count * stride);
  LabelledCloud cloud;
  cloud.has_labels = plabel != nullptr;
  cloud.reserve(count);
  auto get_f = [&](const char* rec, const Property* p) {
    float v;
    std::memcpy(&v, rec + p->offset, 4);
    return v;
  };
  auto get_u16 = [&](const char* rec, const Property* p) -> std::uint16_t {
    if (!p || p->size != 2) return 0;
    std::uint16_t v;
    std::memcpy(&v, rec + p->offset, 2);
    return v;
  };
  for (std::size_t i = 0; i < count; ++i) {
    const char* rec = data.data() + i * stride;
    cloud.push_back({get_f(rec, px), get_f(rec, py), get_f(rec, pz)},
                    prem && prem->type == "float" ? get_f(rec, prem) : 0.0f, get_u16(rec, plabel),
                    get_u16(rec, pinst));
  }
  return cloud;
}

}  // namespace saloam
