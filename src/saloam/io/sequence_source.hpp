#pragma once
// A SemanticKITTI sequence folder (io/sequence.hpp) as a FrameSource:
// rereadable, labels when the folder (or the labels folder given) has them,
// Tr from calib.txt, ground truth from poses.txt and, in simulated
// sequences, poses_sensor.txt. Without calib.txt (or with read_calib false)
// it has no Tr: poses.txt is then taken as LiDAR-frame poses. Remission is
// divided by the range found in the first scan's float32 values, or given
// (io/intensity_scale.hpp): KITTI's own scans hold 0..1, other .bin exports
// 0..255.

#include <optional>

#include "saloam/io/frame_source.hpp"
#include "saloam/io/intensity_scale.hpp"
#include "saloam/io/sequence.hpp"

namespace saloam {

class SequenceFolderSource final : public FrameSource {
 public:
  /// Reads calib.txt when the folder has one, unless `read_calib` is false
  /// (the source then has no Tr), and poses_sensor.txt when present
  /// (InputError when either is unreadable or does not match the scans).
  /// `intensity_scale`: the divisor given (--intensity-scale); none: decided
  /// from the first scan, which is read here.
  explicit SequenceFolderSource(SequenceReader reader, bool read_calib = true,
                                std::optional<float> intensity_scale = std::nullopt);

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override;

 private:
  SequenceReader reader_;
  IntensityScale intensity_;
  SourceInfo info_;
};

/// The intensity range of a sequence folder (io/intensity_scale.hpp): `given`
/// when set, else decided on its first .bin scan; a first scan that cannot
/// be read counts as 0..1 (whatever reads it fails on it, naming it).
IntensityScale sequence_intensity_scale(const SequenceReader& reader, std::optional<float> given = std::nullopt);

}  // namespace saloam
