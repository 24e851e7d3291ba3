#pragma once
// Output files that are either complete or absent. A result is written under
// a temporary name beside its final one ("NAME.partial-PID.N") and renamed
// into place only when every byte is written and the file is closed without
// error: a reader (or the user, after a crash or a full disk) never finds a
// half-written file under the final name, and an earlier file of that name
// stays as it was until the rename. Every write and the close are checked;
// the first failure (ENOSPC, EIO, ...) is kept and reported as an InputError
// naming the final file and the system's reason.
//
// Files are not fsync'ed: the rename makes them atomic for readers and
// against failures of the run; durability across a power cut is not promised.

#include <filesystem>
#include <memory>
#include <ostream>
#include <string_view>

namespace saloam {

/// A buffered output stream over an open file descriptor (taken over) that
/// checks every write. After the first failure later writes are dropped and
/// the stream is bad; flush() and close() then throw an InputError naming
/// `name` with the failure's reason.
class CheckedFileStream {
 public:
  CheckedFileStream(int fd, std::filesystem::path name);
  ~CheckedFileStream();  ///< closes the descriptor if close() was not called (errors ignored)
  CheckedFileStream(const CheckedFileStream&) = delete;
  CheckedFileStream& operator=(const CheckedFileStream&) = delete;

  std::ostream& stream();
  /// Writes the buffered bytes now; InputError when any write failed.
  void flush();
  /// Flushes and closes; InputError when a write or the close failed.
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A file a run writes as it goes: AtomicFile (in place once complete) or
/// GrowingFile (in place from the start, for a reader that follows it).
class OutputFile {
 public:
  virtual ~OutputFile() = default;
  virtual std::ostream& stream() = 0;
  /// Writes what is buffered into the file; InputError on a failed write.
  virtual void flush() = 0;
  /// The file finished: closed, in place and recorded with the output
  /// folder that holds it (output_folder.hpp); InputError naming it on any failure.
  virtual void commit() = 0;
};

/// A file written under a temporary name and renamed into place by commit().
/// Destroyed without commit() (an exception, a failed run), the temporary is
/// removed and the final name is untouched.
class AtomicFile final : public OutputFile {
 public:
  /// Creates the parent folder and the temporary file; InputError naming
  /// `file` when either cannot be created.
  explicit AtomicFile(std::filesystem::path file);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() override;
  /// Writes what is buffered into the temporary file (a file written as a run
  /// goes, e.g. pose lines, so that a crash leaves them under the temporary
  /// name); InputError on a failed write.
  void flush() override;
  /// Flushes, closes and renames the temporary file to the final name;
  /// InputError naming the final file on any failure (the temporary is then
  /// removed). Records the file with the output folder that holds it
  /// (output_folder.hpp).
  void commit() override;

  [[nodiscard]] const std::filesystem::path& file() const { return file_; }
  [[nodiscard]] const std::filesystem::path& temporary() const { return temporary_; }
  [[nodiscard]] bool committed() const { return committed_; }

 private:
  std::filesystem::path file_, temporary_;
  std::unique_ptr<CheckedFileStream> out_;
  bool committed_ = false;
};

/// A file written under its final name from the start, each flush() putting
/// the lines written so far there: what another process can follow as it
/// grows (a live run's poses, `tail -f`). Unlike AtomicFile it is not
/// removed when the run fails: a live run's frames cannot be read again, so
/// what it made is kept. Replaces an earlier file of that name.
class GrowingFile final : public OutputFile {
 public:
  /// Creates (or empties) `file` and its parent folder; InputError naming it when it cannot.
  explicit GrowingFile(std::filesystem::path file);
  std::ostream& stream() override;
  void flush() override;
  void commit() override;

 private:
  std::filesystem::path file_;
  std::unique_ptr<CheckedFileStream> out_;
  bool committed_ = false;
};

/// `bytes` written to `file` through an AtomicFile.
void write_file_atomically(const std::filesystem::path& file, std::string_view bytes);

/// Whether `name` is the name of an AtomicFile's temporary file ("X.partial-PID.N").
bool is_partial_output_name(std::string_view name);

}  // namespace saloam
