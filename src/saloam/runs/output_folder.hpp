#pragma once
// The output folder of a run over a sequence: held by the run while it
// writes (core/output_folder.hpp: one run at a time, cleared of an earlier
// run's outputs, every file recorded), never the sequence folder itself nor
// any folder that holds a sequence, and ended by summary.json, which says
// what the run wrote and whether it was interrupted.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "saloam/core/output_folder.hpp"
#include "saloam/core/types.hpp"
#include "saloam/io/frame_source.hpp"

namespace saloam {

/// Opens `out_dir` for a run of `command` that may write `own_names`.
/// InputError when it is the run's sequence folder `sequence` (when the
/// frames come from one) or holds a sequence (velodyne/): the run's pose files
/// and summary would replace its ground truth. Checked before anything in
/// the folder is touched.
OutputFolder open_run_folder(const std::filesystem::path& out_dir, const std::optional<std::filesystem::path>& sequence,
                             std::string command, const std::vector<std::string>& own_names);

/// Writes `folder`/summary.json, the run's last file: `summary` with
/// "interrupted" (whether a stop was asked for at any time of the run) and
/// "files" (every file the run has put in place, summary.json included).
/// Records the run's end in the folder. Writing it again later (after a file
/// added by the command, e.g. the page) keeps it true.
void write_run_summary(OutputFolder& folder, nlohmann::json summary);
/// Rewrites summary.json with the files written since (InputError when there is none).
void update_run_summary(OutputFolder& folder);

/// The sequence frame of the first pose in `result_file`: "first_frame" of
/// the summary.json beside it when that summary lists the file among the
/// run's; none for a file no run summary claims (e.g. a sequence's poses.txt).
/// Records `path` under `key` in a run summary: as text, and when the path is
/// not valid UTF-8 (JSON text must be) the text with U+FFFD for the bad
/// bytes, readable, plus its exact bytes in hex under KEY_hex, which readers
/// prefer (summary.json never fails over a path, and names the right folder).
void put_summary_path(nlohmann::json& summary, const std::string& key, const std::filesystem::path& path);

std::optional<std::size_t> recorded_first_frame(const std::filesystem::path& result_file);

/// The velodyne-to-camera Tr for a run's KITTI pose files: the source's, so
/// that poses.txt compares with the ground truth. A source without one (a
/// folder opened with --no-calib) gives none: the pose files then hold
/// LiDAR-frame poses, which the log says.
std::optional<Pose> output_velo_to_cam(const SourceInfo& source);

}  // namespace saloam
