#include "saloam/eval/evaluation_report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>

#include "saloam/core/error.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam {
namespace {

/// NaN/Inf become JSON null (nlohmann would do the same, made explicit here).
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

constexpr std::array<const char*, 3> kAxisNames{"x", "y", "z"};

nlohmann::json kitti_json(const KittiMetrics& kitti) {
  nlohmann::json j;
  j["t_err_percent"] = number(kitti.t_err_percent);
  j["r_err_deg_per_100m"] = number(kitti.r_err_deg_per_100m);
  j["segments"] = kitti.segments;
  j["per_length"] = nlohmann::json::array();
  for (const auto& l : kitti.per_length) {
    j["per_length"].push_back({{"length_m", l.length_m},
                               {"t_err_percent", number(l.t_err_percent)},
                               {"r_err_deg_per_100m", number(l.r_err_deg_per_100m)},
                               {"segments", l.segments}});
  }
  return j;
}

/// ATE statistics (aligned and unaligned), the alignment transform, and per pose the aligned errors.
nlohmann::json ate_json(const AteMetrics& ate, bool per_frame) {
  nlohmann::json j;
  j["alignment"] = alignment_name(ate.alignment);
  for (const auto& [suffix, s] : {std::pair{"aligned", ate.aligned}, std::pair{"unaligned", ate.unaligned}}) {
    j[fmt::format("rmse_{}", suffix)] = number(s.rmse);
    j[fmt::format("mean_{}", suffix)] = number(s.mean);
    j[fmt::format("median_{}", suffix)] = number(s.median);
    j[fmt::format("max_{}", suffix)] = number(s.max);
  }
  j["scale"] = ate.transform.scale;
  nlohmann::json rotation = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    rotation.push_back({ate.transform.rotation(r, 0), ate.transform.rotation(r, 1), ate.transform.rotation(r, 2)});
  }
  j["rotation"] = rotation;
  j["translation"] = {ate.transform.translation.x(), ate.transform.translation.y(), ate.transform.translation.z()};
  if (per_frame) j["per_pose_aligned_m"] = ate.aligned_errors;
  return j;
}

nlohmann::json ate_axes_json(const AteAxes& axes) {
  return {{"sideways_m", number(axes.sideways_m)},
          {"vertical_m", number(axes.vertical_m)},
          {"forward_m", number(axes.forward_m)}};
}

nlohmann::json rpe_json(const RpeMetrics& rpe, bool per_frame) {
  nlohmann::json j;
  j["delta"] = rpe.delta;
  j["trans_rmse_m"] = number(rpe.trans.rmse);
  j["trans_mean_m"] = number(rpe.trans.mean);
  j["trans_median_m"] = number(rpe.trans.median);
  j["trans_max_m"] = number(rpe.trans.max);
  j["rot_rmse_deg"] = number(rpe.rot.rmse);
  j["rot_mean_deg"] = number(rpe.rot.mean);
  j["rot_median_deg"] = number(rpe.rot.median);
  j["rot_max_deg"] = number(rpe.rot.max);
  if (per_frame) {
    j["per_frame_trans_m"] = rpe.trans_errors_m;
    j["per_frame_rot_deg"] = rpe.rot_errors_deg;
  }
  return j;
}

nlohmann::json bias_json(const ScaleBias& bias) {
  nlohmann::json j;
  j["delta"] = bias.delta;
  j["windows"] = bias.windows;
  j["length_m"] = number(bias.length_m);
  j["forward_percent"] = number(bias.forward_percent);
  j["lateral_percent"] = number(bias.lateral_percent);
  j["vertical_percent"] = number(bias.vertical_percent);
  j["body_up"] = {bias.body_up.x(), bias.body_up.y(), bias.body_up.z()};
  return j;
}

}  // namespace

std::string format_metric(double value, int decimals) {
  return std::isfinite(value) ? fmt::format("{:.{}f}", value, decimals) : "n/a";
}

nlohmann::json evaluation_to_json(const TrajectoryEvaluation& ev, const EvaluationLabels& labels, bool per_frame) {
  nlohmann::json j;
  j["gt"] = labels.gt_name;
  j["est"] = labels.est_name;
  j["alignment"] = alignment_name(ev.ate.alignment);
  j["num_poses"] = ev.evaluated_poses;
  j["gt_poses"] = ev.gt_poses;
  j["est_poses"] = ev.est_poses;
  j["gt_length_m"] = number(ev.gt_length_m);
  j["kitti"] = kitti_json(ev.kitti);
  j["ate"] = ate_json(ev.ate, per_frame);
  j["ate"]["per_axis_rmse"] = ate_axes_json(ev.ate_axes);
  j["rpe"] = rpe_json(ev.rpe, per_frame);
  j["scale_bias"] = bias_json(ev.bias);
  j["warnings"] = ev.warnings;
  return j;
}

void write_evaluation_json(const std::filesystem::path& file, const TrajectoryEvaluation& evaluation,
                           const EvaluationLabels& labels) {
  AtomicFile out(file);
  out.stream() << evaluation_to_json(evaluation, labels).dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
               << '\n';
  out.commit();
}

void print_evaluation_markdown(std::ostream& out, const TrajectoryEvaluation& ev, const EvaluationLabels& labels) {
  out << "## Trajectory evaluation";
  if (!labels.est_name.empty() || !labels.gt_name.empty()) {
    out << ": " << (labels.est_name.empty() ? "estimate" : labels.est_name) << " vs "
        << (labels.gt_name.empty() ? "ground truth" : labels.gt_name);
  }
  out << "\n\n";
  const std::string align = alignment_name(ev.ate.alignment);
  out << "| metric | value |\n|---|---|\n";
  out << fmt::format("| poses evaluated | {} (ground truth {}, estimate {}) |\n", ev.evaluated_poses, ev.gt_poses,
                     ev.est_poses);
  out << fmt::format("| ground-truth path length | {} m |\n", format_metric(ev.gt_length_m, 1));
  out << fmt::format("| KITTI translation error | {} % |\n", format_metric(ev.kitti.t_err_percent, 5));
  out << fmt::format("| KITTI rotation error | {} deg/100 m |\n", format_metric(ev.kitti.r_err_deg_per_100m, 5));
  out << fmt::format("| KITTI segments (100..800 m) | {} |\n", ev.kitti.segments);
  if (ev.ate.alignment != Alignment::kNone) {
    out << fmt::format("| ATE RMSE, {}-aligned | {} m |\n", align, format_metric(ev.ate.aligned.rmse, 6));
    out << fmt::format("| ATE mean / median / max, {}-aligned | {} / {} / {} m |\n", align,
                       format_metric(ev.ate.aligned.mean, 4), format_metric(ev.ate.aligned.median, 4), format_metric(ev.ate.aligned.max, 4));
  }
  if (ev.ate.alignment == Alignment::kSim3) out << fmt::format("| Sim(3) scale | {} |\n", format_metric(ev.ate.transform.scale, 6));
  out << fmt::format("| ATE RMSE, unaligned | {} m |\n", format_metric(ev.ate.unaligned.rmse, 6));
  out << fmt::format("| ATE mean / median / max, unaligned | {} / {} / {} m |\n", format_metric(ev.ate.unaligned.mean, 4),
                     format_metric(ev.ate.unaligned.median, 4), format_metric(ev.ate.unaligned.max, 4));
  out << fmt::format("| RPE ({}-frame) translation RMSE | {} m |\n", ev.rpe.delta, format_metric(ev.rpe.trans_rmse_m, 6));
  out << fmt::format("| RPE ({}-frame) rotation RMSE | {} deg |\n", ev.rpe.delta, format_metric(ev.rpe.rot_rmse_deg, 6));
  out << fmt::format("| ATE RMSE sideways / vertical / forward (sensor frame), {} | {} / {} / {} m |\n",
                     ev.ate.alignment == Alignment::kNone ? "unaligned" : align + "-aligned",
                     format_metric(ev.ate_axes.sideways_m, 4), format_metric(ev.ate_axes.vertical_m, 4),
                     format_metric(ev.ate_axes.forward_m, 4));
  out << fmt::format("| scale bias forward / lateral / vertical ({}-frame) | {} / {} / {} % |\n", ev.bias.delta,
                     format_metric(ev.bias.forward_percent, 4), format_metric(ev.bias.lateral_percent, 4),
                     format_metric(ev.bias.vertical_percent, 4));

  out << "\n| segment length [m] | t_err [%] | r_err [deg/100 m] | segments |\n|---|---|---|---|\n";
  for (const auto& l : ev.kitti.per_length) {
    out << fmt::format("| {:.0f} | {} | {} | {} |\n", l.length_m, format_metric(l.t_err_percent, 5),
                       format_metric(l.r_err_deg_per_100m, 5), l.segments);
  }
  for (const auto& w : ev.warnings) out << "\n> warning: " << w << '\n';
}

std::pair<int, int> top_down_axes(const std::vector<Pose>& gt) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : gt) {
    lo = lo.cwiseMin(p.translation());
    hi = hi.cwiseMax(p.translation());
  }
  const Eigen::Vector3d extent = gt.empty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(hi - lo);
  // Drop the axis with the smallest extent (ties: drop the later axis, so a
  // motionless or straight path keeps x and y).
  int smallest = 2;
  for (int a = 1; a >= 0; --a) {
    if (extent[a] < extent[smallest]) smallest = a;
  }
  if (smallest == 0) return {1, 2};
  if (smallest == 1) return {0, 2};
  return {0, 1};
}

void plot_evaluation(const std::filesystem::path& file, const std::vector<Pose>& gt, const std::vector<Pose>& est,
                     const TrajectoryEvaluation& ev, const EvaluationLabels& labels) {
  const std::size_t n = std::min({gt.size(), est.size(), ev.ate.aligned_errors.size()});
  const std::vector<Pose> gt_common(gt.begin(), gt.begin() + static_cast<std::ptrdiff_t>(n));
  const auto [ax, ay] = top_down_axes(gt_common);

  std::vector<Eigen::Vector2d> gt_xy, est_xy, all;
  gt_xy.reserve(n);
  est_xy.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d g = gt[i].translation();
    const Eigen::Vector3d e = ev.ate.transform.apply(Eigen::Vector3d(est[i].translation()));
    gt_xy.emplace_back(g[ax], g[ay]);
    est_xy.emplace_back(e[ax], e[ay]);
  }
  all = gt_xy;
  all.insert(all.end(), est_xy.begin(), est_xy.end());

  const std::vector<double> errors(ev.ate.aligned_errors.begin(),
                                   ev.ate.aligned_errors.begin() + static_cast<std::ptrdiff_t>(n));
  const double vmax = std::max(1e-6, errors.empty() ? 0.0 : *std::max_element(errors.begin(), errors.end()));

  Plot plot(1100, 950);
  plot.set_margins(80, 100, 56, 60);
  plot.fit_range(all, true);
  const std::string align = ev.ate.alignment == Alignment::kNone ? "unaligned" : alignment_name(ev.ate.alignment);
  plot.set_title(fmt::format("KITTI t_err {} %  r_err {} deg/100m  |  ATE RMSE {} m ({})  |  RPE {} m",
                             format_metric(ev.kitti.t_err_percent, 3), format_metric(ev.kitti.r_err_deg_per_100m, 3),
                             format_metric(ev.ate.aligned.rmse, 3), align, format_metric(ev.rpe.trans_rmse_m, 4)));
  plot.set_labels(fmt::format("{} [m]", kAxisNames[static_cast<std::size_t>(ax)]),
                  fmt::format("{} [m]", kAxisNames[static_cast<std::size_t>(ay)]));

  const Rgb grey{150, 150, 150};
  plot.line(gt_xy, grey, 4.0);
  plot.colored_line(est_xy, errors, 0.0, vmax, 2.0);
  if (!gt_xy.empty()) {
    plot.marker(gt_xy.front(), {0, 0, 0}, 5.0, "start");
    if ((gt_xy.back() - gt_xy.front()).norm() > 1e-3) plot.marker(gt_xy.back(), {0, 0, 0}, 3.5, "end");
  }

  const std::string est_name = labels.est_name.empty() ? "estimate" : labels.est_name;
  const std::string gt_name = labels.gt_name.empty() ? "ground truth" : labels.gt_name;
  const std::string est_label = ev.ate.alignment == Alignment::kNone
                                    ? fmt::format("{} (unaligned), colour = ATE", est_name)
                                    : fmt::format("{} ({}-aligned), colour = ATE", est_name, align);
  plot.legend({{fmt::format("ground truth: {}", gt_name), grey}, {est_label, turbo(0.75)}});
  plot.colorbar(0.0, vmax, "ATE [m]");
  plot.save_png(file);
}

}  // namespace saloam
