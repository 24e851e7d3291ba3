// `saloam render`: pictures of a sequence (top-down labelled map with the
// trajectory, and a range image of one scan), to judge data by eye.

#include <iostream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/sim/lidar.hpp"
#include "saloam/sim/render.hpp"
#include "saloam/viz/range_image.hpp"

namespace saloam::cli {
namespace {

struct RenderArgs {
  std::string sequence;
  std::string out;
  std::size_t frame = 0;
  MapRenderOptions map;  ///< --resolution, --frame-step and every default
  std::string labels_dir;
};

int run_render(const RenderArgs& args) {
  PathRules().input("sequence", args.sequence).output("--out", args.out, OutputUse::kFolder).check();
  const std::filesystem::path out(args.out);
  create_folder(out);
  SequenceOptions seq_options;
  if (!args.labels_dir.empty()) seq_options.labels_dir = args.labels_dir;
  const SequenceReader reader(args.sequence, seq_options);
  if (args.frame >= reader.size()) {
    throw InputError(args.sequence, fmt::format("--frame {} out of range: the sequence has {} scans", args.frame, reader.size()));
  }
  const auto range_png = out / fmt::format("range_{}.png", frame_name(args.frame));
  render_range_image(reader.load_scan(args.frame), range_png, LidarModel::hdl64e().elevation_deg);
  std::cout << "range image: " << range_png.string() << '\n';

  MapRenderOptions options = args.map;
  options.show_progress = spdlog::get_level() <= spdlog::level::info;
  const auto map_png = out / "map.png";
  const MapRenderStats s = render_map(reader, map_png, options);
  std::cout << fmt::format("map: {} ({}x{} px, {:.2f} m/px, {} scans, {} points)\n", map_png.string(), s.width, s.height,
                           s.metres_per_pixel, s.scans_used, s.points_drawn);
  return 0;
}

const CommandRegistration kRegistration{Command{
    "render", "Draw a sequence: top-down labelled map with the trajectory, and a range image of one scan", 80,
    [](CLI::App& app) {
      auto args = std::make_shared<RenderArgs>();
      app.add_option("sequence", args->sequence, "Sequence folder (velodyne/, labels/, poses.txt, calib.txt)")->required();
      app.add_option("--out", args->out, "Output folder for map.png and range_NNNNNN.png")->required();
      app.add_option("--frame", args->frame, "Scan shown as a range image (default 0)")->check(non_negative_integer());
      app.add_option("--resolution", args->map.picture.metres_per_pixel, "Map metres per pixel")
          ->check(positive_number())
          ->capture_default_str();
      app.add_option("--frame-step", args->map.frame_step, "Accumulate every n-th scan (default 0: about 300 scans)")
          ->check(non_negative_integer());
      app.add_option("--labels-dir", args->labels_dir, "Labels folder instead of labels/ (e.g. labels_gt or predictions)");
      return [args] { return run_render(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
