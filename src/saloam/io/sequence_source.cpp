#include "saloam/io/sequence_source.hpp"

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/imu/imu_stream.hpp"
#include "saloam/io/imu_text.hpp"
#include "saloam/io/trajectory_io.hpp"

namespace saloam {
namespace {

std::optional<std::vector<Pose>> sensor_camera_poses(const SequenceReader& reader) {
  const auto file = reader.root() / "poses_sensor.txt";
  if (!std::filesystem::exists(file)) return std::nullopt;
  std::vector<Pose> poses = read_kitti_poses(file);
  if (poses.size() != reader.size()) {
    throw InputError(file, fmt::format("{} poses for {} scans", poses.size(), reader.size()));
  }
  return poses;
}

std::vector<std::string> notes(const SequenceReader& reader, bool calib) {
  std::vector<std::string> out;
  out.emplace_back(reader.has_times_file() ? "times: times.txt" : "times: no times.txt, 0.1 s steps assumed");
  if (calib) {
    out.emplace_back("calibration: calib.txt (Tr, velodyne to camera 0): poses in KITTI's camera frame");
  } else {
    out.emplace_back(reader.has_calib() ? "calibration: calib.txt ignored (--no-calib): runs in the LiDAR frame"
                                        : "calibration: none (no calib.txt): runs in the LiDAR frame");
  }
  if (!reader.has_poses()) {
    out.emplace_back("reference: none (no poses.txt)");
  } else {
    out.emplace_back(calib ? "reference: poses.txt (camera frame)" : "reference: poses.txt (taken as LiDAR frame)");
  }
  return out;
}

}  // namespace

SequenceFolderSource::SequenceFolderSource(SequenceReader reader, bool read_calib, std::optional<float> intensity_scale)
    : reader_(std::move(reader)), intensity_(sequence_intensity_scale(reader_, intensity_scale)) {
  info_.name = reader_.root().string();
  info_.times = reader_.times();
  info_.has_labels = reader_.has_labels();
  info_.rereadable = true;
  if (read_calib && reader_.has_calib()) info_.velo_to_cam = reader_.velo_to_cam();
  if (reader_.has_poses()) info_.camera_poses = reader_.camera_poses();
  info_.sensor_camera_poses = sensor_camera_poses(reader_);
  info_.folder = reader_.root();
  info_.format = "semantickitti";
  info_.point_fields = "x y z remission";
  info_.notes = notes(reader_, info_.velo_to_cam.has_value());
  info_.notes.push_back(intensity_.note());
  // An IMU beside the scans (imu.txt, in their frame: saloam simulate --imu)
  // is described. Its up at rest is not handed to the run: the rest test
  // (imu_up_at_rest) takes the handheld walk's setting off for rest, 2.6 deg
  // off, where the scans' up is 0.3 deg off (docs/imu.md).
  const std::filesystem::path imu = reader_.root() / "imu.txt";
  if (std::filesystem::exists(imu)) {
    const ImuStreamReport report =
        describe_imu_stream(read_imu_text(imu), "in imu.txt", Eigen::Matrix3d::Identity(), "scans'");
    info_.notes.insert(info_.notes.end(), report.notes.begin(), report.notes.end());
  }
}

IntensityScale sequence_intensity_scale(const SequenceReader& reader, std::optional<float> given) {
  if (given || reader.size() == 0) return unread_intensity_scale(given);
  try {
    return choose_intensity_scale(given, ScalarType::kFloat32, read_scan(reader.scan_file(0)).remission);
  } catch (const InputError&) {
    return unread_intensity_scale(given);  // the run fails on that scan, naming it
  }
}

LabelledCloud SequenceFolderSource::scan(std::size_t i) {
  LabelledCloud cloud = reader_.load_scan(i);
  intensity_.apply(cloud);
  return cloud;
}

}  // namespace saloam
