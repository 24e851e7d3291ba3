#include "saloam/sources/semantic_kitti_sequence.hpp"

namespace saloam {

SemanticKittiSequence::SemanticKittiSequence(std::filesystem::path root, const ScanSequenceOptions& options)
    : reader_(std::move(root), SequenceOptions{options.labels_dir, options.ignore_labels}) {}

std::optional<Pose> SemanticKittiSequence::velo_to_cam() const {
  if (!reader_.has_calib()) return std::nullopt;
  return reader_.velo_to_cam();
}

std::optional<std::vector<Pose>> SemanticKittiSequence::reference_poses() const {
  if (!reader_.has_poses()) return std::nullopt;
  return reader_.camera_poses();
}

ScanSequenceFacts SemanticKittiSequence::facts() const {
  ScanSequenceFacts f;
  f.notes.push_back(reader_.has_times_file() ? "times: times.txt" : "times: no times.txt, 0.1 s steps assumed");
  f.notes.push_back(reader_.has_calib() ? "calibration: calib.txt (Tr, velodyne to camera 0)"
                                        : "calibration: none (no calib.txt): runs in the LiDAR frame");
  f.notes.push_back(reader_.has_poses() ? (reader_.has_calib() ? "reference: poses.txt (camera frame)"
                                                               : "reference: poses.txt (taken as LiDAR frame)")
                                        : "reference: none (no poses.txt)");
  return f;
}

}  // namespace saloam
