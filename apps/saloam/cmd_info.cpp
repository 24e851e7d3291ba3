// `saloam info PATH`: what a scan source holds before anything runs on it:
// format, frames, rate, duration, point fields, beams, the sensor a run would
// take (--sensor: the guess from the first scan by default), labels,
// calibration, reference poses, and the reader's notes (where times,
// calibration and reference come from, the intensity range found or given).

#include <iostream>

#include <fmt/format.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/sources/sequence_summary.hpp"

namespace saloam::cli {
namespace {

struct InfoArgs {
  SourceArgs source;
  std::size_t scans = 3;
};

std::string beams_text(const SequenceSummary& s) {
  if (!s.lasers) return "unknown";
  const std::string about = s.lasers->exact() ? "" : "about ";
  return fmt::format("{}{} ({})", about, s.lasers->count(), beam_method_text(s.lasers->method));
}

std::string sensor_text(const SensorChoice& sensor) {
  return sensor.profile ? fmt::format("{}, {}", sensor.profile->title(), sensor.how) : sensor.how;
}

void print_summary(const FrameSource& source, const SequenceSummary& s, const SensorChoice& sensor, bool format_given) {
  std::cout << source.info().name << '\n';
  std::cout << fmt::format("  format:      {}{}\n", s.format, format_given ? "" : " (detected)");
  const double duration = s.last_time - s.first_time;
  std::cout << fmt::format("  frames:      {}, {:.3f} s from {:.6f} to {:.6f} s\n", s.frames, duration, s.first_time, s.last_time);
  if (s.median_interval > 0.0) {
    std::cout << fmt::format("  rate:        {:.2f} Hz (median interval {:.4f} s)\n", 1.0 / s.median_interval, s.median_interval);
  }
  std::cout << fmt::format("  fields:      {}\n", s.fields);
  std::cout << fmt::format("  points:      {:.0f} per scan (mean of {} scans read)\n", s.mean_points, s.scans_read);
  std::cout << fmt::format("  beams:       {}\n", beams_text(s));
  std::cout << fmt::format("  sensor:      {}\n", sensor_text(sensor));
  std::cout << fmt::format("  point times: {}\n", s.per_point_times ? fmt::format("yes, spanning {:.4f} s in the first scan", s.sweep_seconds)
                                                                     : std::string("no (de-skew uses the sweep model)"));
  std::cout << fmt::format("  labels:      {}\n", s.labels ? "yes" : "no");
  std::cout << fmt::format("  reference:   {}\n", s.reference_poses ? fmt::format("{} poses", *s.reference_poses) : std::string("none"));
  for (const auto& note : s.notes) std::cout << "  - " << note << '\n';
}

int run_info(const InfoArgs& args) {
  SaloamConfig config;
  SensorChoice sensor;
  const auto source = args.source.open(false, config, &sensor);
  const SequenceSummary summary = summarize(*source, args.scans);
  print_summary(*source, summary, sensor, args.source.format != "auto");
  return 0;
}

const CommandRegistration kRegistration{Command{
    "info", "What a scan source holds: format, frames, rate, fields, beams, duration, calibration, reference", 15,
    [](CLI::App& app) {
      auto args = std::make_shared<InfoArgs>();
      args->source.add_with_no_calib_to(app);
      app.add_option("--scans", args->scans, "Scans to read for fields, points and beams (default 3)")
          ->check(positive_number());
      return [args] { return run_info(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
