#pragma once
// A SemanticKITTI sequence folder (io/sequence.hpp) as a FrameSource:
// rereadable, labels when the folder (or the labels folder given) has them,
// Tr from calib.txt, ground truth from poses.txt and, in simulated
// sequences, poses_sensor.txt. Without calib.txt (or with read_calib false)
// it has no Tr: poses.txt is then taken as LiDAR-frame poses.

#include "saloam/io/frame_source.hpp"
#include "saloam/io/sequence.hpp"

namespace saloam {

class SequenceFolderSource final : public FrameSource {
 public:
  /// Reads calib.txt when the folder has one, unless `read_calib` is false
  /// (the source then has no Tr), and poses_sensor.txt when present
  /// (InputError when either is unreadable or does not match the scans).
  explicit SequenceFolderSource(SequenceReader reader, bool read_calib = true);

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override { return reader_.load_scan(i); }

 private:
  SequenceReader reader_;
  SourceInfo info_;
};

}  // namespace saloam
