#pragma once
// Place-recognition evaluation over a frame source with ground truth, of one
// PlaceRecognizer (SGPR, Scan Context, their hybrid or Semantic Scan
// Context: the loop detectors of `saloam slam`), by SGPR's protocol: every
// frame against the earlier frames except the most recent ones; a match
// within 3 m, a non-match beyond 20 m. Writes into the output folder:
//   pr_curve.csv, pr_curve.png  the precision-recall curve
//   summary.json                max F1, precision at full recall, recall at
//                               full precision, the protocol, timings
//   graphs/NNNNNN.json          with save_graphs (SGPR): every frame's graph
//   pair_scores.csv             with save_scores: every evaluated pair's score
// Frames are named by their number in the source's folder (first_frame + i).
// The folder is held by the run alone and cleared of an earlier run's files
// (runs/output_folder.hpp); summary.json is written last.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "saloam/core/config.hpp"
#include "saloam/io/frame_source.hpp"
#include "saloam/place/place_recognition.hpp"
#include "saloam/place/semantic_graph.hpp"

namespace saloam {

struct PlaceEvalOptions {
  std::string method = "sgpr";     ///< sgpr, scancontext, hybrid or ssc (parse_place_detector)
  std::filesystem::path model;     ///< SGPR weights, for the methods that use SGPR
  PlaceEvalConfig protocol;
  GraphBuilderConfig graph;        ///< how SGPR's graphs are built (use_instances: --no-instances)
  /// SGPR: read every frame's graph from here (an earlier run's graphs/)
  /// instead of building it, to compare models on the very same graphs.
  std::optional<std::filesystem::path> graphs;
  bool save_graphs = false;
  bool save_scores = false;
  std::string labels = "labels/";  ///< where the labels came from, for summary.json
  bool show_progress = true;

  /// ConfigError for a protocol whose match and non-match distances overlap,
  /// or `graphs` with a method that cannot use them; InputError when the
  /// graphs folder does not exist.
  void check() const;
};

struct PlaceEvalResult {
  PrSummary summary;
  std::size_t frames = 0;
  std::vector<std::string> left_out;  ///< why each unreadable frame was left out of the evaluation
  std::size_t pairs = 0;
  double mean_nodes = 0;              ///< SGPR: mean graph size
  double describe_ms_per_frame = 0;   ///< descriptor time of one frame on one core
  double describe_wall_s = 0;
  double score_wall_s = 0;
  bool interrupted = false;           ///< Ctrl-C: nothing was written
};

/// What run_place_eval() may write into its folder (besides graphs/).
inline const std::vector<std::string> kPlaceEvalOutputs{"pr_curve.csv", "pr_curve.png", "summary.json",
                                                        "pair_scores.csv"};

/// Evaluates `options.method` over every frame of `source`, writing into
/// `out_dir` (open_run_folder(); ConfigError when options.graphs lies in it). Distances are between LiDAR positions (the ground
/// truth through the source's Tr; as given when it has none). InputError
/// when the source has no ground truth, or no labels for a method that needs
/// them; a frame that cannot be read is left out with a warning.
PlaceEvalResult run_place_eval(FrameSource& source, const SaloamConfig& config, const PlaceEvalOptions& options,
                               const std::filesystem::path& out_dir);

}  // namespace saloam
