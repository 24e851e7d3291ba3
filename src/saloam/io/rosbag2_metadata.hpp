#pragma once
// A rosbag2 folder's metadata.yaml: which files hold the messages and in
// what storage, and what the recording holds. Written as rosbag2 (Humble,
// version 5) writes it:
//   rosbag2_bagfile_information:
//     version: 5
//     storage_identifier: sqlite3 | mcap
//     duration: {nanoseconds: N}
//     starting_time: {nanoseconds_since_epoch: N}
//     message_count: N
//     topics_with_message_count:
//       - topic_metadata: {name, type, serialization_format: cdr, offered_qos_profiles: ""}
//         message_count: N
//     compression_format: ""
//     compression_mode: ""
//     relative_file_paths: [NAME_0.db3]
//     files: [{path, starting_time, duration, message_count}]
// Read: storage_identifier, relative_file_paths and the compression; a bag
// compressed by rosbag2 (file or message mode) is an InputError saying so.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "saloam/io/message_storage.hpp"

namespace saloam {

struct Rosbag2Metadata {
  std::string storage;  ///< "sqlite3" or "mcap"
  std::vector<std::filesystem::path> files;  ///< in the folder, in recording order
};

/// The metadata.yaml of `folder`. InputError naming the file when it is not
/// rosbag2 metadata, names an unknown storage, a compressed bag, or no file.
Rosbag2Metadata read_rosbag2_metadata(const std::filesystem::path& folder);

struct Rosbag2FileSummary {
  std::string name;  ///< relative to the folder
  std::int64_t start_ns = 0, end_ns = 0;
  std::size_t messages = 0;
};

/// The metadata.yaml text for one file of `storage` holding `topics`.
std::string rosbag2_metadata_text(const std::string& storage, const std::vector<StoredTopic>& topics,
                                  const Rosbag2FileSummary& file);

}  // namespace saloam
