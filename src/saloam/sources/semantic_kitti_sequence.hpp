#pragma once
// A SemanticKITTI sequence folder (io/sequence.hpp's SequenceReader) as a
// ScanSequence. Without calib.txt it runs in the LiDAR frame: poses.txt is
// then taken as LiDAR-frame poses.

#include "saloam/io/sequence.hpp"
#include "saloam/sources/scan_sequence.hpp"

namespace saloam {

class SemanticKittiSequence final : public ScanSequence {
 public:
  SemanticKittiSequence(std::filesystem::path root, const ScanSequenceOptions& options);

  [[nodiscard]] ScanFormat format() const override { return ScanFormat::kSemanticKitti; }
  [[nodiscard]] const std::filesystem::path& path() const override { return reader_.root(); }
  [[nodiscard]] std::size_t size() const override { return reader_.size(); }
  [[nodiscard]] const std::vector<double>& times() const override { return reader_.times(); }
  [[nodiscard]] bool has_labels() const override { return reader_.has_labels(); }
  LabelledCloud scan(std::size_t i) override { return reader_.load_scan(i); }
  [[nodiscard]] std::optional<Pose> velo_to_cam() const override;
  [[nodiscard]] std::optional<std::vector<Pose>> reference_poses() const override;
  [[nodiscard]] ScanSequenceFacts facts() const override;
  [[nodiscard]] const SequenceReader& reader() const { return reader_; }

 private:
  SequenceReader reader_;
};

}  // namespace saloam
