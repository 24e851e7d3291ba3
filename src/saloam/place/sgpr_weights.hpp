#pragma once
// Pretrained SGPR weights in the flat `.sgw` format (described in
// ../shared/models/sgpr/FORMAT.md): magic "SGPRW001", a tensor count, then
// named float32 tensors in row-major order.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace saloam {

/// A weight beyond this in magnitude is not a trained one (SGPR's models hold
/// values below 20; 3e38 overflows the network's float arithmetic to NaN).
inline constexpr float kMaxSgprWeight = 1.0e6F;

/// One named tensor: its dimensions (outermost first) and row-major values.
struct SgprTensor {
  std::vector<std::uint32_t> dims;
  std::vector<float> values;
};

/// All tensors of one `.sgw` file, looked up by name. `source` names the file
/// in error messages.
struct SgprWeights {
  std::filesystem::path source;
  std::map<std::string, SgprTensor> tensors;

  /// The tensor `name` after checking its shape; throws InputError (naming
  /// `source`) when it is missing or shaped differently.
  [[nodiscard]] const SgprTensor& require(const std::string& name, const std::vector<std::uint32_t>& dims) const;
};

/// Parses the bytes of a `.sgw` file. Throws InputError(source, ...) for a
/// wrong magic, truncated records, bad dimensions, duplicate names,
/// non-finite values, values beyond kMaxSgprWeight or trailing bytes.
SgprWeights parse_sgpr_weights(std::span<const std::byte> bytes, const std::filesystem::path& source);

/// Reads and parses a `.sgw` file; throws InputError when it is missing or malformed.
SgprWeights read_sgpr_weights(const std::filesystem::path& file);

/// Serialises weights in the `.sgw` layout (tensors in name order; readers
/// look tensors up by name), as they are (tests use it to make bad files).
std::vector<std::byte> serialize_sgpr_weights(const SgprWeights& weights);

/// Writes weights as a `.sgw` file: to a temporary file beside `file`, then
/// renamed over it, so a reader (or an interrupted run) never sees half a
/// file. Throws std::invalid_argument (writing nothing) when a tensor's value
/// count does not match its dims or a value is not finite or beyond
/// kMaxSgprWeight, so that nothing
/// the reader would refuse is ever written; InputError naming the file when
/// it cannot be written.
void write_sgpr_weights(const std::filesystem::path& file, const SgprWeights& weights);

}  // namespace saloam
