#include "saloam/io/rosbag2_metadata.hpp"

#include <algorithm>
#include <sstream>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/yaml_documents.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

std::string scalar(const YAML::Node& node, const char* key) {
  const YAML::Node value = node[key];
  return value && value.IsScalar() ? value.as<std::string>() : std::string();
}

/// Files of the listed names, which must stay inside the folder.
std::vector<fs::path> listed_files(const YAML::Node& info, const fs::path& folder, const fs::path& yaml) {
  std::vector<fs::path> files;
  const YAML::Node paths = info["relative_file_paths"];
  if (!paths || !paths.IsSequence()) return files;
  for (const auto& p : paths) {
    const std::string name = p.IsScalar() ? p.as<std::string>() : std::string();
    const fs::path relative(name);
    if (name.empty() || relative.is_absolute() || std::any_of(relative.begin(), relative.end(), [](const fs::path& part) { return part == ".."; })) {
      throw InputError(yaml, fmt::format("relative_file_paths: '{}' is not a file name inside the bag", name.substr(0, 80)));
    }
    files.push_back(folder / relative.filename());
  }
  return files;
}

/// The folder's files of `extension` by name, when metadata.yaml lists none.
std::vector<fs::path> files_by_extension(const fs::path& folder, const std::string& extension) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() == extension) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

Rosbag2Metadata read_rosbag2_metadata(const fs::path& folder) {
  const fs::path yaml = folder / "metadata.yaml";
  const YamlDocument document = load_yaml_document(read_file(yaml, 1u << 24, "rosbag2 metadata"), "rosbag2 metadata");
  if (!document.problem.empty()) throw InputError(yaml, document.problem);
  const YAML::Node info = document.root.IsMap() ? document.root["rosbag2_bagfile_information"] : YAML::Node();
  if (!info || !info.IsMap()) throw InputError(yaml, "not rosbag2 metadata (no 'rosbag2_bagfile_information' map)");
  Rosbag2Metadata out;
  out.storage = scalar(info, "storage_identifier");
  if (out.storage.empty()) out.storage = "sqlite3";
  if (out.storage != "sqlite3" && out.storage != "mcap") {
    throw InputError(yaml, fmt::format("storage '{}': saloam reads sqlite3 and mcap bags", out.storage.substr(0, 40)));
  }
  const std::string compression = scalar(info, "compression_format");
  if (!compression.empty()) {
    throw InputError(yaml, fmt::format("compressed by rosbag2 ({}, {} mode): decompress it first (ros2 bag convert)",
                                       compression.substr(0, 20), scalar(info, "compression_mode").substr(0, 20)));
  }
  out.files = listed_files(info, folder, yaml);
  if (out.files.empty()) out.files = files_by_extension(folder, out.storage == "mcap" ? ".mcap" : ".db3");
  if (out.files.empty()) throw InputError(yaml, fmt::format("names no {} file, and the folder holds none", out.storage));
  return out;
}

std::string rosbag2_metadata_text(const std::string& storage, const std::vector<StoredTopic>& topics,
                                  const Rosbag2FileSummary& file) {
  std::ostringstream out;
  const std::int64_t duration = file.end_ns - file.start_ns;
  out << "rosbag2_bagfile_information:\n  version: 5\n"
      << fmt::format("  storage_identifier: {}\n", storage)
      << fmt::format("  duration:\n    nanoseconds: {}\n", duration)
      << fmt::format("  starting_time:\n    nanoseconds_since_epoch: {}\n", file.start_ns)
      << fmt::format("  message_count: {}\n", file.messages) << "  topics_with_message_count:\n";
  for (const auto& t : topics) {
    out << fmt::format("    - topic_metadata:\n        name: {}\n        type: {}\n        serialization_format: {}\n"
                       "        offered_qos_profiles: \"\"\n      message_count: {}\n",
                       t.name, t.type, t.encoding, t.messages);
  }
  out << "  compression_format: \"\"\n  compression_mode: \"\"\n"
      << fmt::format("  relative_file_paths:\n    - {}\n", file.name)
      << fmt::format("  files:\n    - path: {}\n      starting_time:\n        nanoseconds_since_epoch: {}\n"
                     "      duration:\n        nanoseconds: {}\n      message_count: {}\n",
                     file.name, file.start_ns, duration, file.messages);
  return out.str();
}

}  // namespace saloam
