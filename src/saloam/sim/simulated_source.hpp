#pragma once
// The simulator as a FrameSource (io/frame_source.hpp): a simulated sequence
// streamed to a run in memory, rendered ahead on a worker thread, and
// written to disk only when asked.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "saloam/core/output_folder.hpp"
#include "saloam/core/types.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/sim/label_noise.hpp"
#include "saloam/sim/simulator.hpp"

namespace saloam {

/// Streams a SimulatedSequence: a worker thread renders up to `lookahead`
/// frames ahead of the consumer (the simulator's ray casting is the costly
/// part; it runs beside the consumer on another core). With `keep_folder`
/// the frames are also written there as a sequence folder, exactly as
/// `saloam simulate` would write them (trimmed to the frames rendered when
/// the run stops early), the folder held as simulate holds it
/// (open_sequence_output()). The worker stops when the source is destroyed; an
/// error on the worker is rethrown by scan().
class SimulatedSource final : public FrameSource {
 public:
  SimulatedSource(const SimulatedSequence& sequence, std::size_t lookahead = 8,
                  std::optional<std::filesystem::path> keep_folder = std::nullopt);
  ~SimulatedSource() override;
  SimulatedSource(const SimulatedSource&) = delete;
  SimulatedSource& operator=(const SimulatedSource&) = delete;

  [[nodiscard]] const SourceInfo& info() const override { return info_; }
  LabelledCloud scan(std::size_t i) override;

  /// Scores of the emulated network labels over the frames rendered so far
  /// (noisy-label sequences); call after the run.
  [[nodiscard]] SegmentationScore label_score() const;
  [[nodiscard]] std::size_t frames_rendered() const;

 private:
  void render_ahead();
  void keep(std::size_t k, const SimulatedFrame& frame) const;
  void finish_kept_folder(std::size_t frames) const;

  const SimulatedSequence& sequence_;
  const SourceInfo info_;
  const std::size_t lookahead_;
  const std::optional<std::filesystem::path> keep_folder_;
  std::unique_ptr<OutputFolder> kept_;  ///< the keep folder's lock and record

  mutable std::mutex mutex_;
  std::condition_variable frame_ready_, slot_free_;
  std::deque<LabelledCloud> queue_;  ///< frames next_ ... next_ + queue_.size() - 1
  std::size_t next_ = 0;             ///< the frame scan() must be asked for next
  std::size_t rendered_ = 0;
  bool stopping_ = false;
  std::exception_ptr error_;
  SegmentationScore score_;
  std::thread worker_;
};

}  // namespace saloam
