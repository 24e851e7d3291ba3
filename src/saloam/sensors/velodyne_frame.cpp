#include "saloam/sensors/velodyne_frame.hpp"

#include <cmath>

namespace saloam {
namespace {

constexpr double kHourUs = 3600e6;
constexpr std::uint16_t kFullTurn = 36000;
constexpr std::size_t kBlocks = 12;

}  // namespace

VelodyneFrameAssembler::VelodyneFrameAssembler(VelodyneDecoder decoder, double cut_azimuth_deg)
    : decoder_(std::move(decoder)),
      cut_(static_cast<std::uint16_t>(std::lround(std::fmod(std::fmod(cut_azimuth_deg, 360.0) + 360.0, 360.0) * 100.0) %
                                      kFullTurn)) {}

double VelodyneFrameAssembler::unwrap_us(std::uint32_t t) {
  if (last_timestamp_us_ && static_cast<double>(t) + kHourUs / 2 < static_cast<double>(*last_timestamp_us_)) {
    hours_us_ += kHourUs;  // past the top of the hour
  }
  last_timestamp_us_ = t;
  return hours_us_ + static_cast<double>(t);
}

std::size_t VelodyneFrameAssembler::count_gap(double packet_us, bool dual) {
  // A packet's span: 12 blocks (6 upper/lower pairs on the HDL-64E), 6 firings in dual mode.
  const std::size_t blocks = decoder_.model() == VelodyneModel::kHdl64e ? kBlocks : (dual ? kBlocks / 2 : kBlocks);
  const double period = velodyne_block_offset_us(decoder_.model(), blocks);
  std::size_t missing = 0;
  if (last_packet_us_ && period > 0 && packet_us - *last_packet_us_ > 1.5 * period) {
    missing = static_cast<std::size_t>(std::lround((packet_us - *last_packet_us_) / period)) - 1;
    missing_packets_ += missing;
    if (current_) current_->missing_packets += missing;  // the frame the gap fell in (or ended)
  }
  last_packet_us_ = packet_us;
  return missing;
}

void VelodyneFrameAssembler::begin(double time_s, std::size_t block, std::vector<VelodyneFrame>& done) {
  // Room for as many points as the last frame had (and a little more): a
  // sweep's 100 000+ points grown one by one cost more than decoding them.
  const std::size_t expected = current_ ? current_->cloud.size() + current_->cloud.size() / 16 : 0;
  if (current_) done.push_back(std::move(*current_));
  current_ = VelodyneFrame{};
  current_->cloud.reserve(expected);
  current_->time = time_s;
  ++frames_begun_;
  last_start_block_ = block;
}

void VelodyneFrameAssembler::add(std::span<const std::uint8_t> packet, std::vector<VelodyneFrame>& done,
                                 std::size_t first_block) {
  if (!check_velodyne_packet(packet).empty()) {
    ++bad_packets_;
    return;
  }
  const bool dual = decoder_.dual(packet);
  const double packet_us = unwrap_us(velodyne_tail(packet).timestamp_us);
  const std::size_t gap = count_gap(packet_us, dual);
  returns_.clear();
  decoder_.decode(packet, returns_);
  std::size_t next_return = 0;
  bool counted = false;
  for (std::size_t b = first_block; b < kBlocks; ++b) {
    const auto relative = static_cast<std::uint16_t>((velodyne_block_azimuth(packet, b) + kFullTurn - cut_) % kFullTurn);
    const bool wrapped = last_relative_azimuth_ && relative < *last_relative_azimuth_;
    last_relative_azimuth_ = relative;
    if (!current_ || wrapped) {
      const std::size_t firing = decoder_.model() == VelodyneModel::kHdl64e ? b : (dual ? b / 2 : b);
      begin((packet_us + velodyne_block_offset_us(decoder_.model(), firing)) * 1e-6, b, done);
      // A frame begun right after a gap may lack its first packets as well (where the gap lay is not known).
      if (b == first_block) current_->missing_packets += gap;
      counted = false;
    }
    if (!counted) {
      ++current_->packets;
      counted = true;
    }
    while (next_return < returns_.size() && returns_[next_return].block < b) ++next_return;  // blocks skipped
    for (; next_return < returns_.size() && returns_[next_return].block == b; ++next_return) {
      const VelodyneReturn& r = returns_[next_return];
      LabelledCloud& c = current_->cloud;
      c.points.push_back(r.point);
      c.remission.push_back(r.intensity);
      c.label.push_back(0);
      c.instance.push_back(0);
      c.ring.push_back(r.ring);
      c.time.push_back(static_cast<float>((packet_us * 1e-6 + r.time_offset) - current_->time));
    }
  }
}

std::optional<VelodyneFrame> VelodyneFrameAssembler::finish() {
  std::optional<VelodyneFrame> out = std::move(current_);
  current_.reset();
  return out;
}

}  // namespace saloam
