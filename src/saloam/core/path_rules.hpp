#pragma once
// The one rule for a command's paths (issue #39): an output never equals,
// contains or lies inside an input, and nothing another path names lies
// inside an output that the run replaces whole. Every command lists its
// inputs and outputs in a PathRules and calls check() before it reads or
// writes anything; a breach is an InputError naming the output, its option,
// the other path and its option.
//
// Paths are compared absolute and resolved component by component as a run
// that creates the missing folders would reach them (every link followed,
// also after a missing folder and `..`; `.` and `..` removed), then by
// components: /a/bc is not inside /a/b. Two existing paths that are one
// file (a hard link) are equal, and a path through a bind mount of a folder
// lies in that folder (an existing folder along it is the folder: device
// and inode).

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace saloam {

/// How a run writes an output path.
enum class OutputUse {
  kFile,            ///< one file, replaced atomically
  kFolder,          ///< a folder the run adds its own files to (its other files stay)
  kReplacedFolder,  ///< a folder the run replaces whole (a saved map, a simulated sequence)
};

/// Whether `inner` is `outer` or lies inside it, by path components (both
/// as given: use comparable_path() first).
bool path_within(const std::filesystem::path& inner, const std::filesystem::path& outer);

/// `path` absolute, `..` and `.` resolved and every link followed, component by component (see above), without a
/// trailing separator.
std::filesystem::path comparable_path(const std::filesystem::path& path);

class PathRules {
 public:
  /// An input (a file or folder read); an empty path is ignored.
  PathRules& input(std::string_view option, const std::filesystem::path& path);
  /// An output; an empty path is ignored.
  PathRules& output(std::string_view option, const std::filesystem::path& path, OutputUse use = OutputUse::kFile);
  /// InputError (naming both paths and their options) at the first breach.
  void check() const;

 private:
  struct Entry {
    std::string option;
    std::filesystem::path given, path;
    OutputUse use = OutputUse::kFile;
  };
  std::vector<Entry> inputs_, outputs_;
};

}  // namespace saloam
