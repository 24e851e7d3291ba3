#include "saloam/place/sgpr_weights.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"

namespace saloam {
namespace {

constexpr char kMagic[8] = {'S', 'G', 'P', 'R', 'W', '0', '0', '1'};
// Far more than the 43 tensors of SGPR; guards against garbage counts.
constexpr std::uint32_t kMaxTensors = 4096;
// SGPR's weights are 0.3 MB; a file this large is not a model of it.
constexpr std::size_t kMaxWeightsBytes = std::size_t{256} << 20;

std::string shape_text(const std::vector<std::uint32_t>& dims) {
  std::ostringstream out;
  out << '[';
  for (std::size_t i = 0; i < dims.size(); ++i) out << (i ? " x " : "") << dims[i];
  out << ']';
  return out.str();
}

/// Little-endian cursor over the file's bytes; every read checks the length.
class Reader {
 public:
  Reader(std::span<const std::byte> bytes, const std::filesystem::path& source) : bytes_(bytes), source_(source) {}

  void need(std::size_t n, const std::string& what) const {
    if (bytes_.size() - offset_ < n)
      throw InputError(source_, "truncated file: " + what + " needs " + std::to_string(n) + " bytes at offset " +
                                    std::to_string(offset_) + ", only " + std::to_string(bytes_.size() - offset_) +
                                    " left");
  }
  std::uint32_t u32(const std::string& what) {
    need(4, what);
    const auto* p = reinterpret_cast<const unsigned char*>(bytes_.data() + offset_);
    offset_ += 4;
    return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
           static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
  }
  std::span<const std::byte> take(std::size_t n, const std::string& what) {
    need(n, what);
    const auto out = bytes_.subspan(offset_, n);
    offset_ += n;
    return out;
  }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - offset_; }
  [[nodiscard]] std::size_t offset() const { return offset_; }

 private:
  std::span<const std::byte> bytes_;
  const std::filesystem::path& source_;
  std::size_t offset_ = 0;
};

void put_u32(std::vector<std::byte>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::byte>((v >> (8 * i)) & 0xffu));
}

}  // namespace

const SgprTensor& SgprWeights::require(const std::string& name, const std::vector<std::uint32_t>& dims) const {
  const auto it = tensors.find(name);
  if (it == tensors.end()) throw InputError(source, "SGPR weights lack tensor '" + name + "'");
  if (it->second.dims != dims)
    throw InputError(source, "SGPR tensor '" + name + "' has shape " + shape_text(it->second.dims) + ", expected " +
                                 shape_text(dims));
  return it->second;
}

SgprWeights parse_sgpr_weights(std::span<const std::byte> bytes, const std::filesystem::path& source) {
  static_assert(std::numeric_limits<float>::is_iec559 && sizeof(float) == 4);
  SgprWeights weights;
  weights.source = source;
  Reader in(bytes, source);
  const auto magic = in.take(sizeof(kMagic), "magic");
  if (std::memcmp(magic.data(), kMagic, sizeof(kMagic)) != 0)
    throw InputError(source, "not an SGPR weights file (magic is not \"SGPRW001\")");
  const std::uint32_t count = in.u32("tensor count");
  if (count == 0 || count > kMaxTensors)
    throw InputError(source, "implausible tensor count " + std::to_string(count));
  for (std::uint32_t t = 0; t < count; ++t) {
    const std::string record = "tensor record " + std::to_string(t);
    const std::uint32_t name_length = in.u32(record + " name length");
    if (name_length == 0 || name_length > 1024)
      throw InputError(source, record + ": implausible name length " + std::to_string(name_length));
    const auto name_bytes = in.take(name_length, record + " name");
    std::string name(reinterpret_cast<const char*>(name_bytes.data()), name_length);
    const std::uint32_t ndim = in.u32("'" + name + "' ndim");
    if (ndim < 1 || ndim > 4)
      throw InputError(source, "tensor '" + name + "' has " + std::to_string(ndim) + " dimensions (expected 1..4)");
    SgprTensor tensor;
    std::uint64_t elements = 1;
    for (std::uint32_t d = 0; d < ndim; ++d) {
      tensor.dims.push_back(in.u32("'" + name + "' dims"));
      elements *= tensor.dims.back();
      // Checked per dimension so that absurd shapes cannot overflow.
      if (elements * 4 > in.remaining())
        throw InputError(source, "truncated file or bad shape: tensor '" + name + "' of shape " +
                                     shape_text(tensor.dims) + " is larger than the rest of the file");
    }
    const auto data = in.take(static_cast<std::size_t>(elements) * 4, "'" + name + "' values");
    tensor.values.resize(static_cast<std::size_t>(elements));
    for (std::size_t i = 0; i < tensor.values.size(); ++i) {
      const auto* p = reinterpret_cast<const unsigned char*>(data.data() + 4 * i);
      const std::uint32_t bits = static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
                                 static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
      float value;
      std::memcpy(&value, &bits, 4);
      if (!std::isfinite(value))
        throw InputError(source, "tensor '" + name + "' holds a non-finite value at element " + std::to_string(i));
      if (std::abs(value) > kMaxSgprWeight)
        throw InputError(source, fmt::format("tensor '{}' holds {:g} at element {}, beyond +-{:g}: not trained "
                                             "weights (they would overflow the network's arithmetic)",
                                             name, value, i, kMaxSgprWeight));
      tensor.values[i] = value;
    }
    if (!weights.tensors.emplace(name, std::move(tensor)).second)
      throw InputError(source, "tensor '" + name + "' appears twice");
  }
  if (in.remaining() != 0)
    throw InputError(source, std::to_string(in.remaining()) + " unexpected bytes after the last tensor (offset " +
                                 std::to_string(in.offset()) + ")");
  return weights;
}

SgprWeights read_sgpr_weights(const std::filesystem::path& file) {
  const std::string raw = read_file(file, kMaxWeightsBytes, "SGPR weights file");
  return parse_sgpr_weights(std::as_bytes(std::span<const char>(raw)), file);
}

std::vector<std::byte> serialize_sgpr_weights(const SgprWeights& weights) {
  std::vector<std::byte> out;
  for (const char c : kMagic) out.push_back(static_cast<std::byte>(c));
  put_u32(out, static_cast<std::uint32_t>(weights.tensors.size()));
  for (const auto& [name, tensor] : weights.tensors) {
    put_u32(out, static_cast<std::uint32_t>(name.size()));
    for (const char c : name) out.push_back(static_cast<std::byte>(c));
    put_u32(out, static_cast<std::uint32_t>(tensor.dims.size()));
    for (const auto d : tensor.dims) put_u32(out, d);
    for (const float v : tensor.values) {
      std::uint32_t bits;
      std::memcpy(&bits, &v, 4);
      put_u32(out, bits);
    }
  }
  return out;
}

void write_sgpr_weights(const std::filesystem::path& file, const SgprWeights& weights) {
  for (const auto& [name, tensor] : weights.tensors) {
    std::uint64_t elements = 1;
    for (const auto d : tensor.dims) elements *= d;
    if (tensor.dims.empty() || tensor.dims.size() > 4 || elements != tensor.values.size())
      throw std::invalid_argument("SGPR tensor '" + name + "' of shape " + shape_text(tensor.dims) + " holds " +
                                  std::to_string(tensor.values.size()) + " values");
    for (const float v : tensor.values)
      if (!std::isfinite(v) || std::abs(v) > kMaxSgprWeight)
        throw std::invalid_argument("SGPR tensor '" + name + "' holds a non-finite or absurd value");
  }
  const auto bytes = serialize_sgpr_weights(weights);
  write_file_atomically(file, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace saloam
