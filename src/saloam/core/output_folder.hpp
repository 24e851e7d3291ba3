#pragma once
// One run per output folder. The run that writes a folder holds an
// OutputFolder for as long as it writes there:
//  * a lock: flock() on DIR/.saloam-run, held while the object lives and
//    dropped by the kernel when the process ends, however it ends. A second
//    run on the same folder stops at once with an InputError naming the
//    folder and the run that holds it.
//  * a record: DIR/.saloam-run names the command and the process, lists
//    every file the run put in place (AtomicFile::commit records them, line
//    by line, so a crash leaves an accurate list) and how the run ended
//    ("complete", "interrupted", "failed"; nothing after a crash).
//  * a clean start: before this run writes, the files the previous record
//    lists, the temporaries of a killed run (NAME.partial-PID.N) and the
//    names this command writes (for folders of earlier versions without a
//    record) are removed, so that the folder never holds an older run's map,
//    page or summary beside this run's results.

#include <filesystem>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace saloam {

class OutputFolder {
 public:
  /// Creates `dir`, takes its lock and removes an earlier run's outputs (see
  /// above; `own_names` relative to `dir`). InputError when the folder cannot
  /// be created or written, or another run holds it.
  OutputFolder(std::filesystem::path dir, std::string command, const std::vector<std::string>& own_names = {});
  /// Takes the lock of an existing folder without clearing it or starting a
  /// new record: a command that adds a file to a finished run's folder
  /// (`view` writing the page). The files it writes are added to the record.
  static OutputFolder join(std::filesystem::path dir, std::string command);
  /// Releases the lock; a run that did not call finish() is recorded as failed.
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return dir_; }
  [[nodiscard]] std::filesystem::path operator/(std::string_view name) const { return dir_ / name; }
  /// The files this run has put in place so far, relative to the folder, in order.
  [[nodiscard]] std::vector<std::string> files() const;
  [[nodiscard]] bool wrote(std::string_view name) const;
  /// Records how the run ended: "complete" or "interrupted".
  void finish(std::string_view state);

  /// The record's file name inside an output folder.
  static constexpr std::string_view kRecordName = ".saloam-run";

 private:
  enum class Mode { kNewRun, kJoin };
  OutputFolder(std::filesystem::path dir, std::string command, const std::vector<std::string>& own_names, Mode mode);
  void lock(Mode mode);
  void start_record();
  void append(const std::string& line);
  friend void record_output(const std::filesystem::path& file);

  std::filesystem::path dir_, absolute_;
  std::string command_;
  bool joined_ = false;
  int fd_ = -1;
  std::size_t offset_ = 0;  ///< where the record's next line goes
  bool finished_ = false;
  mutable std::mutex mutex_;
  std::vector<std::string> files_;
};

/// Called by AtomicFile::commit(): adds `file` to the record of the innermost
/// live OutputFolder that holds it (a run writing inside another run's
/// folder, e.g. the demo's kept sequence, keeps a record of its own).
void record_output(const std::filesystem::path& file);

/// The files that the record in `dir` lists, relative to `dir` (none without a record).
std::vector<std::string> recorded_outputs(const std::filesystem::path& dir);
/// The command of the run recorded in `dir` ("" without a record).
std::string recorded_command(const std::filesystem::path& dir);

}  // namespace saloam
