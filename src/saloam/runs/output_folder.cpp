#include "saloam/runs/output_folder.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/path_rules.hpp"

namespace saloam {
namespace {

constexpr std::size_t kMaxSummaryBytes = 64u << 20;

std::string dump(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + '\n';
}

void write_summary_file(OutputFolder& folder, nlohmann::json summary) {
  std::vector<std::string> files = folder.files();
  if (std::find(files.begin(), files.end(), "summary.json") == files.end()) files.emplace_back("summary.json");
  summary["interrupted"] = stop_requested();
  summary["files"] = files;
  write_file_atomically(folder / "summary.json", dump(summary));
}

}  // namespace

OutputFolder open_run_folder(const std::filesystem::path& out_dir, const std::optional<std::filesystem::path>& sequence,
                             std::string command, const std::vector<std::string>& own_names) {
  std::error_code error;
  if (sequence && comparable_path(out_dir) == comparable_path(*sequence)) {
    throw InputError(out_dir, fmt::format("is the sequence folder {}: the run's poses.txt would overwrite its ground "
                                          "truth; choose another output folder",
                                          sequence->string()));
  }
  if (std::filesystem::is_directory(out_dir / "velodyne", error)) {
    throw InputError(out_dir, "holds a sequence (velodyne/): the run's poses.txt and summary would replace its own; "
                              "choose another output folder");
  }
  return OutputFolder(out_dir, std::move(command), own_names);
}

void write_run_summary(OutputFolder& folder, nlohmann::json summary) {
  write_summary_file(folder, std::move(summary));
  folder.finish(stop_requested() ? "interrupted" : "complete");
}

void update_run_summary(OutputFolder& folder) {
  const std::filesystem::path file = folder / "summary.json";
  nlohmann::json summary = nlohmann::json::parse(read_file(file, kMaxSummaryBytes, "run summary"), nullptr, false);
  if (!summary.is_object()) throw InputError(file, "is not the run's summary (not a JSON object)");
  write_summary_file(folder, std::move(summary));
  folder.finish(stop_requested() ? "interrupted" : "complete");
}

void put_summary_path(nlohmann::json& summary, const std::string& key, const std::filesystem::path& path) {
  const std::string text = path.string();
  summary[key] = text;  // dump() replaces invalid bytes
  if (!is_valid_utf8(text)) summary[key + "_hex"] = to_hex(text);
}

std::optional<std::size_t> recorded_first_frame(const std::filesystem::path& result_file) {
  const std::filesystem::path file = result_file.parent_path() / "summary.json";
  if (!path_taken(file)) return std::nullopt;
  const nlohmann::json summary = nlohmann::json::parse(read_file(file, kMaxSummaryBytes, "run summary"), nullptr, false);
  if (!summary.is_object() || !summary.contains("first_frame") || !summary.contains("files")) return std::nullopt;
  const auto& files = summary["files"];
  const std::string name = result_file.filename().string();
  if (!files.is_array() || std::find(files.begin(), files.end(), name) == files.end()) return std::nullopt;
  const auto& first = summary["first_frame"];
  if (!first.is_number_unsigned() || first.get<std::uint64_t>() > (1ull << 40)) {
    throw InputError(file, "'first_frame' is not a frame number");
  }
  return static_cast<std::size_t>(first.get<std::uint64_t>());
}

std::optional<Pose> output_velo_to_cam(const SourceInfo& source) {
  if (!source.velo_to_cam) {
    spdlog::info("{}: no calibration: pose files hold LiDAR-frame poses, not the KITTI camera convention", source.name);
  }
  return source.velo_to_cam;
}

}  // namespace saloam
