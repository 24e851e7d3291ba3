#include "saloam/sources/scan_files.hpp"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

bool all_digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::optional<std::size_t> frame_number(std::string_view stem) {
  if (!all_digits(stem) || stem.size() > 10) return std::nullopt;
  std::size_t n = 0;
  std::from_chars(stem.data(), stem.data() + stem.size(), n);
  return n;
}

std::optional<double> stamp_of(std::string_view stem) {
  const auto dot = stem.find('.');
  if (dot != std::string_view::npos) {
    if (!all_digits(stem.substr(0, dot)) || !all_digits(stem.substr(dot + 1))) return std::nullopt;
    double value = 0.0;
    const auto [end, ec] = std::from_chars(stem.data(), stem.data() + stem.size(), value);
    if (ec != std::errc() || end != stem.data() + stem.size()) return std::nullopt;
    return value;
  }
  if (all_digits(stem) && stem.size() >= 16 && stem.size() <= 19) {
    std::uint64_t ns = 0;
    std::from_chars(stem.data(), stem.data() + stem.size(), ns);
    return static_cast<double>(ns / 1000000000ULL) + 1e-9 * static_cast<double>(ns % 1000000000ULL);
  }
  return std::nullopt;
}

std::vector<fs::path> files_with_extension(const fs::path& folder, std::string_view extension) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() == extension && entry.is_regular_file(ec)) files.push_back(entry.path());
  }
  if (ec) throw InputError(folder, fmt::format("cannot list folder: {}", ec.message()));
  return files;
}

}  // namespace

bool has_files_with_extension(const fs::path& folder, std::string_view extension) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() == extension && entry.is_regular_file(ec)) return true;
  }
  return false;
}

ScanFiles list_scan_files(const fs::path& folder, std::string_view extension) {
  ScanFiles out;
  out.files = files_with_extension(folder, extension);
  if (out.files.empty()) throw InputError(folder, fmt::format("no {} files", extension));
  const auto stem = [](const fs::path& p) { return p.stem().string(); };
  const bool numbered = std::all_of(out.files.begin(), out.files.end(), [&](const fs::path& p) { return frame_number(stem(p)).has_value(); });
  const bool stamped = std::all_of(out.files.begin(), out.files.end(), [&](const fs::path& p) { return stamp_of(stem(p)).has_value(); });
  if (numbered) {
    std::sort(out.files.begin(), out.files.end(), [&](const fs::path& a, const fs::path& b) {
      return *frame_number(stem(a)) < *frame_number(stem(b));
    });
    for (std::size_t i = 1; i < out.files.size(); ++i) {
      const std::size_t previous = *frame_number(stem(out.files[i - 1]));
      const std::size_t current = *frame_number(stem(out.files[i]));
      if (current != previous + 1) {
        throw InputError(out.files[i], fmt::format("frame {} follows {}: a scan is missing (or a duplicate number), so "
                                                   "every later scan would get the wrong time and pose",
                                                   current, previous));
      }
    }
  } else if (stamped) {
    std::sort(out.files.begin(), out.files.end(), [&](const fs::path& a, const fs::path& b) {
      return *stamp_of(stem(a)) < *stamp_of(stem(b));
    });
    std::vector<double> stamps;
    for (const auto& f : out.files) stamps.push_back(*stamp_of(stem(f)));
    for (std::size_t i = 1; i < stamps.size(); ++i) {
      if (!(stamps[i] > stamps[i - 1])) throw InputError(out.files[i], "two scans with the same timestamp name");
    }
    out.stamps = std::move(stamps);
  } else {
    std::sort(out.files.begin(), out.files.end());
  }
  return out;
}

}  // namespace saloam
