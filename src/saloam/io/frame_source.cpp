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

std::optional<SourceFrame> FrameSource::next_frame(std::size_t i) {
  if (i >= size()) return std::nullopt;
  return SourceFrame{scan(i), info().times.at(i)};
}

FrameRangeSource::FrameRangeSource(std::unique_ptr<FrameSource> inner, const FrameRange& range)
    : inner_(std::move(inner)), info_(inner_->info()) {
  if (info_.live) {  // nothing to clip to (FrameRange::parse refused empty ranges): applied as frames come
    first_ = range.first;
    end_ = range.end;
    return;
  }
  const auto [first, end] = range.clip(inner_->size());
  first_ = first;
  end_ = end;
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

std::optional<SourceFrame> FrameRangeSource::next_frame(std::size_t i) {
  if (!info_.live) return FrameSource::next_frame(i);
  if (i >= end_ - first_) {
    inner_->close_stream();
    return std::nullopt;
  }
  for (; dropped_ < first_; ++dropped_) {
    if (!inner_->next_frame(dropped_)) return std::nullopt;
  }
  return inner_->next_frame(first_ + i);
}

}  // namespace saloam
