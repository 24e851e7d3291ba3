#include "saloam/io/frame_source.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace saloam {
namespace {

template <class T>
std::vector<T> slice(const std::vector<T>& all, std::size_t first, std::size_t end) {
  return std::vector<T>(all.begin() + static_cast<std::ptrdiff_t>(first), all.begin() + static_cast<std::ptrdiff_t>(end));
}

template <class T>
std::optional<std::vector<T>> slice(const std::optional<std::vector<T>>& all, std::size_t first, std::size_t end) {
  if (!all) return std::nullopt;
  return slice(*all, first, end);
}

}  // namespace

FrameRangeSource::FrameRangeSource(std::unique_ptr<FrameSource> inner, const FrameRange& range)
    : inner_(std::move(inner)), info_(inner_->info()) {
  const auto [first, end] = range.clip(inner_->size());
  first_ = first;
  info_.times = slice(info_.times, first, end);
  info_.camera_poses = slice(info_.camera_poses, first, end);
  info_.sensor_camera_poses = slice(info_.sensor_camera_poses, first, end);
  info_.first_frame += first;
}

LabelledCloud FrameRangeSource::scan(std::size_t i) {
  if (i >= size()) throw std::out_of_range(fmt::format("{}: frame {} of a range of {}", info_.name, i, size()));
  if (!info_.rereadable) {
    for (; dropped_ < first_; ++dropped_) (void)inner_->scan(dropped_);
  }
  return inner_->scan(first_ + i);
}

}  // namespace saloam
