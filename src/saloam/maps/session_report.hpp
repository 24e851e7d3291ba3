#pragma once
// What joining a session to a map did (session_join.hpp), for `saloam slam
// --map` and `saloam merge`: every verified cross-session candidate and
// confirming fit as a CSV, the summary as JSON and as one sentence.

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "saloam/maps/session_join.hpp"

namespace saloam {

/// cross_session.csv: per record the joining and base keyframes, the path
/// [m], the score, the fit (inlier fraction, mean residual [m]), the outcome
/// and T_base<-query (3x4 row-major); written atomically.
void write_cross_session_csv(const std::filesystem::path& file, const JoinedMaps& joined);

/// {"linked", "linked_at_keyframe", "linked_after_m", "cross_session_loops",
///  "verified", "sessions", "optimization": {...}}.
nlohmann::json join_summary_json(const JoinedMaps& joined);

/// A sentence saying whether and where the joining map linked to `base`,
/// and that before the link (or without one) it was a component of its own.
std::string describe_join(const JoinedMaps& joined, const std::string& base);

}  // namespace saloam
