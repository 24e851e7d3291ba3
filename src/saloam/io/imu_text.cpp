#include "saloam/io/imu_text.hpp"

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/io/text_input.hpp"

namespace saloam {

std::vector<ImuSample> read_imu_text(const std::filesystem::path& file) {
  auto in = open_text_file(file, "IMU file");
  return read_imu_text(in, file);
}

std::vector<ImuSample> read_imu_text(std::istream& in, const std::filesystem::path& file) {
  std::vector<ImuSample> samples;
  std::size_t previous_line = 0;
  for_each_number_line(in, file, [&](const std::vector<double>& v, std::size_t line_no) {
    if (v.size() != 7) {
      throw InputError(file, fmt::format("line {}: expected 7 numbers (time ax ay az wx wy wz), found {}", line_no, v.size()));
    }
    if (!samples.empty()) check_time_increases(samples.back().time, previous_line, v[0], file, line_no);
    samples.push_back({v[0], Eigen::Vector3d(v[1], v[2], v[3]), Eigen::Vector3d(v[4], v[5], v[6])});
    previous_line = line_no;
  });
  if (samples.empty()) throw InputError(file, "no IMU samples in file");
  return samples;
}

void write_imu_text(const std::filesystem::path& file, const std::vector<ImuSample>& samples, const std::string& source) {
  AtomicFile out(file);
  out.stream() << "# " << source << '\n' << "# time [s] ax ay az [m/s^2, specific force] wx wy wz [rad/s]\n";
  for (const ImuSample& s : samples) {
    out.stream() << fmt::format("{:.6f} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n", s.time, s.acceleration.x(),
                                s.acceleration.y(), s.acceleration.z(), s.angular_velocity.x(), s.angular_velocity.y(),
                                s.angular_velocity.z());
  }
  out.commit();
}

}  // namespace saloam
