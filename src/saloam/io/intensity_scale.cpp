#include "saloam/io/intensity_scale.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace saloam {
namespace {

constexpr std::string_view kNotePrefix = "intensity: ";

std::string range_text(float divisor) { return divisor == 1.0F ? "0-1" : fmt::format("0-{:.0f}", divisor); }

/// The divisor the values' peak says.
float divisor_of_peak(float peak) {
  if (peak <= kUnitIntensityPeak) return 1.0F;
  if (peak <= kByteIntensityPeak) return 255.0F;
  return 65535.0F;
}

}  // namespace

std::string IntensityScale::describe() const {
  const std::string applied = divisor == 1.0F ? "kept" : fmt::format("divided by {:.0f}", divisor);
  return how.empty() ? fmt::format("{}, {}", range_text(divisor), applied)
                     : fmt::format("{}, {} ({})", range_text(divisor), applied, how);
}

std::string IntensityScale::note() const { return std::string(kNotePrefix) + describe(); }

std::optional<std::string> intensity_note(const std::vector<std::string>& notes) {
  for (const auto& note : notes) {
    if (note.starts_with(kNotePrefix)) return note;
  }
  return std::nullopt;
}

void IntensityScale::apply(LabelledCloud& cloud) const {
  if (divisor == 1.0F) return;
  for (float& r : cloud.remission) r /= divisor;
}

const std::vector<std::string>& intensity_scale_names() {
  static const std::vector<std::string> names{"auto", "1", "255", "65535"};
  return names;
}

std::optional<float> parse_intensity_scale(std::string_view text) {
  if (text == "auto") return std::nullopt;
  if (text == "1") return 1.0F;
  if (text == "255") return 255.0F;
  if (text == "65535") return 65535.0F;
  throw ConfigError(fmt::format("--intensity-scale {}: not one of auto, 1, 255, 65535", text));
}

float intensity_peak(std::span<const float> values) {
  std::vector<float> finite;
  finite.reserve(values.size());
  std::copy_if(values.begin(), values.end(), std::back_inserter(finite), [](float v) { return std::isfinite(v); });
  if (finite.empty()) return 0.0F;
  const std::size_t outliers = finite.size() <= 3 ? 0 : std::max<std::size_t>(3, finite.size() / 1000);
  const auto peak = finite.begin() + static_cast<std::ptrdiff_t>(std::min(outliers, finite.size() - 1));
  std::nth_element(finite.begin(), peak, finite.end(), std::greater<>());
  return *peak;
}

IntensityScale choose_intensity_scale(std::optional<float> given, std::optional<ScalarType> field_type,
                                      std::span<const float> first_scan) {
  if (given) return {*given, fmt::format("as given (--intensity-scale {:.0f})", *given)};
  if (!field_type) return {1.0F, "no intensity field: remission 0"};
  if (*field_type == ScalarType::kUint8) return {255.0F, "uint8 field"};
  const float peak = intensity_peak(first_scan);
  if (*field_type == ScalarType::kUint16) {
    return peak <= kByteIntensityPeak
               ? IntensityScale{255.0F, fmt::format("uint16 field, its values within 0-255: peak {:g} in the first scan", peak)}
               : IntensityScale{65535.0F, "uint16 field"};
  }
  return {divisor_of_peak(peak), fmt::format("detected: {} field, peak {:g} in the first scan (--intensity-scale to choose)",
                                             scalar_name(*field_type), peak)};
}

IntensityScale unread_intensity_scale(std::optional<float> given) {
  if (given) return {*given, fmt::format("as given (--intensity-scale {:.0f})", *given)};
  return {1.0F, "taken as such: the first scan cannot be read"};
}

}  // namespace saloam
