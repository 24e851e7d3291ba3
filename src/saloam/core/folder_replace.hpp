#pragma once
// Crash-safe replacement of a folder (a saved map): the new folder is
// written whole beside the old one under a temporary name, then put in place
// in one atomic step, so that after a kill at any moment either the old or
// the new folder is whole under the final name (issue #39).
//
//  * Writing: TARGET.partial-PID.N (the writer's process id, a counter).
//  * Putting in place, where the file system can (Linux renameat2 with
//    RENAME_EXCHANGE: ext4, xfs, btrfs, tmpfs): the two folders are
//    exchanged in one step, and the old one, now under the temporary name,
//    is removed. Without an existing TARGET it is one rename.
//  * Elsewhere: TARGET is renamed to TARGET.previous-PID.N, the new folder
//    to TARGET, and the previous one removed. A kill between the two renames
//    leaves no TARGET but the whole old folder under the previous name.
//
// Leftovers of a killed writer (its process gone) are recovered by the next
// writer, and by a reader that finds no TARGET (recover_folder()): when
// TARGET is missing, the whole previous folder goes back in place; every
// other leftover is removed with a warning that names it. Nothing is
// deleted without a message, and a complete folder is never deleted while
// TARGET is missing.

#include <filesystem>
#include <functional>
#include <string_view>

namespace saloam {

/// Whether a folder holds a complete copy (e.g. a saved map with its manifest).
using FolderCheck = std::function<bool(const std::filesystem::path&)>;

/// A fresh temporary name beside `target` ("TARGET.partial-PID.N").
std::filesystem::path partial_folder_name(const std::filesystem::path& target);

/// Puts the complete folder `temporary` (beside `target`, same file system)
/// in the place of `target` (see above). InputError naming `target` when a
/// rename fails; the old folder then stays in place.
void replace_folder(const std::filesystem::path& target, const std::filesystem::path& temporary);

/// Tidies the leftovers of killed writers of `target` (see above); returns
/// true when it put a previous folder back in place. `complete` tells a whole
/// folder from a part-written one.
bool recover_folder(const std::filesystem::path& target, const FolderCheck& complete);

/// The leftovers of killed writers beside `target` (temporary and previous
/// folders whose writer is gone), for messages.
std::vector<std::filesystem::path> folder_leftovers(const std::filesystem::path& target);

/// For tests: `hook` is called with the name of each step of a replacement
/// ("exchanged", "moved aside", "renamed", "removed"; writers of a folder
/// call it between their files too), so that a test can kill the writer
/// there; `use_exchange` false takes the path without RENAME_EXCHANGE.
void set_folder_replace_test_hooks(std::function<void(std::string_view step)> hook, bool use_exchange = true);
/// Calls the test hook (nothing without one).
void folder_replace_step(std::string_view step);

}  // namespace saloam
