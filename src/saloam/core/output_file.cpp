#include "saloam/core/output_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <streambuf>
#include <string>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_folder.hpp"

namespace saloam {
namespace {

constexpr std::string_view kPartialMarker = ".partial-";

// A stream buffer writing to a file descriptor. The first failed write is
// kept (its errno); from then on overflow() and sync() fail, so the stream
// turns bad and nothing more is written.
class FdBuffer : public std::streambuf {
 public:
  explicit FdBuffer(int fd) : fd_(fd) { setp(buffer_.data(), buffer_.data() + buffer_.size()); }

  [[nodiscard]] int error() const { return error_; }
  [[nodiscard]] int fd() const { return fd_; }
  void release() { fd_ = -1; }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    *pptr() = traits_type::to_char_type(c);
    pbump(1);
    return c;
  }

  std::streamsize xsputn(const char* data, std::streamsize n) override {
    if (n < static_cast<std::streamsize>(buffer_.size())) return std::streambuf::xsputn(data, n);
    if (!drain() || !write_all(data, static_cast<std::size_t>(n))) return 0;  // large blocks bypass the buffer
    return n;
  }

  int sync() override { return drain() ? 0 : -1; }

 private:
  bool drain() {
    const auto n = static_cast<std::size_t>(pptr() - pbase());
    const bool ok = write_all(pbase(), n);
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return ok;
  }

  bool write_all(const char* data, std::size_t n) {
    if (error_ != 0 || fd_ < 0) return error_ == 0 && n == 0;
    while (n > 0) {
      const ssize_t written = ::write(fd_, data, n);
      if (written < 0 && errno == EINTR) continue;
      if (written <= 0) {
        error_ = written < 0 ? errno : EIO;
        return false;
      }
      data += written;
      n -= static_cast<std::size_t>(written);
    }
    return true;
  }

  int fd_;
  int error_ = 0;
  std::array<char, 1 << 16> buffer_{};
};

std::string reason(int error) { return error == ENOSPC ? "no space left on the device" : std::strerror(error); }

std::filesystem::path temporary_name(const std::filesystem::path& file) {
  static std::atomic<unsigned> counter{0};
  auto name = file;
  name += fmt::format("{}{}.{}", kPartialMarker, ::getpid(), counter++);
  return name;
}

}  // namespace

struct CheckedFileStream::Impl {
  Impl(int fd, std::filesystem::path file) : buffer(fd), stream(&buffer), name(std::move(file)) {}
  FdBuffer buffer;
  std::ostream stream;
  std::filesystem::path name;

  void check() const {
    if (buffer.error() != 0) throw InputError(name, "cannot write: " + reason(buffer.error()));
  }
};

CheckedFileStream::CheckedFileStream(int fd, std::filesystem::path name)
    : impl_(std::make_unique<Impl>(fd, std::move(name))) {}

CheckedFileStream::~CheckedFileStream() {
  if (impl_->buffer.fd() >= 0) ::close(impl_->buffer.fd());
}

std::ostream& CheckedFileStream::stream() { return impl_->stream; }

void CheckedFileStream::flush() {
  impl_->stream.flush();
  impl_->check();
}

void CheckedFileStream::close() {
  flush();
  const int fd = impl_->buffer.fd();
  impl_->buffer.release();
  if (fd >= 0 && ::close(fd) != 0 && errno != EINTR) {
    throw InputError(impl_->name, "cannot write: " + reason(errno));
  }
}

AtomicFile::AtomicFile(std::filesystem::path file) : file_(std::move(file)), temporary_(temporary_name(file_)) {
  create_parent_folder(file_);
  const int fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw InputError(file_, "cannot create: " + reason(errno));
  out_ = std::make_unique<CheckedFileStream>(fd, file_);
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.reset();
  std::error_code ignored;
  std::filesystem::remove(temporary_, ignored);
}

std::ostream& AtomicFile::stream() { return out_->stream(); }

void AtomicFile::flush() { out_->flush(); }

void AtomicFile::commit() {
  if (committed_) return;
  try {
    out_->close();
    if (::rename(temporary_.c_str(), file_.c_str()) != 0) {
      throw InputError(file_, "cannot put the finished file in place: " + reason(errno));
    }
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary_, ignored);
    throw;
  }
  committed_ = true;
  record_output(file_);
}

GrowingFile::GrowingFile(std::filesystem::path file) : file_(std::move(file)) {
  create_parent_folder(file_);
  const int fd = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw InputError(file_, "cannot create: " + reason(errno));
  out_ = std::make_unique<CheckedFileStream>(fd, file_);
}

std::ostream& GrowingFile::stream() { return out_->stream(); }

void GrowingFile::flush() { out_->flush(); }

void GrowingFile::commit() {
  if (committed_) return;
  out_->close();
  committed_ = true;
  record_output(file_);
}

void write_file_atomically(const std::filesystem::path& file, std::string_view bytes) {
  AtomicFile out(file);
  out.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.commit();
}

bool is_partial_output_name(std::string_view name) {
  const auto at = name.rfind(kPartialMarker);
  if (at == std::string_view::npos || at == 0) return false;
  const std::string_view tail = name.substr(at + kPartialMarker.size());
  const auto dot = tail.find('.');
  const auto digits = [](std::string_view s) {
    return !s.empty() && s.find_first_not_of("0123456789") == std::string_view::npos;
  };
  return dot != std::string_view::npos && digits(tail.substr(0, dot)) && digits(tail.substr(dot + 1));
}

}  // namespace saloam
