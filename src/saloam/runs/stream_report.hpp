#pragma once
// What a live source received, served and dropped (FrameSource::stream_stats),
// reported at the end of every run that takes one (odom, slam, localize): one
// log line, and summary.json's "live" entry.

#include <nlohmann/json.hpp>

#include "saloam/io/frame_source.hpp"

namespace saloam {

/// The log line and summary["live"] for a live source; nothing for a recorded one.
void report_stream(const FrameSource& source, nlohmann::json& summary);

/// After a live run's frame loop: Ctrl-C ends a live stream as the end of a
/// file ends a recording, so it is taken as handled (clear_stop) and the run
/// finishes as a whole run (a SLAM run's map and saved map too, exit status
/// 0); summary.json's live.ended_by says "Ctrl-C". Nothing for a recorded source.
void end_live_stream(const SourceInfo& info);

}  // namespace saloam
