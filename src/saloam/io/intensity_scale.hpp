#pragma once
// How a source's intensity (remission) values are brought to 0..1, which is
// what LabelledCloud::remission means and what the segmentation network was
// trained on (KITTI's remission). Files store the value in one of three ranges:
//   0..1      KITTI .bin scans, the simulator's files in every layout
//   0..255    Velodyne drivers, nuScenes-style .bin exports, many PCD and PLY files
//   0..65535  Ouster signal and reflectivity, other uint16 fields
// Fed 0..255 values as they are, the network labels worse than at random
// (9.6 % mIoU against 27.6 % for the same scans divided by 255).
//
// A source decides its range once, when it is opened, and divides every
// scan by it, so that the frames of one sequence are never scaled
// differently (a per-frame guess could flip between a dark and a bright
// scan):
//   --intensity-scale 1|255|65535    that divisor, nothing guessed
//   uint8 field                      255
//   uint16 field                     65535, or 255 when the first scan's
//                                    values stay within 0..255 (Ouster
//                                    reflectivity of 8-bit firmware modes)
//   any other field (float, int)     from the first scan's values: their
//                                    peak (the largest once the top
//                                    max(3, 0.1 %) are left out as outliers)
//                                    up to 1.5: 0..1; up to 255: 0..255;
//                                    above: 0..65535
//   no intensity field               1 (remission reads 0)
// Values are divided, not clipped: a later scan brighter than the first
// keeps values above 1, as it had them above 255 in the file.

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/point_fields.hpp"

namespace saloam {

/// The peak above which values mean 0..255 rather than 0..1.
inline constexpr float kUnitIntensityPeak = 1.5F;
/// The peak above which values mean 0..65535 rather than 0..255.
inline constexpr float kByteIntensityPeak = 255.0F;

struct IntensityScale {
  float divisor = 1.0F;  ///< 1, 255 or 65535
  /// Why: "as given (--intensity-scale 255)", "uint8 field", "detected: the first scan's values peak at 87.5".
  std::string how;

  /// "0-255, divided by 255 (uint8 field)", "0-1, kept (...)".
  [[nodiscard]] std::string describe() const;
  /// The line a reader adds to SourceInfo::notes (what `saloam info` lists
  /// and the run logs): "intensity: " and describe().
  [[nodiscard]] std::string note() const;
  /// Divides the cloud's remission by `divisor` (nothing when it is 1).
  void apply(LabelledCloud& cloud) const;
};

/// Every --intensity-scale value: "auto", "1", "255", "65535".
[[nodiscard]] const std::vector<std::string>& intensity_scale_names();
/// The divisor of an --intensity-scale value; nullopt for "auto"; ConfigError
/// naming the option for anything else.
[[nodiscard]] std::optional<float> parse_intensity_scale(std::string_view text);

/// The level `values` reach with their top max(3, 0.1 %) left out (a few
/// stray returns of a 0..1 scan must not make it 0..255); the largest value
/// when there are no more than 3; 0 for none. Non-finite values are skipped.
[[nodiscard]] float intensity_peak(std::span<const float> values);

/// The scale of a source, as the table above says: `given` (--intensity-scale)
/// when set; else from `field_type` (the intensity field's type; nullopt when
/// the source has no intensity field) and `first_scan` (the first scan's
/// remission as stored).
[[nodiscard]] IntensityScale choose_intensity_scale(std::optional<float> given, std::optional<ScalarType> field_type,
                                                    std::span<const float> first_scan);
/// The intensity line among a source's notes (IntensityScale::note), when
/// its reader gave one.
[[nodiscard]] std::optional<std::string> intensity_note(const std::vector<std::string>& notes);

/// The scale of a source whose first scan cannot be read: `given`, else 1
/// (a run then fails on that scan, as it would anyway).
[[nodiscard]] IntensityScale unread_intensity_scale(std::optional<float> given);

}  // namespace saloam
