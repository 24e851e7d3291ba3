#include "saloam/sensors/velodyne_packet.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/error.hpp"
#include "saloam/io/text_input.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr std::size_t kBlocks = 12;
constexpr std::size_t kBlockBytes = 100;
constexpr std::size_t kChannels = 32;
constexpr std::uint16_t kUpperFlag = 0xEEFF;
constexpr std::uint16_t kLowerFlag = 0xDDFF;
constexpr std::uint16_t kFullTurn = 36000;  // [0.01 deg]
constexpr std::uint8_t kProductHdl32e = 0x21;
constexpr std::uint8_t kProductVlp16 = 0x22;
constexpr double kCentidegree = std::numbers::pi / 18000.0;

// Firing timing [us] (velodyne_packet.hpp).
constexpr double kVlp16Laser = 2.304, kVlp16Sequence = 55.296, kVlp16Block = 110.592;
constexpr double kHdl32eLaserPair = 1.152, kHdl32eBlock = 46.08;
constexpr double kHdl64eLaser = 1.5, kHdl64eBlockPair = 48.0;

constexpr std::array<double, 32> kHdl32eElevationDeg{
    -30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33, -25.33, -4.00, -24.00, -2.67, -22.67, -1.33, -21.33, 0.00,
    -20.00, 1.33,  -18.67, 2.67,  -17.33, 4.00,  -16.00, 5.33,  -14.67, 6.67,  -13.33, 8.00,  -12.00, 9.33,  -10.67, 10.67};

std::uint16_t le16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}
void put_le16(std::vector<std::uint8_t>& b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<std::uint8_t>(v & 0xFF);
  b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
std::size_t block_at(std::size_t b) { return b * kBlockBytes; }

double yaml_number(const YAML::Node& laser, const char* key, double fallback, const fs::path& file) {
  const YAML::Node v = laser[key];
  if (!v) return fallback;
  try {
    return v.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(file, fmt::format("Velodyne calibration: \"{}\" is not a number", key));
  }
}

// A laser's correction: finite and within `bound` (angles [rad] within a
// half or a quarter turn, offsets [m] within 10 m: real ones are
// centimetres), or the calibration would put points anywhere (1e300 put
// them 1,700 km away).
double laser_correction(const YAML::Node& laser, const char* key, double fallback, double bound, std::size_t index,
                        const fs::path& file) {
  const double v = yaml_number(laser, key, fallback, file);
  if (!std::isfinite(v) || std::abs(v) > bound) {
    throw InputError(file, fmt::format("Velodyne calibration: laser entry {}: \"{}\" {} is not within +-{}", index, key,
                                       v, bound));
  }
  return v;
}

}  // namespace

std::string_view velodyne_model_name(VelodyneModel model) {
  switch (model) {
    case VelodyneModel::kVlp16: return "VLP-16";
    case VelodyneModel::kHdl32e: return "HDL-32E";
    case VelodyneModel::kHdl64e: return "HDL-64E";
  }
  return "?";
}

std::size_t velodyne_lasers(VelodyneModel model) {
  switch (model) {
    case VelodyneModel::kVlp16: return 16;
    case VelodyneModel::kHdl32e: return 32;
    case VelodyneModel::kHdl64e: return 64;
  }
  return 0;
}

std::optional<VelodyneCalibration> nominal_velodyne_calibration(VelodyneModel model) {
  VelodyneCalibration c;
  if (model == VelodyneModel::kVlp16) {
    for (int ch = 0; ch < 16; ++ch) {
      VelodyneLaser l;
      l.vert_correction = (ch % 2 == 0 ? -15 + ch : ch) * std::numbers::pi / 180.0;
      c.lasers.push_back(l);
    }
    c.source = "the VLP-16 datasheet's laser elevations (no calibration file)";
    return c;
  }
  if (model == VelodyneModel::kHdl32e) {
    for (double e : kHdl32eElevationDeg) {
      VelodyneLaser l;
      l.vert_correction = e * std::numbers::pi / 180.0;
      c.lasers.push_back(l);
    }
    c.source = "the HDL-32E datasheet's laser elevations (no calibration file)";
    return c;
  }
  return std::nullopt;
}

VelodyneCalibration parse_velodyne_calibration(std::string_view text, const fs::path& file) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    throw InputError(file, fmt::format("not YAML (a Velodyne calibration expected): {}", e.msg));
  }
  const YAML::Node lasers = root.IsMap() ? root["lasers"] : YAML::Node();
  if (!lasers || !lasers.IsSequence() || lasers.size() == 0 || lasers.size() > 128) {
    throw InputError(file, "Velodyne calibration without a \"lasers\" list (velodyne_pointcloud's YAML format)");
  }
  const std::size_t n = lasers.size();
  if (root["num_lasers"] && yaml_number(root, "num_lasers", 0, file) != static_cast<double>(n)) {
    throw InputError(file, fmt::format("Velodyne calibration: num_lasers says {} but {} lasers are listed",
                                       root["num_lasers"].as<std::string>(), n));
  }
  VelodyneCalibration c;
  c.lasers.resize(n);
  std::vector<bool> seen(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    const YAML::Node l = lasers[i];
    if (!l.IsMap()) throw InputError(file, fmt::format("Velodyne calibration: laser entry {} is not a map", i));
    const double id_value = yaml_number(l, "laser_id", -1, file);
    if (id_value < 0 || id_value >= static_cast<double>(n) || id_value != std::floor(id_value)) {
      throw InputError(file, fmt::format("Velodyne calibration: laser entry {} has no laser_id within 0..{}", i, n - 1));
    }
    const auto id = static_cast<std::size_t>(id_value);
    if (seen[id]) throw InputError(file, fmt::format("Velodyne calibration: laser_id {} twice", id));
    seen[id] = true;
    VelodyneLaser& laser = c.lasers[id];
    constexpr double kMetres = 10.0;
    laser.rot_correction = laser_correction(l, "rot_correction", 0, std::numbers::pi, i, file);
    laser.vert_correction = laser_correction(l, "vert_correction", 0, std::numbers::pi / 2, i, file);
    laser.dist_correction = laser_correction(l, "dist_correction", 0, kMetres, i, file);
    laser.dist_correction_x = laser_correction(l, "dist_correction_x", laser.dist_correction, kMetres, i, file);
    laser.dist_correction_y = laser_correction(l, "dist_correction_y", laser.dist_correction, kMetres, i, file);
    laser.vert_offset = laser_correction(l, "vert_offset_correction", 0, kMetres, i, file);
    laser.horiz_offset = laser_correction(l, "horiz_offset_correction", 0, kMetres, i, file);
  }
  c.source = file.string();
  return c;
}

VelodyneCalibration read_velodyne_calibration(const fs::path& file) {
  return parse_velodyne_calibration(open_text_file(file, "Velodyne calibration").str(), file);
}

std::string velodyne_calibration_yaml(const VelodyneCalibration& c) {
  std::ostringstream out;
  out.precision(17);
  out << "lasers:\n";
  for (std::size_t i = 0; i < c.lasers.size(); ++i) {
    const VelodyneLaser& l = c.lasers[i];
    out << "- {dist_correction: " << l.dist_correction << ", dist_correction_x: " << l.dist_correction_x
        << ", dist_correction_y: " << l.dist_correction_y << ", focal_distance: 0.0, focal_slope: 0.0"
        << ", horiz_offset_correction: " << l.horiz_offset << ", laser_id: " << i
        << ", max_intensity: 255, min_intensity: 0, rot_correction: " << l.rot_correction
        << ", vert_correction: " << l.vert_correction << ", vert_offset_correction: " << l.vert_offset << "}\n";
  }
  out << "num_lasers: " << c.lasers.size() << "\ndistance_resolution: " << kVelodyneDistanceUnit << '\n';
  return out.str();
}

// ---------------------------------------------------------------- packets

std::string check_velodyne_packet(std::span<const std::uint8_t> p) {
  if (p.size() != kVelodynePacketBytes) {
    return fmt::format("a Velodyne data packet has {} bytes, this one {}", kVelodynePacketBytes, p.size());
  }
  for (std::size_t b = 0; b < kBlocks; ++b) {
    const std::uint16_t flag = le16(p, block_at(b));
    if (flag != kUpperFlag && flag != kLowerFlag) return fmt::format("block {} has flag 0x{:04X}, not 0xEEFF/0xDDFF", b, flag);
    if (velodyne_block_azimuth(p, b) >= kFullTurn) return fmt::format("block {} has azimuth {} >= 36000", b, velodyne_block_azimuth(p, b));
  }
  return {};
}

VelodyneTail velodyne_tail(std::span<const std::uint8_t> p) {
  const std::size_t at = kBlocks * kBlockBytes;
  return {static_cast<std::uint32_t>(p[at] | (p[at + 1] << 8) | (p[at + 2] << 16) | (std::uint32_t{p[at + 3]} << 24)),
          p[at + 4], p[at + 5]};
}

std::uint16_t velodyne_block_azimuth(std::span<const std::uint8_t> p, std::size_t block) {
  return le16(p, block_at(block) + 2);
}

std::optional<VelodyneModel> velodyne_model_of(std::span<const std::uint8_t> p) {
  if (p.size() != kVelodynePacketBytes) return std::nullopt;
  for (std::size_t b = 0; b < kBlocks; ++b) {
    if (le16(p, block_at(b)) == kLowerFlag) return VelodyneModel::kHdl64e;
  }
  const auto tail = velodyne_tail(p);
  if (tail.byte_1205 == kProductVlp16) return VelodyneModel::kVlp16;
  if (tail.byte_1205 == kProductHdl32e) return VelodyneModel::kHdl32e;
  return std::nullopt;
}

VelodyneDecoder::VelodyneDecoder(VelodyneModel model, VelodyneCalibration calibration)
    : model_(model), calibration_(std::move(calibration)) {
  const std::size_t n = velodyne_lasers(model_);
  if (calibration_.lasers.size() != n) {
    throw std::invalid_argument(fmt::format("a {} needs a calibration of {} lasers, not {}", velodyne_model_name(model_),
                                            n, calibration_.lasers.size()));
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return calibration_.lasers[a].vert_correction > calibration_.lasers[b].vert_correction;
  });
  ring_of_laser_.resize(n);
  for (std::size_t rank = 0; rank < n; ++rank) ring_of_laser_[order[rank]] = static_cast<std::uint16_t>(rank);
  for (const auto& l : calibration_.lasers) {
    cos_vert_.push_back(std::cos(l.vert_correction));
    sin_vert_.push_back(std::sin(l.vert_correction));
  }
}

bool VelodyneDecoder::dual(std::span<const std::uint8_t> p) const {
  return model_ != VelodyneModel::kHdl64e &&
         velodyne_tail(p).byte_1204 == static_cast<std::uint8_t>(VelodyneReturnMode::kDual);
}

double VelodyneDecoder::firing_offset_us(std::size_t block, std::size_t channel, bool dual) const {
  const std::size_t firing = dual ? block / 2 : block;
  switch (model_) {
    case VelodyneModel::kVlp16:
      return static_cast<double>(firing) * kVlp16Block + static_cast<double>(channel / 16) * kVlp16Sequence +
             static_cast<double>(channel % 16) * kVlp16Laser;
    case VelodyneModel::kHdl32e:
      return static_cast<double>(firing) * kHdl32eBlock + static_cast<double>(channel / 2) * kHdl32eLaserPair;
    case VelodyneModel::kHdl64e:
      return static_cast<double>(block / 2) * kHdl64eBlockPair + static_cast<double>(channel) * kHdl64eLaser;
  }
  return 0.0;
}

Eigen::Vector3f VelodyneDecoder::place(std::size_t laser, double distance_m, double azimuth_rad) const {
  // velodyne_pointcloud's RawData::unpack, in its own axes (x right, y forward), then turned to x forward, y left.
  const VelodyneLaser& c = calibration_.lasers[laser];
  const double cos_v = cos_vert_[laser], sin_v = sin_vert_[laser];
  const double cos_rot = std::cos(azimuth_rad - c.rot_correction), sin_rot = std::sin(azimuth_rad - c.rot_correction);
  const double distance = distance_m + c.dist_correction;
  double xy = distance * cos_v - c.vert_offset * sin_v;
  const double xx = std::abs(xy * sin_rot - c.horiz_offset * cos_rot);
  const double yy = std::abs(xy * cos_rot + c.horiz_offset * sin_rot);
  const double corr_x = (c.dist_correction - c.dist_correction_x) * (xx - 2.4) / (25.04 - 2.4) + c.dist_correction_x -
                        c.dist_correction;
  const double corr_y = (c.dist_correction - c.dist_correction_y) * (yy - 1.93) / (25.04 - 1.93) +
                        c.dist_correction_y - c.dist_correction;
  xy = (distance + corr_x) * cos_v - c.vert_offset * sin_v;
  const double x = xy * sin_rot - c.horiz_offset * cos_rot;
  const double distance_y = distance + corr_y;
  xy = distance_y * cos_v - c.vert_offset * sin_v;
  const double y = xy * cos_rot + c.horiz_offset * sin_rot;
  const double z = distance_y * sin_v + c.vert_offset * cos_v;
  return {static_cast<float>(y), static_cast<float>(-x), static_cast<float>(z)};
}

void VelodyneDecoder::decode(std::span<const std::uint8_t> p, std::vector<VelodyneReturn>& out) const {
  const bool two = dual(p);
  const std::size_t step = two ? 2 : 1;  // dual: the even block of each pair (last return)
  for (std::size_t b = 0; b < kBlocks; b += step) {
    const std::size_t at = block_at(b);
    const bool lower = le16(p, at) == kLowerFlag;
    const double azimuth = velodyne_block_azimuth(p, b);
    // The azimuth turned between this firing and the next (VLP-16 interpolation).
    const std::size_t next = b + step < kBlocks ? b + step : b;
    const std::size_t before = b + step < kBlocks ? b : (b >= step ? b - step : b);
    const double gap = (velodyne_block_azimuth(p, next) - velodyne_block_azimuth(p, before) + kFullTurn) % kFullTurn;
    for (std::size_t ch = 0; ch < kChannels; ++ch) {
      const std::uint16_t raw = le16(p, at + 4 + 3 * ch);
      if (raw == 0) continue;
      std::size_t laser = ch;
      double az = azimuth;
      if (model_ == VelodyneModel::kVlp16) {
        laser = ch % 16;
        az += gap * ((ch / 16) * kVlp16Sequence + (ch % 16) * kVlp16Laser) / kVlp16Block;
      } else if (lower) {
        if (model_ != VelodyneModel::kHdl64e) continue;  // a lower block belongs to an HDL-64E only
        laser = ch + 32;
      }
      VelodyneReturn r;
      r.point = place(laser, raw * kVelodyneDistanceUnit, std::fmod(az, kFullTurn) * kCentidegree);
      r.intensity = p[at + 6 + 3 * ch];
      r.ring = ring_of_laser_[laser];
      r.block = static_cast<std::uint16_t>(b);
      r.time_offset = firing_offset_us(b, ch, two) * 1e-6;
      out.push_back(r);
    }
  }
}

std::vector<std::uint8_t> encode_velodyne_packet(VelodyneModel model, std::span<const VelodyneFiring, 12> blocks,
                                                 std::uint32_t timestamp_us) {
  std::vector<std::uint8_t> p(kVelodynePacketBytes, 0);
  for (std::size_t b = 0; b < kBlocks; ++b) {
    const VelodyneFiring& f = blocks[b];
    const std::size_t at = block_at(b);
    put_le16(p, at, f.lower ? kLowerFlag : kUpperFlag);
    put_le16(p, at + 2, f.azimuth);
    for (std::size_t ch = 0; ch < kChannels; ++ch) {
      put_le16(p, at + 4 + 3 * ch, f.distance[ch]);
      p[at + 6 + 3 * ch] = f.intensity[ch];
    }
  }
  const std::size_t tail = kBlocks * kBlockBytes;
  for (int i = 0; i < 4; ++i) p[tail + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(timestamp_us >> (8 * i));
  if (model != VelodyneModel::kHdl64e) {
    p[tail + 4] = static_cast<std::uint8_t>(VelodyneReturnMode::kStrongest);
    p[tail + 5] = model == VelodyneModel::kVlp16 ? kProductVlp16 : kProductHdl32e;
  }
  return p;
}

double velodyne_block_offset_us(VelodyneModel model, std::size_t block) {
  switch (model) {
    case VelodyneModel::kVlp16: return static_cast<double>(block) * kVlp16Block;
    case VelodyneModel::kHdl32e: return static_cast<double>(block) * kHdl32eBlock;
    case VelodyneModel::kHdl64e: return static_cast<double>(block / 2) * kHdl64eBlockPair;
  }
  return 0.0;
}

}  // namespace saloam
