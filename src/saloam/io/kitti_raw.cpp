#include "saloam/io/kitti_raw.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/files.hpp"
#include "saloam/io/point_fields.hpp"
#include "saloam/io/text_input.hpp"
#include "saloam/io/text_records.hpp"

namespace saloam {
namespace {

constexpr double kEarthRadius = 6378137.0;  // KITTI devkit's er (WGS84 equatorial radius)
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kMaxLatitude = 85.0;  // Mercator's y diverges at the poles
constexpr double kMaxAltitude = 1e5;   // [m]: far above anything that carries a LiDAR
constexpr double kMaxAngle = 7.0;      // [rad]: a little beyond 2 pi

Eigen::Vector3d mercator(double lat, double lon, double scale) {
  return {scale * lon * kDeg * kEarthRadius, scale * kEarthRadius * std::log(std::tan((90.0 + lat) * kDeg / 2.0)), 0.0};
}

Pose oxts_pose(const OxtsRecord& r, double scale) {
  Pose T = Pose::Identity();
  T.translation() = mercator(r.lat, r.lon, scale);
  T.translation().z() = r.alt;
  T.linear() = (Eigen::AngleAxisd(r.yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(r.pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(r.roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

/// An unsigned number of exactly `digits` digits at text[at...].
std::optional<int> digits_at(std::string_view text, std::size_t at, std::size_t digits) {
  if (at + digits > text.size()) return std::nullopt;
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data() + at, text.data() + at + digits, value);
  if (ec != std::errc() || end != text.data() + at + digits || text[at] == '-' || text[at] == '+') return std::nullopt;
  return value;
}

/// Days from 1970-01-01 to the civil date (proleptic Gregorian; H. Hinnant's algorithm).
long days_from_civil(long y, unsigned m, unsigned d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<long>(doe) - 719468;
}

/// Years a timestamp may carry: wide of any recording, inside the range of
/// 64-bit nanoseconds since 1970.
constexpr int kFirstYear = 1900;
constexpr int kLastYear = 2200;

/// "YYYY-MM-DD hh:mm:ss[.fffffffff]" as nanoseconds since the epoch (exact:
/// times of one drive subtract without rounding), or nullopt. A tenth
/// fraction digit rounds the nanoseconds.
std::optional<std::int64_t> parse_date_time(std::string_view s) {
  if (s.size() < 19 || s[4] != '-' || s[7] != '-' || s[10] != ' ' || s[13] != ':' || s[16] != ':') return std::nullopt;
  const auto year = digits_at(s, 0, 4), month = digits_at(s, 5, 2), day = digits_at(s, 8, 2);
  const auto hour = digits_at(s, 11, 2), minute = digits_at(s, 14, 2), second = digits_at(s, 17, 2);
  if (!year || !month || !day || !hour || !minute || !second) return std::nullopt;
  if (*month < 1 || *month > 12 || *day < 1 || *day > 31 || *hour > 23 || *minute > 59 || *second > 60) return std::nullopt;
  // Nanoseconds since 1970 in 64 bits reach the years 1678-2262.
  if (*year < kFirstYear || *year > kLastYear) return std::nullopt;
  std::int64_t nanos = 0;
  if (s.size() > 19) {
    if (s[19] != '.' || s.size() == 20 || s.size() > 30) return std::nullopt;
    std::int64_t scale = 100000000;
    for (std::size_t i = 20; i < s.size(); ++i, scale /= 10) {
      if (s[i] < '0' || s[i] > '9') return std::nullopt;
      nanos += scale > 0 ? scale * (s[i] - '0') : (s[i] >= '5');  // the 10th digit rounds
    }
  }
  const long days = days_from_civil(*year, static_cast<unsigned>(*month), static_cast<unsigned>(*day));
  const std::int64_t seconds = static_cast<std::int64_t>(days) * 86400 + *hour * 3600 + *minute * 60 + *second;
  return seconds * kNanosPerSecond + nanos;
}

std::string read_all(std::istream& in, const std::filesystem::path& file) {
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(file, "read failed");
  return ss.str();
}

struct KeyedLine {
  std::vector<double> values;
  std::size_t line_no = 0;
};

/// The numbers after "KEY:" on the first such line of `text`, or nullopt.
std::optional<KeyedLine> keyed_numbers(const std::string& text, std::string_view key, const std::filesystem::path& file) {
  std::istringstream in(text);
  std::optional<KeyedLine> found;
  for_each_text_line(in, file, [&](const std::string& line, std::size_t line_no) {
    const auto words = split_words(line);
    if (found || words.empty() || words[0] != std::string(key) + ":") return;
    std::vector<double> values;
    for (std::size_t i = 1; i < words.size(); ++i) {
      const auto v = parse_number(words[i]);
      if (!v || !std::isfinite(*v)) {
        throw InputError(file, fmt::format("line {}: '{}' is not a finite number", line_no, words[i].substr(0, 40)));
      }
      values.push_back(*v);
    }
    found = KeyedLine{std::move(values), line_no};
  });
  return found;
}

}  // namespace

OxtsRecord parse_oxts(std::istream& in, const std::filesystem::path& file) {
  std::string text = read_all(in, file);
  std::replace(text.begin(), text.end(), '\n', ' ');
  const auto words = split_words(text);
  std::vector<double> v;
  for (const auto& w : words) {
    const auto value = parse_number(w);
    if (!value || !std::isfinite(*value)) throw InputError(file, fmt::format("'{}' is not a finite number", w.substr(0, 40)));
    v.push_back(*value);
    if (v.size() > 30) throw InputError(file, "more than 30 numbers: not an oxts record");
  }
  if (v.size() < 6) throw InputError(file, fmt::format("{} numbers: an oxts record has 30 (lat lon alt roll pitch yaw ...)", v.size()));
  if (std::abs(v[0]) > kMaxLatitude) throw InputError(file, fmt::format("latitude {} deg is beyond +-{} deg", v[0], kMaxLatitude));
  if (std::abs(v[1]) > 180.0) throw InputError(file, fmt::format("longitude {} deg is beyond +-180 deg", v[1]));
  if (std::abs(v[2]) > kMaxAltitude) throw InputError(file, fmt::format("altitude {} m is beyond +-{} m", v[2], kMaxAltitude));
  for (int k = 3; k < 6; ++k) {
    if (std::abs(v[k]) > kMaxAngle) {
      throw InputError(file, fmt::format("{} {} rad is not an angle (beyond +-{} rad)", k == 3 ? "roll" : k == 4 ? "pitch" : "yaw", v[k], kMaxAngle));
    }
  }
  return {v[0], v[1], v[2], v[3], v[4], v[5]};
}

OxtsRecord read_oxts(const std::filesystem::path& file) {
  auto in = open_text_file(file, "oxts file");
  return parse_oxts(in, file);
}

void write_oxts(const std::filesystem::path& file, const OxtsRecord& r) {
  AtomicFile text(file);  // complete under its name, or absent
  std::ostream& out = text.stream();
  out << fmt::format("{:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}", r.lat, r.lon, r.alt, r.roll, r.pitch, r.yaw);
  for (int i = 6; i < 30; ++i) out << (i == 25 ? " 4" : i == 26 ? " 10" : " 0");  // navstat 4, numsats 10
  out << '\n';
  text.commit();
}

std::vector<Pose> oxts_to_poses(const std::vector<OxtsRecord>& records) {
  std::vector<Pose> poses;
  if (records.empty()) return poses;
  const double scale = std::cos(records.front().lat * kDeg);
  const Pose first_inv = oxts_pose(records.front(), scale).inverse();
  poses.reserve(records.size());
  for (const auto& r : records) poses.push_back(first_inv * oxts_pose(r, scale));
  return poses;
}

std::vector<OxtsRecord> poses_to_oxts(const std::vector<Pose>& imu_poses, const OxtsRecord& origin) {
  const double scale = std::cos(origin.lat * kDeg);
  const Pose first = oxts_pose(origin, scale);
  std::vector<OxtsRecord> out;
  out.reserve(imu_poses.size());
  for (const auto& P : imu_poses) {
    const Pose T = first * P;
    const Eigen::Vector3d t = T.translation();
    const Eigen::Matrix3d R = T.linear();
    OxtsRecord r;
    r.lon = t.x() / (scale * kEarthRadius) / kDeg;
    r.lat = 2.0 * std::atan(std::exp(t.y() / (scale * kEarthRadius))) / kDeg - 90.0;
    r.alt = t.z();
    r.pitch = -std::asin(std::clamp(R(2, 0), -1.0, 1.0));
    r.roll = std::atan2(R(2, 1), R(2, 2));
    r.yaw = std::atan2(R(1, 0), R(0, 0));
    out.push_back(r);
  }
  return out;
}

std::vector<std::int64_t> parse_kitti_timestamps_ns(std::istream& in, const std::filesystem::path& file) {
  std::vector<std::int64_t> times;
  std::size_t previous_line = 0;
  for_each_text_line(in, file, [&](const std::string& raw, std::size_t line_no) {
    const auto words = split_words(raw);
    if (words.empty()) return;
    const std::string line = words.size() == 2 ? words[0] + " " + words[1] : raw;
    const auto t = parse_date_time(line);
    if (!t) {
      throw InputError(file, fmt::format("line {}: '{}' is not a KITTI timestamp (YYYY-MM-DD hh:mm:ss.fffffffff)", line_no,
                                         line.substr(0, 40)));
    }
    if (!times.empty() && *t <= times.back()) {
      check_time_increases(nanos_to_seconds(times.back()), previous_line, nanos_to_seconds(*t), file, line_no);
    }
    times.push_back(*t);
    previous_line = line_no;
  });
  return times;
}

std::vector<std::int64_t> read_kitti_timestamps_ns(const std::filesystem::path& file) {
  auto in = open_text_file(file, "timestamps file");
  return parse_kitti_timestamps_ns(in, file);
}

void write_kitti_timestamps(const std::filesystem::path& file, const std::vector<double>& seconds) {
  std::vector<std::int64_t> nanos(seconds.size());
  std::transform(seconds.begin(), seconds.end(), nanos.begin(), [](double t) { return std::llround(t * 1e9); });
  write_kitti_timestamps_ns(file, nanos);
}

void write_kitti_timestamps_ns(const std::filesystem::path& file, const std::vector<std::int64_t>& times) {
  AtomicFile text(file);
  std::ostream& out = text.stream();
  for (const std::int64_t t : times) {
    const std::int64_t s = t >= 0 ? t / kNanosPerSecond : (t - kNanosPerSecond + 1) / kNanosPerSecond;
    const long nanos = static_cast<long>(t - s * kNanosPerSecond);
    const long days = s >= 0 ? s / 86400 : (s - 86399) / 86400;
    const long in_day = s - days * 86400;
    // civil_from_days (H. Hinnant)
    const long z = days + 719468;
    const long era = (z >= 0 ? z : z - 146096) / 146097;
    const auto doe = static_cast<unsigned>(z - era * 146097);
    const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    const unsigned mp = (5 * doy + 2) / 153;
    const unsigned d = doy - (153 * mp + 2) / 5 + 1;
    const unsigned m = mp < 10 ? mp + 3 : mp - 9;
    const long y = static_cast<long>(yoe) + era * 400 + (m <= 2);
    out << fmt::format("{:04d}-{:02d}-{:02d} {:02d}:{:02d}:{:02d}.{:09d}\n", y, m, d, in_day / 3600, in_day % 3600 / 60,
                       in_day % 60, nanos);
  }
  text.commit();
}

Pose parse_imu_to_velo(std::istream& in, const std::filesystem::path& file) {
  const std::string text = read_all(in, file);
  const auto R = keyed_numbers(text, "R", file);
  const auto T = keyed_numbers(text, "T", file);
  if (!R || R->values.size() != 9) throw InputError(file, "needs a line 'R: ' with 9 numbers (rotation, row-major)");
  if (!T || T->values.size() != 3) throw InputError(file, "needs a line 'T: ' with 3 numbers (translation [m])");
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R->values.data());
  pose.translation() = Eigen::Vector3d(T->values[0], T->values[1], T->values[2]);
  return checked_rigid_pose(pose, file, R->line_no, "rotation R");
}

Pose read_imu_to_velo(const std::filesystem::path& file) {
  auto in = open_text_file(file, "calibration file");
  return parse_imu_to_velo(in, file);
}

void write_imu_to_velo(const std::filesystem::path& file, const Pose& imu_to_velo) {
  AtomicFile text(file);
  std::ostream& out = text.stream();
  const Eigen::Matrix3d R = imu_to_velo.linear();
  const Eigen::Vector3d t = imu_to_velo.translation();
  out << "calib_time: written by saloam\nR:";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out << fmt::format(" {:.17g}", R(r, c));
  }
  out << fmt::format("\nT: {:.17g} {:.17g} {:.17g}\n", t.x(), t.y(), t.z());
  text.commit();
}

}  // namespace saloam
