#include "saloam/io/pcd.hpp"

#include <algorithm>
#include <cstring>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/io/binary_file.hpp"
#include "saloam/io/text_records.hpp"

#ifdef SALOAM_HAVE_LZF
#include <lzf.h>
#endif

namespace saloam {
namespace {

// Limits that keep a hostile header from asking for absurd sizes before
// the data are checked against them.
constexpr std::size_t kMaxFields = 1024;
constexpr std::size_t kMaxElementsPerPoint = 1 << 16;
constexpr std::size_t kMaxStride = 1 << 20;
constexpr std::size_t kMaxHeaderLines = 4096;
/// LZF turns at most 3 bytes into 264 (a long back reference): a larger
/// claimed ratio is a corrupt header.
constexpr std::size_t kMaxLzfRatio = 100;

struct PcdHeader {
  std::vector<PointField> fields;  ///< `_` padding fields included
  std::size_t stride = 0;          ///< bytes of one point (every field, every element)
  std::size_t elements = 0;        ///< values on one ASCII line
  std::size_t points = 0;
  PcdEncoding encoding = PcdEncoding::kAscii;
  std::size_t data_offset = 0;  ///< where the data start in the file
};

ScalarType pcd_scalar(char type, std::size_t size, const std::filesystem::path& file, std::size_t line_no) {
  if (type == 'F' && size == 4) return ScalarType::kFloat32;
  if (type == 'F' && size == 8) return ScalarType::kFloat64;
  if (type == 'I' && size == 1) return ScalarType::kInt8;
  if (type == 'I' && size == 2) return ScalarType::kInt16;
  if (type == 'I' && size == 4) return ScalarType::kInt32;
  if (type == 'I' && size == 8) return ScalarType::kInt64;
  if (type == 'U' && size == 1) return ScalarType::kUint8;
  if (type == 'U' && size == 2) return ScalarType::kUint16;
  if (type == 'U' && size == 4) return ScalarType::kUint32;
  if (type == 'U' && size == 8) return ScalarType::kUint64;
  throw InputError(file, fmt::format("header line {}: no PCD type '{}' of {} bytes (I, U: 1, 2, 4, 8; F: 4, 8)", line_no,
                                     type, size));
}

/// The raw header entries, by key, with their line numbers.
struct HeaderLines {
  std::vector<std::string> names, sizes, types, counts;
  std::optional<std::size_t> width, height, points;
  std::size_t fields_line = 0, sizes_line = 0, types_line = 0, counts_line = 0;
  std::string data;
};

void collect_header(TextRecords& text, HeaderLines& h, const std::filesystem::path& file) {
  std::string_view line;
  while (text.next_line(line)) {
    if (text.line_number() > kMaxHeaderLines) throw InputError(file, "no DATA line in the first 4096 lines: not a PCD file");
    const auto words = split_words(line);
    if (words.empty() || words[0].starts_with('#')) continue;
    const std::string_view key = words[0];
    const std::vector<std::string> values(words.begin() + 1, words.end());
    const auto count = [&](std::string_view name) { return text.unsigned_value(values, name); };
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS" || key == "COLUMNS") {
      h.names = values;
      h.fields_line = text.line_number();
    } else if (key == "SIZE") {
      h.sizes = values;
      h.sizes_line = text.line_number();
    } else if (key == "TYPE") {
      h.types = values;
      h.types_line = text.line_number();
    } else if (key == "COUNT") {
      h.counts = values;
      h.counts_line = text.line_number();
    } else if (key == "WIDTH") {
      h.width = count("WIDTH");
    } else if (key == "HEIGHT") {
      h.height = count("HEIGHT");
    } else if (key == "POINTS") {
      h.points = count("POINTS");
    } else if (key == "DATA") {
      if (values.size() != 1) throw text.error("DATA needs one word: ascii, binary or binary_compressed");
      h.data = values[0];
      return;
    } else {
      throw text.error(fmt::format("unknown PCD header key '{}'", key));
    }
  }
  throw InputError(file, "no DATA line: not a PCD file, or its header is cut off");
}

PcdHeader parse_header(std::span<const std::byte> bytes, const std::filesystem::path& file) {
  TextRecords text(bytes, file, "header line");
  HeaderLines h;
  collect_header(text, h, file);
  PcdHeader header;
  header.data_offset = text.offset();
  if (h.names.empty()) throw InputError(file, "PCD header has no FIELDS line");
  if (h.names.size() > kMaxFields) throw InputError(file, fmt::format("{} fields: more than {}", h.names.size(), kMaxFields));
  if (h.sizes.size() != h.names.size() || h.types.size() != h.names.size()) {
    throw InputError(file, fmt::format("PCD header: {} FIELDS but {} SIZE and {} TYPE entries", h.names.size(),
                                       h.sizes.size(), h.types.size()));
  }
  if (!h.counts.empty() && h.counts.size() != h.names.size()) {
    throw InputError(file, fmt::format("PCD header: {} FIELDS but {} COUNT entries", h.names.size(), h.counts.size()));
  }
  for (std::size_t i = 0; i < h.names.size(); ++i) {
    const std::size_t size = TextRecords::unsigned_at(h.sizes[i], file, h.sizes_line, "SIZE");
    if (h.types[i].size() != 1) throw InputError(file, fmt::format("header line {}: TYPE '{}' is not I, U or F", h.types_line, h.types[i]));
    const std::size_t count = h.counts.empty() ? 1 : TextRecords::unsigned_at(h.counts[i], file, h.counts_line, "COUNT");
    if (count == 0 || count > kMaxElementsPerPoint) {
      throw InputError(file, fmt::format("header line {}: COUNT {} of field '{}' is out of range (1..{})", h.counts_line,
                                         count, h.names[i], kMaxElementsPerPoint));
    }
    PointField f{h.names[i], pcd_scalar(h.types[i][0], size, file, h.types_line), header.stride, count};
    header.stride += size * count;
    header.elements += count;
    if (header.stride > kMaxStride || header.elements > kMaxElementsPerPoint) {
      throw InputError(file, fmt::format("a point of more than {} bytes or {} values: not a point cloud", kMaxStride,
                                         kMaxElementsPerPoint));
    }
    header.fields.push_back(std::move(f));
  }
  if (h.width && h.height && h.points && *h.points != *h.width * *h.height) {
    throw InputError(file, fmt::format("POINTS {} is not WIDTH {} x HEIGHT {}", *h.points, *h.width, *h.height));
  }
  if (!h.points && !(h.width && h.height)) throw InputError(file, "PCD header has neither POINTS nor WIDTH and HEIGHT");
  header.points = h.points ? *h.points : *h.width * *h.height;
  if (h.data == "ascii") {
    header.encoding = PcdEncoding::kAscii;
  } else if (h.data == "binary") {
    header.encoding = PcdEncoding::kBinary;
  } else if (h.data == "binary_compressed") {
    header.encoding = PcdEncoding::kBinaryCompressed;
  } else {
    throw InputError(file, fmt::format("DATA '{}' is not ascii, binary or binary_compressed", h.data));
  }
  return header;
}

[[maybe_unused]] std::uint32_t load_u32(const std::byte* p) {  // unused without liblzf
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

/// The packed records (point after point) of binary_compressed data, whose
/// fields are stored one after another.
std::vector<std::byte> decompress_fields(std::span<const std::byte> data, const PcdHeader& header,
                                         const std::filesystem::path& file) {
#ifndef SALOAM_HAVE_LZF
  (void)data;
  (void)header;
  throw InputError(file, "binary_compressed PCD is not built into this saloam (install liblzf-dev and rebuild)");
#else
  if (data.size() < 8) throw InputError(file, "binary_compressed data shorter than its 8-byte size header");
  const std::size_t compressed = load_u32(data.data());
  const std::size_t size = load_u32(data.data() + 4);
  if (compressed > data.size() - 8) {
    throw InputError(file, fmt::format("truncated: {} compressed bytes announced, {} present", compressed, data.size() - 8));
  }
  if (header.points > size / std::max<std::size_t>(header.stride, 1) || size != header.points * header.stride) {
    throw InputError(file, fmt::format("binary_compressed size {} is not POINTS {} x {} bytes per point", size,
                                       header.points, header.stride));
  }
  if (size > kMaxLzfRatio * compressed + 1024) {
    throw InputError(file, fmt::format("{} bytes cannot come from {} LZF bytes: corrupt header", size, compressed));
  }
  std::vector<std::byte> fields(size);
  if (size > 0) {
    const unsigned got = lzf_decompress(data.data() + 8, static_cast<unsigned>(compressed), fields.data(),
                                        static_cast<unsigned>(size));
    if (got != size) throw InputError(file, fmt::format("corrupt LZF data ({} of {} bytes decompressed)", got, size));
  }
  std::vector<std::byte> records(size);
  for (const PointField& f : header.fields) {
    const std::size_t width = scalar_size(f.type) * f.count;
    const std::byte* src = fields.data() + f.offset * header.points;
    for (std::size_t i = 0; i < header.points; ++i) {
      std::memcpy(records.data() + i * header.stride + f.offset, src + i * width, width);
    }
  }
  return records;
#endif
}

void decode_binary(std::span<const std::byte> records, const PcdHeader& header, CloudAssembler& out,
                   const std::filesystem::path& file) {
  if (header.points > records.size() / std::max<std::size_t>(header.stride, 1)) {
    throw InputError(file, fmt::format("truncated: {} points of {} bytes need {:.0f} bytes of data, found {}", header.points,
                                       header.stride, static_cast<double>(header.points) * static_cast<double>(header.stride),
                                       records.size()));
  }
  for (std::size_t i = 0; i < header.points; ++i) out.add_binary(records.data() + i * header.stride, false);
}

void decode_ascii(std::span<const std::byte> data, const PcdHeader& header, CloudAssembler& out,
                  const std::filesystem::path& file, std::size_t first_line) {
  TextRecords text(data, file, "line", first_line);
  std::vector<double> values(header.fields.size());
  std::string_view line;
  std::size_t read = 0;
  while (read < header.points && text.next_line(line)) {
    const auto words = split_words(line);
    if (words.empty()) continue;
    if (words.size() != header.elements) {
      throw text.error(fmt::format("{} values, the header declares {} per point", words.size(), header.elements));
    }
    std::size_t word = 0;
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
      values[f] = text.number(words[word]);
      word += header.fields[f].count;
    }
    out.add_values(values);
    ++read;
  }
  if (read < header.points) {
    throw InputError(file, fmt::format("truncated: {} of the {} points declared", read, header.points));
  }
}

}  // namespace

bool pcd_compression_available() {
#ifdef SALOAM_HAVE_LZF
  return true;
#else
  return false;
#endif
}

DecodedCloud parse_pcd(std::span<const std::byte> bytes, const std::filesystem::path& file,
                       std::optional<double> scan_stamp) {
  const PcdHeader header = parse_header(bytes, file);
  const FieldRoles roles = FieldRoles::find(header.fields, file);
  const auto data = bytes.subspan(header.data_offset);
  // Reserve no more points than the data can hold (at least 2 bytes a point in ASCII).
  const std::size_t capacity = header.encoding == PcdEncoding::kAscii ? data.size() / 2
                               : header.encoding == PcdEncoding::kBinary ? data.size() / std::max<std::size_t>(header.stride, 1)
                                                                         : data.size() * kMaxLzfRatio / std::max<std::size_t>(header.stride, 1);
  CloudAssembler out(header.fields, roles, std::min(header.points, capacity));
  if (header.encoding == PcdEncoding::kAscii) {
    const auto header_lines = static_cast<std::size_t>(
        std::count(reinterpret_cast<const char*>(bytes.data()), reinterpret_cast<const char*>(data.data()), '\n'));
    decode_ascii(data, header, out, file, header_lines + 1);
  } else if (header.encoding == PcdEncoding::kBinary) {
    decode_binary(data, header, out, file);
  } else {
    decode_binary(decompress_fields(data, header, file), header, out, file);
  }
  return out.decoded(header.points, scan_stamp, file);
}

DecodedCloud read_pcd(const std::filesystem::path& file, std::optional<double> scan_stamp) {
  return parse_pcd(read_file_bytes(file, "PCD file"), file, scan_stamp);
}

namespace {

char pcd_type_letter(ScalarType t) {
  if (is_floating(t)) return 'F';
  return (t == ScalarType::kUint8 || t == ScalarType::kUint16 || t == ScalarType::kUint32 || t == ScalarType::kUint64) ? 'U' : 'I';
}

std::string pcd_header(const std::vector<PointField>& fields, std::size_t points, std::string_view data) {
  std::string names, sizes, types, counts;
  for (const auto& f : fields) {
    names += " " + f.name;
    sizes += fmt::format(" {}", scalar_size(f.type));
    types += fmt::format(" {}", pcd_type_letter(f.type));
    counts += " 1";
  }
  return fmt::format("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS{}\nSIZE{}\nTYPE{}\nCOUNT{}\n"
                     "WIDTH {}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA {}\n",
                     names, sizes, types, counts, points, points, data);
}

}  // namespace

void write_pcd(const std::filesystem::path& file, const LabelledCloud& cloud, PcdEncoding encoding) {
  const ScanRecordLayout layout = ScanRecordLayout::of(cloud);
  const std::vector<PointField>& fields = layout.fields;
  const std::size_t stride = layout.stride;
  const std::size_t n = cloud.size();
  std::string text;
  std::vector<std::byte> body;
  if (encoding == PcdEncoding::kAscii) {
    text = pcd_header(fields, n, "ascii");
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t f = 0; f < fields.size(); ++f) {
        if (f > 0) text += ' ';
        fmt::format_to(std::back_inserter(text), "{}", static_cast<float>(ScanRecordLayout::value(cloud, i, f)));
      }
      text += '\n';
    }
  } else {
    const bool compressed = encoding == PcdEncoding::kBinaryCompressed;
    text = pcd_header(fields, n, compressed ? "binary_compressed" : "binary");
    std::vector<std::byte> packed(n * stride);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t f = 0; f < fields.size(); ++f) {
        // binary: point after point; binary_compressed: field after field.
        std::byte* at = compressed ? packed.data() + fields[f].offset * n + i * scalar_size(fields[f].type)
                                   : packed.data() + i * stride + fields[f].offset;
        write_scalar(at, fields[f].type, ScanRecordLayout::value(cloud, i, f), false);
      }
    }
    if (!compressed) {
      body = std::move(packed);
    } else {
#ifdef SALOAM_HAVE_LZF
      std::vector<std::byte> lzf(packed.size() + packed.size() / 16 + 64);
      const unsigned size = packed.empty() ? 0
                                           : lzf_compress(packed.data(), static_cast<unsigned>(packed.size()), lzf.data(),
                                                          static_cast<unsigned>(lzf.size()));
      if (size == 0 && !packed.empty()) throw InputError(file, "LZF compression failed");
      body.resize(8 + size);
      const auto compressed_size = static_cast<std::uint32_t>(size);
      const auto raw_size = static_cast<std::uint32_t>(packed.size());
      std::memcpy(body.data(), &compressed_size, 4);
      std::memcpy(body.data() + 4, &raw_size, 4);
      std::memcpy(body.data() + 8, lzf.data(), size);
#else
      throw InputError(file, "binary_compressed PCD is not built into this saloam (install liblzf-dev and rebuild)");
#endif
    }
  }
  std::vector<std::byte> all(text.size() + body.size());
  std::memcpy(all.data(), text.data(), text.size());
  if (!body.empty()) std::memcpy(all.data() + text.size(), body.data(), body.size());
  write_file_bytes(file, all);
}

}  // namespace saloam
