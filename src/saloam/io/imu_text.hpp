#pragma once
// IMU samples as plain text (imu.txt beside a sequence's times.txt): one
// sample per line, `time ax ay az wx wy wz` in [s], [m/s^2] (specific force)
// and [rad/s], in the frame of the sequence's scans and on the clock of its
// times.txt; '#' starts a comment line (the writer names the source there).

#include <filesystem>
#include <istream>
#include <string>
#include <vector>

#include "saloam/imu/imu_sample.hpp"

namespace saloam {

/// The samples of an IMU text file. InputError naming the file and the line
/// when a line has not 7 numbers, a value is not finite, or the time does
/// not increase; or when the file holds no sample.
std::vector<ImuSample> read_imu_text(const std::filesystem::path& file);
std::vector<ImuSample> read_imu_text(std::istream& in, const std::filesystem::path& file);

/// Writes the samples (atomically); `source` becomes the header's comment.
void write_imu_text(const std::filesystem::path& file, const std::vector<ImuSample>& samples, const std::string& source);

}  // namespace saloam
