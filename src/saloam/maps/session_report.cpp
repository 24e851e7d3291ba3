#include "saloam/maps/session_report.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "saloam/core/lie.hpp"

#include "saloam/core/output_file.hpp"

namespace saloam {

void write_cross_session_csv(const std::filesystem::path& file, const JoinedMaps& joined) {
  AtomicFile out_file(file);
  std::ostream& out = out_file.stream();
  out << "joining_keyframe,base_keyframe,travelled_m,score,inlier_fraction,mean_residual_m,accepted,reason,outcome,"
         "pose_3x4\n";
  for (const CrossSessionRecord& r : joined.records) {
    double v[12];
    pose_to_3x4(r.pose, v);
    out << fmt::format("{},{},{:.2f},{:.4f},{:.4f},{:.4f},{:d},\"{}\",{},{:.6f}\n", r.query, r.match, r.travelled,
                       r.score.score, r.verification.inlier_fraction, r.verification.mean_residual,
                       r.verification.accepted, r.verification.reason, r.outcome, fmt::join(v, " "));
  }
  out_file.commit();
}

nlohmann::json join_summary_json(const JoinedMaps& joined) {
  nlohmann::json j;
  j["linked"] = joined.linked_at.has_value();
  j["linked_at_keyframe"] = joined.linked_at ? nlohmann::json(*joined.linked_at) : nlohmann::json(nullptr);
  j["linked_after_m"] = joined.linked_at ? nlohmann::json(joined.linked_after) : nlohmann::json(nullptr);
  j["cross_session_loops"] = joined.cross_session_loops;
  j["verified"] = joined.records.size();
  j["sessions"] = joined.map.manifest.sessions.size();
  j["optimization"] = {{"usable", joined.optimization.usable},
                       {"iterations", joined.optimization.iterations},
                       {"initial_cost", joined.optimization.initial_cost},
                       {"final_cost", joined.optimization.final_cost}};
  return j;
}

std::string describe_join(const JoinedMaps& joined, const std::string& base) {
  const std::size_t session = joined.map.manifest.sessions.size() - 1;
  if (!joined.linked_at) {
    return fmt::format("session {} never linked to {} ({} candidates and fits verified, none confirmed): it stays a "
                       "component of its own, in its own frame, and the map holds the sessions unlinked", session,
                       base, joined.records.size());
  }
  return fmt::format("session {} was a component of its own (its own anchor) until its keyframe {} ({:.1f} m along "
                     "its path), where verified fits linked it to {}; {} cross-session loop edges, one pose graph "
                     "over both (optimisation {}), its poses in {}'s frame", session, *joined.linked_at,
                     joined.linked_after, base, joined.cross_session_loops,
                     joined.optimization.usable ? "usable" : "NOT usable", base);
}

}  // namespace saloam
