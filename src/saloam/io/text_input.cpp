#include "saloam/io/text_input.hpp"

#include <cmath>
#include <string_view>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/lie.hpp"

namespace saloam {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

bool is_blank_or_comment(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

/// Parses all numbers of a line; throws with the line number on junk or non-finite values.
std::vector<double> parse_numbers(const std::string& line, const std::filesystem::path& file, std::size_t line_no) {
  std::vector<double> values;
  std::istringstream ss(line);
  std::string token;
  while (ss >> token) {
    double v = 0.0;
    std::size_t used = 0;
    try {
      v = std::stod(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size()) throw InputError(file, fmt::format("line {}: '{}' is not a number", line_no, token));
    if (!std::isfinite(v)) throw InputError(file, fmt::format("line {}: non-finite value '{}'", line_no, token));
    values.push_back(v);
  }
  return values;
}

}  // namespace

void for_each_number_line(std::istream& in, const std::filesystem::path& file,
                          const std::function<void(const std::vector<double>& numbers, std::size_t line_no)>& on_line) {
  for_each_text_line(in, file, [&](const std::string& line, std::size_t line_no) {
    if (!is_blank_or_comment(line)) on_line(parse_numbers(line, file, line_no), line_no);
  });
}

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
