#include "saloam/io/text_input.hpp"

#include <string_view>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"

namespace saloam {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

}  // namespace

std::istringstream open_text_file(const std::filesystem::path& file, std::string_view what) {
  return std::istringstream(read_file(file, kMaxTextFileBytes, what));
}

void for_each_text_line(const std::filesystem::path& file,
                        const std::function<void(const std::string& line, std::size_t line_no)>& on_line) {
  auto in = open_text_file(file);
  for_each_text_line(in, file, on_line);
}

void for_each_text_line(std::istream& in, const std::filesystem::path& file,
                        const std::function<void(const std::string& line, std::size_t line_no)>& on_line) {
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.starts_with(kUtf8Bom)) line.erase(0, kUtf8Bom.size());
    if (!line.empty() && line.back() == '\r') line.pop_back();
    on_line(line, line_no);
  }
  if (in.bad()) throw InputError(file, fmt::format("read error after line {}", line_no));
}

Pose checked_rigid_pose(const Pose& T, const std::filesystem::path& file, std::size_t line_no,
                        const std::string& what) {
  const Eigen::Matrix3d R = T.linear();
  const double error = orthonormality_error(R);
  if (!(error <= kRotationTolerance)) {
    throw InputError(file, fmt::format("line {}: {} is not orthonormal (||R^T R - I|| = {:.2g}, more than {:g}): "
                                       "not a rigid transform",
                                       line_no, what, error, kRotationTolerance));
  }
  if (R.determinant() < 0.0) {
    throw InputError(file, fmt::format("line {}: {} is a reflection (det = {:.4f}), not a rotation", line_no, what,
                                       R.determinant()));
  }
  return orthonormalized(T);
}

void check_time_increases(double previous, std::size_t previous_line, double t, const std::filesystem::path& file,
                          std::size_t line_no) {
  if (t > previous) return;
  throw InputError(file, fmt::format("line {}: timestamp {:.9g} is not after {:.9g} on line {} (timestamps must "
                                     "increase)",
                                     line_no, t, previous, previous_line));
}

}  // namespace saloam
