#include "saloam/runs/stream_report.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/profiling.hpp"

namespace saloam {
namespace {

nlohmann::json stream_json(const StreamStats& s) {
  nlohmann::json j{{"address", s.address},
                   {"packets", s.packets},
                   {"packet_counts", s.packet_counts},
                   {"frames_made", s.frames_made},
                   {"frames_served", s.frames_served},
                   {"frames_dropped", s.frames_dropped},
                   {"frames_out_of_order", s.frames_out_of_order},
                   {"frames_incomplete", s.frames_incomplete},
                   {"frames_unread", s.frames_unread},
                   {"ended_by", s.ended_by}};
  if (!s.latency_ms.empty()) {
    const Summary latency = summarize(s.latency_ms);
    j["latency_ms"] = {{"what", "from the packet that completed a frame to its pose written"},
                       {"frames", s.latency_ms.size()},
                       {"median", latency.median},
                       {"p95", latency.p95},
                       {"max", latency.max}};
  }
  return j;
}

std::string latency_text(const std::vector<double>& latency_ms) {
  if (latency_ms.empty()) return "";
  const Summary latency = summarize(latency_ms);
  return fmt::format("; packet to pose {:.0f} ms median, {:.0f} ms at the 95th percentile", latency.median,
                     latency.p95);
}

}  // namespace

void end_live_stream(const SourceInfo& info) {
  if (info.live && stop_requested()) clear_stop();
}

void report_stream(const FrameSource& source, nlohmann::json& summary) {
  const std::optional<StreamStats> stats = source.stream_stats();
  if (!stats) return;
  const StreamStats& s = *stats;
  spdlog::info("{}: {} frames made, {} run, {} dropped (the run fell behind), {} incomplete (packets lost), {} out "
               "of order, {} left unread; ended by {}; {} datagrams ({}){}",
               s.address, s.frames_made, s.frames_served, s.frames_dropped, s.frames_incomplete,
               s.frames_out_of_order, s.frames_unread,
               s.ended_by.empty() ? "the run" : s.ended_by, s.packets, s.packet_counts, latency_text(s.latency_ms));
  summary["live"] = stream_json(s);
}

}  // namespace saloam
