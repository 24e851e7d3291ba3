#include "saloam/core/output_folder.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/path_rules.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

// A record longer than this is not one of ours: it is not read.
constexpr std::size_t kMaxRecordBytes = 16u << 20;
// Temporaries of killed runs are looked for this deep (OUT/slam/x, OUT/sequence/velodyne/x).
constexpr int kPartialSearchDepth = 2;

std::mutex& registry_mutex() {
  static std::mutex mutex;
  return mutex;
}
std::vector<OutputFolder*>& registry() {
  static std::vector<OutputFolder*> folders;
  return folders;
}

// `path` relative to `root` when it lies inside it (both resolved); empty otherwise.
fs::path inside(const fs::path& path, const fs::path& root) {
  const auto [r, p] = std::mismatch(root.begin(), root.end(), path.begin(), path.end());
  if (r != root.end() || p == path.end()) return {};
  fs::path relative;
  for (auto it = p; it != path.end(); ++it) relative /= *it;
  return relative;
}

std::string read_record(int fd) {
  std::string text;
  char buffer[4096];
  for (off_t offset = 0; text.size() < kMaxRecordBytes;) {
    const ssize_t n = ::pread(fd, buffer, sizeof buffer, offset);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
    offset += n;
  }
  return text;
}

// The value of the first "KEY value" line of a record, or "".
std::string record_value(const std::string& record, std::string_view key) {
  std::istringstream lines(record);
  for (std::string line; std::getline(lines, line);) {
    if (line.starts_with(key) && line.size() > key.size() && line[key.size()] == ' ') return line.substr(key.size() + 1);
  }
  return "";
}

// A name a record may list: relative, inside the folder, one line.
bool listable(const fs::path& name) {
  if (name.empty() || name.is_absolute()) return false;
  const std::string text = name.string();
  if (text.find('\n') != std::string::npos || text == std::string(OutputFolder::kRecordName)) return false;
  return std::none_of(name.begin(), name.end(), [](const fs::path& part) { return part == ".." || part == "."; });
}

// "COMMAND, process PID" of the run holding the lock on `fd`. Its record may
// still be the previous run's for a moment after it took the lock: read
// again until it names a live process.
std::string lock_holder(int fd) {
  std::string command, pid;
  for (int attempt = 0; attempt < 20; ++attempt) {
    const std::string record = read_record(fd);
    command = record_value(record, "command");
    pid = record_value(record, "pid");
    const long number = std::strtol(pid.c_str(), nullptr, 10);
    if (number > 0 && ::kill(static_cast<pid_t>(number), 0) == 0) break;
    ::usleep(25000);
  }
  if (command.empty() || pid.empty()) return "a starting run";
  return fmt::format("{}, process {}", command, pid);
}

std::vector<std::string> listed_files(const std::string& record) {
  std::vector<std::string> files;
  std::istringstream lines(record);
  for (std::string line; std::getline(lines, line);) {
    if (line.starts_with("file ") && listable(line.substr(5))) files.push_back(line.substr(5));
  }
  return files;
}

// Removes `file` (a file or a link, never a folder) when it exists.
void remove_output(const fs::path& file) {
  std::error_code ec;
  const auto type = fs::symlink_status(file, ec).type();
  if (type != fs::file_type::regular && type != fs::file_type::symlink) return;
  if (!fs::remove(file, ec) && ec) {
    throw InputError(file, fmt::format("cannot remove this output of an earlier run: {}", ec.message()));
  }
}

void remove_partials(const fs::path& dir) {
  std::error_code ec;
  fs::recursive_directory_iterator it(dir, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    if (it.depth() >= kPartialSearchDepth) it.disable_recursion_pending();
    if (is_partial_output_name(it->path().filename().string())) remove_output(it->path());
  }
}

}  // namespace

OutputFolder::OutputFolder(fs::path dir, std::string command, const std::vector<std::string>& own_names)
    : OutputFolder(std::move(dir), std::move(command), own_names, Mode::kNewRun) {}

OutputFolder OutputFolder::join(fs::path dir, std::string command) {
  return OutputFolder(std::move(dir), std::move(command), {}, Mode::kJoin);
}

OutputFolder::OutputFolder(fs::path dir, std::string command, const std::vector<std::string>& own_names, Mode mode)
    : dir_(std::move(dir)), command_(std::move(command)), joined_(mode == Mode::kJoin) {
  create_folder(dir_);
  absolute_ = comparable_path(dir_);  // links resolved, as the path rule compares
  lock(mode);
  if (mode == Mode::kNewRun) {
    std::vector<std::string> earlier = listed_files(read_record(fd_));
    earlier.insert(earlier.end(), own_names.begin(), own_names.end());
    try {
      for (const auto& name : earlier) remove_output(dir_ / name);
      remove_partials(dir_);
    } catch (...) {
      ::close(fd_);
      throw;
    }
    start_record();
  }
  const std::lock_guard lock(registry_mutex());
  registry().push_back(this);
}

void OutputFolder::lock(Mode mode) {
  const fs::path record = dir_ / kRecordName;
  fd_ = ::open(record.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0666);
  if (fd_ < 0) throw InputError(dir_, fmt::format("cannot write in this folder: {}", std::strerror(errno)));
  if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) {
    offset_ = static_cast<std::size_t>(std::max<off_t>(::lseek(fd_, 0, SEEK_END), 0));
    return;
  }
  const std::string holder = lock_holder(fd_);
  ::close(fd_);
  fd_ = -1;
  throw InputError(dir_, fmt::format("another saloam run ({}) is writing this folder; wait for it to end or {} "
                                     "another folder",
                                     holder, mode == Mode::kJoin ? "write to" : "choose"));
}

// The record of the previous run is replaced by this run's header in one write.
void OutputFolder::start_record() {
  const std::string header = fmt::format("saloam-run 1\ncommand {}\npid {}\n", command_, ::getpid());
  if (::pwrite(fd_, header.data(), header.size(), 0) != static_cast<ssize_t>(header.size()) ||
      ::ftruncate(fd_, static_cast<off_t>(header.size())) != 0) {
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    throw InputError(dir_ / kRecordName, fmt::format("cannot start the run's record: {}", std::strerror(error)));
  }
  offset_ = header.size();
}

OutputFolder::~OutputFolder() {
  {
    const std::lock_guard lock(registry_mutex());
    std::erase(registry(), this);
  }
  if (fd_ < 0) return;
  if (!finished_ && !joined_) {
    try {
      append("end failed\n");
    } catch (...) {  // a destructor does not throw; the record then ends without a state
    }
  }
  ::close(fd_);  // releases the lock
}

std::vector<std::string> OutputFolder::files() const {
  const std::lock_guard lock(mutex_);
  return files_;
}

bool OutputFolder::wrote(std::string_view name) const {
  const std::lock_guard lock(mutex_);
  return std::find(files_.begin(), files_.end(), name) != files_.end();
}

void OutputFolder::finish(std::string_view state) {
  append(fmt::format("end {}\n", state));
  finished_ = true;
}

void OutputFolder::append(const std::string& line) {
  std::string_view rest = line;
  while (!rest.empty()) {
    const ssize_t n = ::pwrite(fd_, rest.data(), rest.size(), static_cast<off_t>(offset_));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw InputError(dir_ / kRecordName,
                       fmt::format("cannot write the run's record: {}", n < 0 ? std::strerror(errno) : "short write"));
    }
    rest.remove_prefix(static_cast<std::size_t>(n));
    offset_ += static_cast<std::size_t>(n);
  }
}

void record_output(const fs::path& file) {
  const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  const fs::path path = comparable_path(folder) / file.filename();
  const std::lock_guard lock(registry_mutex());
  OutputFolder* holder = nullptr;  // the innermost folder: a run inside another run's folder keeps its own record
  fs::path name;
  for (OutputFolder* folder : registry()) {
    const fs::path relative = inside(path, folder->absolute_);
    if (!listable(relative)) continue;
    if (holder && std::distance(relative.begin(), relative.end()) >= std::distance(name.begin(), name.end())) continue;
    holder = folder;
    name = relative;
  }
  if (!holder) return;
  const std::lock_guard files_lock(holder->mutex_);
  if (std::find(holder->files_.begin(), holder->files_.end(), name.string()) != holder->files_.end()) return;
  holder->files_.push_back(name.string());
  holder->append(fmt::format("file {}\n", name.string()));
}

namespace {
std::string record_in(const fs::path& dir) {
  const int fd = ::open((dir / OutputFolder::kRecordName).c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOFOLLOW);
  if (fd < 0) return "";
  const std::string record = read_record(fd);
  ::close(fd);
  return record;
}
}  // namespace

std::vector<std::string> recorded_outputs(const fs::path& dir) { return listed_files(record_in(dir)); }

std::string recorded_command(const fs::path& dir) { return record_value(record_in(dir), "command"); }

}  // namespace saloam
