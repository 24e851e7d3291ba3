#pragma once
// A progress bar for long runs on stderr: redrawn in place on a terminal,
// a line every 10 % otherwise (CI logs), with rate and time left. Progress
// is information: with the log level above info (`saloam -q`) nothing is drawn.

#include <chrono>
#include <cstddef>
#include <string>

namespace saloam {

class ProgressBar {
 public:
  ProgressBar(std::size_t total, std::string label, bool enabled = true);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// Marks `n` more items done; thread-compatible (call from one thread).
  void advance(std::size_t n = 1);
  /// Extra text shown after the bar (e.g. current error).
  void set_status(std::string status) { status_ = std::move(status); }
  void finish();

 private:
  void draw(bool final_line);

  std::size_t total_;
  std::size_t done_ = 0;
  std::string label_;
  std::string status_;
  bool enabled_;
  bool tty_;
  bool finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace saloam
