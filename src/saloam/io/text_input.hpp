#pragma once
// Shared checks of the text readers (poses, times, calibration): line
// iteration (a UTF-8 byte-order mark at the start is skipped, '\r' of CRLF
// files dropped), rigid-rotation and increasing-timestamp checks. Every
// error names the file and the line.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <istream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/types.hpp"

namespace saloam {

/// A text file (pose list, timestamps, calibration) may have at most this
/// many bytes: far more than any real one (KITTI 00's poses.txt: 0.6 MB).
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{256} << 20;

/// Calls on_line(line, line_no) for every line (numbered from 1). InputError
/// when the file is missing, not a regular file, larger than
/// kMaxTextFileBytes, or unreadable.
void for_each_text_line(const std::filesystem::path& file,
                        const std::function<void(const std::string& line, std::size_t line_no)>& on_line);
/// The same over an open stream; `file` names it in errors (a read error).
void for_each_text_line(std::istream& in, const std::filesystem::path& file,
                        const std::function<void(const std::string& line, std::size_t line_no)>& on_line);
/// The text of `file` as a stream: InputError when it is missing, not a
/// regular file (a folder, a FIFO, a device), larger than kMaxTextFileBytes
/// or unreadable (`what` names the kind of file in the message). Nothing
/// waits: a FIFO in its place is refused, not read.
std::istringstream open_text_file(const std::filesystem::path& file, std::string_view what = "file");

/// Calls on_line(numbers, line_no) for every line that is neither blank nor
/// a comment ('#' first): its whitespace-separated numbers. InputError (file,
/// line) on a token that is not a number or not finite.
void for_each_number_line(std::istream& in, const std::filesystem::path& file,
                          const std::function<void(const std::vector<double>& numbers, std::size_t line_no)>& on_line);

/// T with its rotation projected back onto SO(3). InputError (file, line)
/// when the rotation is not one: ||R^T R - I|| > kRotationTolerance (a scale
/// or shear, not rounding) or a reflection (det < 0). `what` names the pose
/// in the message, e.g. "rotation" or "rotation of 'Tr'".
Pose checked_rigid_pose(const Pose& T, const std::filesystem::path& file, std::size_t line_no,
                        const std::string& what = "rotation");

/// InputError (file, line) unless `t` is later than `previous` (the
/// timestamp of `previous_line`).
void check_time_increases(double previous, std::size_t previous_line, double t, const std::filesystem::path& file,
                          std::size_t line_no);

}  // namespace saloam
