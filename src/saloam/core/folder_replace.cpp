#include "saloam/core/folder_replace.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

#ifndef RENAME_EXCHANGE
constexpr unsigned kRenameExchange = 1U << 1;  // linux/fs.h
#else
constexpr unsigned kRenameExchange = RENAME_EXCHANGE;
#endif

std::function<void(std::string_view)>& test_hook() {
  static std::function<void(std::string_view)> hook;
  return hook;
}
bool& use_exchange_flag() {
  static bool use = true;
  return use;
}

constexpr std::string_view kPartial = ".partial-";
constexpr std::string_view kPrevious = ".previous-";

// The writer's process id in "TARGET<marker>PID.N", when `name` is such a name.
std::optional<long> writer_of(const std::string& name, const std::string& prefix) {
  if (!name.starts_with(prefix)) return std::nullopt;
  const std::string tail = name.substr(prefix.size());
  const auto dot = tail.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == tail.size()) return std::nullopt;
  if (tail.find_first_not_of("0123456789.") != std::string::npos) return std::nullopt;
  return std::strtol(tail.substr(0, dot).c_str(), nullptr, 10);
}

bool process_gone(long pid) { return pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH; }

struct Leftover {
  fs::path path;
  bool previous = false;  ///< the old folder moved aside (else a temporary)
};

std::vector<Leftover> leftovers(const fs::path& target) {
  std::vector<Leftover> found;
  const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const std::string name = target.filename().string();
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    std::error_code type_error;
    if (!it->is_directory(type_error) || it->is_symlink(type_error)) continue;
    for (const auto& [marker, previous] : {std::pair{kPartial, false}, std::pair{kPrevious, true}}) {
      const auto pid = writer_of(entry, name + std::string(marker));
      if (pid && process_gone(*pid)) found.push_back({it->path(), previous});
    }
  }
  return found;
}

}  // namespace

fs::path partial_folder_name(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  return target.string() + fmt::format("{}{}.{}", kPartial, static_cast<long>(::getpid()), counter.fetch_add(1));
}

void set_folder_replace_test_hooks(std::function<void(std::string_view)> hook, bool use_exchange) {
  test_hook() = std::move(hook);
  use_exchange_flag() = use_exchange;
}

void folder_replace_step(std::string_view step) {
  if (test_hook()) test_hook()(step);
}

std::vector<fs::path> folder_leftovers(const fs::path& target) {
  std::vector<fs::path> paths;
  for (const Leftover& l : leftovers(target)) paths.push_back(l.path);
  return paths;
}

bool recover_folder(const fs::path& target, const FolderCheck& complete) {
  std::vector<Leftover> found = leftovers(target);
  // Puts the first complete leftover of the kind into the missing target's place.
  const auto put_back = [&](bool previous, std::string_view before, std::string_view after) {
    if (path_taken(target)) return false;
    for (const Leftover& l : found) {
      if (l.previous != previous || !path_taken(l.path) || !complete(l.path)) continue;
      std::error_code ec;
      fs::rename(l.path, target, ec);
      if (ec) continue;
      spdlog::warn("{}: {} {}{}", target.string(), before, l.path.string(), after);
      return true;
    }
    return false;
  };
  bool recovered = put_back(true, "put back from", ", where a replacement killed before it ended had left it");
  // No previous folder: a complete new one is kept rather than removed.
  recovered = put_back(false, "put in place from", ", complete, whose writer was killed before it ended") || recovered;
  const bool missing = !path_taken(target);
  for (const Leftover& l : found) {
    if (!path_taken(l.path)) continue;
    if (missing && complete(l.path)) {
      spdlog::warn("{}: missing; {} is a complete copy left by a killed writer (kept)", target.string(), l.path.string());
      continue;
    }
    std::error_code ec;
    fs::remove_all(l.path, ec);
    spdlog::warn("{}: removed {}, {} of a writer that was killed{}", target.string(), l.path.string(),
                 l.previous ? "the folder it replaced" : "the temporary folder (part-written, or the replaced folder)",
                 ec ? fmt::format(" (not all of it: {})", ec.message()) : "");
  }
  return recovered;
}

void replace_folder(const fs::path& target, const fs::path& temporary) {
  std::error_code ec;
  if (!path_taken(target)) {
    fs::rename(temporary, target, ec);
    if (ec) throw InputError(target, fmt::format("cannot put the new folder in place: {}", ec.message()));
    folder_replace_step("renamed");
    return;
  }
  if (use_exchange_flag() &&
      ::syscall(SYS_renameat2, AT_FDCWD, temporary.c_str(), AT_FDCWD, target.c_str(), kRenameExchange) == 0) {
    folder_replace_step("exchanged");
    fs::remove_all(temporary, ec);  // the old folder, now under the temporary name
    if (ec) spdlog::warn("{}: the replaced folder stays at {}: {}", target.string(), temporary.string(), ec.message());
    folder_replace_step("removed");
    return;
  }
  // No exchange here (EINVAL: a file system without it; ENOSYS: an old kernel): two renames.
  std::string previous = temporary.string();
  previous.replace(previous.rfind(kPartial), kPartial.size(), kPrevious);
  fs::rename(target, previous, ec);
  if (ec) throw InputError(target, fmt::format("cannot move the earlier folder aside: {}", ec.message()));
  folder_replace_step("moved aside");
  fs::rename(temporary, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::rename(previous, target, ignored);
    throw InputError(target, fmt::format("cannot put the new folder in place: {}", ec.message()));
  }
  folder_replace_step("renamed");
  fs::remove_all(previous, ec);
  if (ec) spdlog::warn("{}: the replaced folder stays at {}: {}", target.string(), previous, ec.message());
  folder_replace_step("removed");
}

}  // namespace saloam
