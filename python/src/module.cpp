// The Python module `saloam._saloam` (imported as `saloam`): the library's
// odometry, SLAM, sources, saved maps, merging, evaluation and segmentation
// for numpy arrays (docs/python.md). Everything calls the same functions as
// the command line, so the results are the same; the GIL is released while
// the C++ works, errors of the library come out as saloam.InputError /
// saloam.ConfigError with the CLI's messages.

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <spdlog/spdlog.h>

#include "arrays.hpp"
#include "command.hpp"
#include "config_dict.hpp"
#include "program.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/path_rules.hpp"
#include "saloam/eval/evaluation_report.hpp"
#include "saloam/eval/trajectory_metrics.hpp"
#include "saloam/io/trajectory_io.hpp"
#include "saloam/maps/map_format.hpp"
#include "saloam/maps/prior_map.hpp"
#include "saloam/maps/session_join.hpp"
#include "saloam/maps/session_report.hpp"
#include "saloam/maps/slam_map.hpp"
#include "saloam/odometry/semantic_odometry.hpp"
#include "saloam/place/place_recognizer.hpp"
#include "saloam/runs/localize_run.hpp"
#include "saloam/runs/slam_run.hpp"
#include "saloam/runs/trajectory_pairing.hpp"
#include "saloam/sources/source_options.hpp"
#include "saloam/runs/trajectory_writer.hpp"
#include "saloam/segmentation/segmenter.hpp"
#include "saloam/segmentation/segmenter_spec.hpp"
#include "saloam/slam/slam_system.hpp"

namespace saloam::python {
namespace {

namespace py = pybind11;
using namespace pybind11::literals;

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

std::string fspath(const py::handle& path) {
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

std::vector<std::string> string_list(const py::handle& value) {
  std::vector<std::string> out;
  if (value.is_none()) return out;
  if (py::isinstance<py::str>(value)) return {value.cast<std::string>()};
  for (const py::handle item : value) out.push_back(item.cast<std::string>());
  return out;
}

// ---------------------------------------------------------------- sources

/// A source opened as `saloam odom SEQ ...` opens it (cli::SourceArgs::open:
/// the reader, the sensor profile, the stages) and the configuration the
/// run would take: `config` has the sensor profile applied.
struct Source {
  std::unique_ptr<FrameSource> source;
  SaloamConfig config;
  std::string sensor;      ///< the profile's name, "" when none
  std::string sensor_how;  ///< how it was chosen
  std::size_t served = 0;  ///< frames a stream has served
  mutable std::mutex mutex;

  [[nodiscard]] const SourceInfo& info() const { return source->info(); }
};

struct FrameIterator {
  std::shared_ptr<Source> source;
  std::size_t next = 0;
};

py::object frame_type() { return py::module_::import("saloam._saloam").attr("Frame"); }

/// Frame i as a Frame tuple, or None when the source has none: i past the
/// end, or a live stream ended (idle for its timeout). A stream (a live
/// source, a recording read once) serves its frames in order, once each.
py::object read_frame(Source& s, std::size_t i) {
  std::optional<SourceFrame> frame;
  {
    py::gil_scoped_release release;
    std::lock_guard lock(s.mutex);
    if (s.info().rereadable) {
      if (i < s.info().size()) frame = SourceFrame{s.source->scan(i), s.info().times[i]};
    } else {
      if (i != s.served) throw py::index_error("a stream serves its frames once each, in order");
      frame = s.source->next_frame(i);
      if (frame) ++s.served;
    }
  }
  if (!frame) return py::none();
  const py::tuple arrays = cloud_to_arrays(frame->cloud);
  return frame_type()(arrays[0], arrays[1], arrays[2], frame->time, arrays[3]);
}

py::object stream_stats_dict(const StreamStats& s) {
  py::dict d;
  d["address"] = s.address;
  d["packets"] = s.packets;
  d["frames_made"] = s.frames_made;
  d["frames_served"] = s.frames_served;
  d["frames_dropped"] = s.frames_dropped;
  d["frames_out_of_order"] = s.frames_out_of_order;
  d["frames_incomplete"] = s.frames_incomplete;
  d["frames_unread"] = s.frames_unread;
  d["ended_by"] = s.ended_by;
  return d;
}

std::shared_ptr<Source> open_source_py(const py::object& path, const std::string& format, const std::string& sensor,
                                       const std::string& topic, const py::object& labels, const std::string& frames,
                                       bool no_calib, const std::string& intensity_scale, bool semantics, bool segment,
                                       const std::string& segmenter, const std::string& projection,
                                       const py::object& config, const py::object& set, const py::object& metadata,
                                       double idle_timeout, std::size_t queue) {
  cli::SourceArgs args;
  args.path = fspath(path);
  args.format = format;
  args.sensor = sensor;
  args.topic = topic;
  if (!metadata.is_none()) args.metadata = fspath(metadata);
  if (!(idle_timeout >= 0)) throw py::value_error("idle_timeout must be >= 0 seconds");
  if (queue < 1 || queue > 1000) throw py::value_error("queue must hold 1 to 1000 frames");
  args.accepts_live = true;  // udp://[ADDRESS]:PORT: the frames as the sensor's packets arrive
  args.idle_timeout_s = idle_timeout;
  args.queue_frames = queue;
  if (!labels.is_none()) args.labels = fspath(labels);
  args.frames = frames;
  args.no_calib = no_calib;
  args.intensity_scale = intensity_scale;
  args.segment.segment = segment;
  args.segment.segmenter = segmenter;
  args.segment.projection = projection;
  auto s = std::make_shared<Source>();
  s->config = config_from_python(config, string_list(set));
  if (!semantics) s->config.odometry.use_semantics = false;
  cli::SensorChoice chosen;
  {
    py::gil_scoped_release release;
    s->source = args.open(!s->config.odometry.use_semantics, s->config, &chosen);
  }
  if (chosen.profile) s->sensor = chosen.profile->name;
  s->sensor_how = chosen.how;
  return s;
}

// ---------------------------------------------------------------- odometry

// The scan's stamp: `t` when `given`, else 0.1 s after the previous one.
double next_stamp(const std::vector<double>& stamps, bool given, double t) {
  if (given) {
    if (!std::isfinite(t)) throw py::value_error("stamp must be finite");
    if (!stamps.empty() && !(t > stamps.back()))
      throw py::value_error(fmt::format("stamp {} does not follow the previous scan's {}", t, stamps.back()));
    return t;
  }
  return stamps.empty() ? 0.0 : stamps.back() + 0.1;  // a 10 Hz sensor
}

// One scan through `step(cloud, stamp)` of `system` (an odometry or a SLAM):
// the stamp read while the GIL is held, the work done without it, one call
// at a time per object.
template <class System, class Step>
py::array_t<double> register_with(System& system, std::mutex& mutex, const LabelledCloud& cloud,
                                  const py::object& stamp, Step&& step) {
  const bool given = !stamp.is_none();
  const double t = given ? stamp.cast<double>() : 0.0;
  Pose pose;
  {
    py::gil_scoped_release release;
    std::lock_guard lock(mutex);
    pose = step(cloud, next_stamp(system.timestamps(), given, t));
  }
  return pose_to_array(pose);
}

struct Odometry {
  SaloamConfig config;
  std::unique_ptr<SemanticOdometry> odometry;
  std::mutex mutex;

  explicit Odometry(const py::object& config_value, const py::object& set)
      : config(config_from_python(config_value, string_list(set))),
        odometry(std::make_unique<SemanticOdometry>(config.odometry)) {}

  py::array_t<double> register_scan(const py::object& points, const py::object& labels, const py::object& times,
                                    const py::object& stamp, const py::object& rings) {
    return register_with(*odometry, mutex, cloud_from_arrays(points, labels, times, rings), stamp,
                         [this](const LabelledCloud& cloud, double t) { return odometry->register_frame(cloud, t); });
  }

  py::dict local_map() {
    std::lock_guard lock(mutex);
    py::dict out;
    for (const auto& [name, grid] : {std::pair{"edges", &odometry->local_map().edges()},
                                     std::pair{"planars", &odometry->local_map().planars()}}) {
      const auto n = static_cast<py::ssize_t>(grid->size());
      py::array_t<double> points({n, py::ssize_t{3}});
      py::array_t<std::uint16_t> classes(n);
      auto p = points.mutable_unchecked<2>();
      auto c = classes.mutable_unchecked<1>();
      py::ssize_t i = 0;
      grid->for_each([&](const Eigen::Vector3d& q, ClassIndex k) {
        if (i >= n) return;
        p(i, 0) = q.x();
        p(i, 1) = q.y();
        p(i, 2) = q.z();
        c(i) = from_learning_class(k);
        ++i;
      });
      out[py::str(name)] = points;
      out[py::str(std::string(name) + "_labels")] = classes;
    }
    return out;
  }
};

py::dict registration_dict(const SemanticOdometry& odometry) {
  const FrameStats& s = odometry.last_frame_stats();
  return py::dict("ok"_a = s.registration.ok, "correspondences"_a = s.registration.correspondences(),
                  "degenerate_directions"_a = s.registration.degenerate_directions,
                  "smallest_eigenvalue"_a = s.registration.smallest_eigenvalue, "edge_features"_a = s.edge_features,
                  "planar_features"_a = s.planar_features, "map_edge_points"_a = s.map_edge_points,
                  "map_planar_points"_a = s.map_planar_points);
}

// ---------------------------------------------------------------- SLAM

struct Slam {
  SaloamConfig config;
  std::unique_ptr<SlamSystem> slam;
  std::mutex mutex;

  Slam(const py::object& config_value, const py::object& set, const std::string& model)
      : config(config_from_python(config_value, string_list(set))) {
    cli::use_model_option(model, config);
    slam = std::make_unique<SlamSystem>(config, load_loop_network(config));
  }

  py::array_t<double> register_scan(const py::object& points, const py::object& labels, const py::object& times,
                                    const py::object& stamp, const py::object& rings) {
    return register_with(*slam, mutex, cloud_from_arrays(points, labels, times, rings), stamp,
                         [this](const LabelledCloud& cloud, double t) { return slam->process(cloud, t); });
  }

  py::list loops() {
    std::lock_guard lock(mutex);
    py::list out;
    for (const LoopRecord& r : slam->loops()) {
      out.append(py::dict("query_frame"_a = r.query_frame, "match_frame"_a = r.match_frame,
                          "query_keyframe"_a = r.query_keyframe, "match_keyframe"_a = r.match_keyframe,
                          "travelled"_a = r.travelled, "score"_a = r.score.score, "by_proximity"_a = r.by_proximity,
                          "query_offset"_a = r.query_offset,
                          "accepted"_a = r.verification.accepted, "reason"_a = r.verification.reason,
                          "inlier_fraction"_a = r.verification.inlier_fraction,
                          "mean_residual"_a = r.verification.mean_residual,
                          "relative"_a = pose_to_array(r.verification.relative)));
    }
    return out;
  }

  void save_map(const py::object& folder, const std::string& sensor, const py::object& velo_to_cam,
                const std::string& source) {
    const std::filesystem::path path = fspath(folder);
    MapManifest manifest;
    manifest.sensor = sensor;
    manifest.source = source;
    if (!velo_to_cam.is_none()) {
      manifest.camera_frame_outputs = true;
      manifest.velo_to_cam = pose_from_array(velo_to_cam, "velo_to_cam");
    }
    py::gil_scoped_release release;
    std::lock_guard lock(mutex);
    if (slam->keyframes().empty()) throw ConfigError("save_map: no keyframe yet (register scans first)");
    // The map replaces its folder: the scans it was made from (source, when
    // it names a path) may not lie in it.
    PathRules().input("source", std::filesystem::exists(source) ? std::filesystem::path(source) : std::filesystem::path())
        .output("path", path, OutputUse::kReplacedFolder)
        .check();
    check_map_destination(path);
    write_slam_map(path, *slam, config, manifest);
  }
};

// ---------------------------------------------------------------- maps

struct Map {
  std::filesystem::path folder;
  SavedMap saved;

  explicit Map(const py::object& path) : folder(fspath(path)) {
    py::gil_scoped_release release;
    saved = read_map(folder);
  }

  py::dict info() const {
    py::list sessions;
    for (const MapSession& s : saved.manifest.sessions) {
      sessions.append(py::dict("source"_a = s.source, "first_frame"_a = s.first_frame, "keyframes"_a = s.keyframes,
                               "linked"_a = s.linked));
    }
    return py::dict("folder"_a = folder.string(), "keyframes"_a = saved.keyframes.size(),
                    "edges"_a = saved.edges.size(), "loop_edges"_a = saved.manifest.loop_edges,
                    "cross_session_loops"_a = saved.manifest.cross_session_loops, "sessions"_a = sessions,
                    "detector"_a = saved.manifest.detector, "sensor"_a = saved.manifest.sensor,
                    "id"_a = saved.manifest.id);
  }

  py::array_t<double> poses() const {
    std::vector<Pose> poses;
    for (const auto& k : saved.keyframes) poses.push_back(k.pose);
    return poses_to_array(poses);
  }

  py::dict localize(const std::shared_ptr<Source>& source, const py::object& out, const py::object& config_value,
                    const py::object& set, const std::string& model) {
    cli::ConfigOptions options;
    if (!config_value.is_none()) {
      if (!py::isinstance<py::str>(config_value) && !py::hasattr(config_value, "__fspath__"))
        throw py::type_error("Map.localize: config must be a file or a shipped configuration's name");
      options.config_file = fspath(config_value);
    }
    options.overrides = string_list(set);
    SaloamConfig config = options.resolve_for_map(saved.config);
    cli::use_model_option(model, config);
    const std::filesystem::path out_dir = fspath(out);
    py::gil_scoped_release release;
    std::lock_guard lock(source->mutex);
    PathRules()
        .input("map", folder)
        .input("source", source->info().folder.value_or(std::filesystem::path()))
        .input("config", options.config_file.empty() || !std::filesystem::exists(options.config_file)
                             ? std::filesystem::path()
                             : std::filesystem::path(options.config_file))
        .output("out", out_dir, OutputUse::kFolder)
        .check();
    const PriorMap map =
        PriorMap::open(folder, SavedMap(saved), static_cast<std::size_t>(config.localize.cached_keyframes));
    LocalizeRunOptions run_options;
    run_options.show_progress = false;
    const LocalizeRunResult r = run_localize(*source->source, config, map, load_loop_network(config), out_dir, run_options);
    py::gil_scoped_acquire acquire;
    return py::dict("frames"_a = r.frames, "localized"_a = r.localized, "odometry"_a = r.odometry,
                    "unplaced"_a = r.unplaced, "first_placed_m"_a = r.first_placed_m,
                    "first_placed_frame"_a = r.first_placed_frame, "left_map"_a = r.left_map,
                    "reentered"_a = r.reentered, "median_frame_ms"_a = r.median_frame_ms, "files"_a = r.files);
  }
};

py::dict merge_maps(const py::object& map_a, const py::object& map_b, const py::object& out,
                    const py::object& config_value, const py::object& set, const std::string& model) {
  const std::filesystem::path a_path = fspath(map_a), b_path = fspath(map_b), out_path = fspath(out);
  cli::ConfigOptions options;
  if (!config_value.is_none()) options.config_file = fspath(config_value);
  options.overrides = string_list(set);
  std::string description;
  JoinedMaps joined;
  {
    py::gil_scoped_release release;
    PathRules().input("map_a", a_path.string()).input("map_b", b_path.string())
        .output("out", out_path.string(), OutputUse::kReplacedFolder).check();
    SavedMap a = read_map(a_path);
    SaloamConfig config = options.resolve_for_map(a.config);
    cli::use_model_option(model, config);
    const auto cached = static_cast<std::size_t>(config.localize.cached_keyframes);
    const PriorMap base = PriorMap::open(a_path, std::move(a), cached);
    const PriorMap joining = PriorMap::open(b_path, cached);
    check_map_destination(out_path);
    const PlaceRecognizer places = PlaceRecognizer::from_config(config.loop, load_loop_network(config));
    joined = join_maps(base, joining, config, places);
    write_joined_map(out_path, joined, base, joining);
    description = describe_join(joined, a_path.string());
  }
  py::dict result = json_to_python(join_summary_json(joined)).cast<py::dict>();
  result["sessions"] = joined.map.manifest.sessions.size();
  result["linked"] = joined.linked_at.has_value();
  result["cross_session_loops"] = joined.cross_session_loops;
  result["description"] = description;
  return result;
}

// ---------------------------------------------------------------- evaluation

py::dict evaluate(const py::object& gt, const py::object& est, const std::string& align, const py::object& calib) {
  const bool files = py::isinstance<py::str>(gt) || py::hasattr(gt, "__fspath__");
  std::vector<Pose> gt_poses, est_poses;
  EvaluationLabels labels{"gt", "est"};
  if (files) {
    const std::optional<std::filesystem::path> calib_file =
        calib.is_none() ? std::nullopt : std::optional<std::filesystem::path>(fspath(calib));
    const std::filesystem::path gt_file = fspath(gt), est_file = fspath(est);
    TrajectoryPair pair;
    {
      py::gil_scoped_release release;
      pair = read_trajectory_pair(gt_file, est_file, calib_file);
    }
    gt_poses = std::move(pair.gt.poses);
    est_poses = std::move(pair.est.poses);
    labels = {gt_file.filename().string(), est_file.filename().string()};
  } else {
    gt_poses = poses_from_array(gt, "gt pose");
    est_poses = poses_from_array(est, "est pose");
  }
  EvaluationOptions options;
  options.alignment = parse_alignment(align);
  TrajectoryEvaluation evaluation;
  {
    py::gil_scoped_release release;
    try {
      evaluation = evaluate_trajectories(gt_poses, est_poses, options);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(e.what());
    }
  }
  return json_to_python(evaluation_to_json(evaluation, labels)).cast<py::dict>();
}

// ---------------------------------------------------------------- segmentation

struct PySegmenter {
  std::unique_ptr<Segmenter> segmenter;
  std::mutex mutex;

  PySegmenter(const std::string& model, const std::string& projection, const py::object& config_value,
              const py::object& plugin) {
    const SaloamConfig config = config_from_python(config_value);
    const auto description = cli::segmenter_description_path(model, projection, config);
    SegmenterSpec spec = read_segmenter_spec(description);
    const std::filesystem::path m = !model.empty() ? model : config.segmentation.model;
    if (m.extension() == ".pt") {
      spec.network.format = NetworkFormat::kTorchScript;
      spec.network.weights = std::filesystem::absolute(m).string();
    }
    const std::filesystem::path plugin_path = fspath(plugin);
    py::gil_scoped_release release;
    segmenter = std::make_unique<Segmenter>(std::move(spec), plugin_path, config.odometry.features);
  }

  /// The labels, or (labels, confidence) with `confidence`.
  py::object label(const py::object& points, const py::object& rings, bool confidence) {
    const LabelledCloud cloud = cloud_from_arrays(points, py::none(), py::none(), rings);
    Segmentation segmented;
    {
      py::gil_scoped_release release;
      std::lock_guard lock(mutex);
      segmented = segmenter->segment(cloud, confidence);
    }
    py::array_t<std::uint32_t> labels(static_cast<py::ssize_t>(segmented.labels.size()));
    std::copy(segmented.labels.begin(), segmented.labels.end(), labels.mutable_data());
    if (!confidence) return labels;
    py::array_t<float> sure(static_cast<py::ssize_t>(segmented.confidence.size()));
    std::copy(segmented.confidence.begin(), segmented.confidence.end(), sure.mutable_data());
    return py::make_tuple(labels, sure);
  }
};

// ---------------------------------------------------------------- module

constexpr const char* kRegisterDoc = R"(Registers the next scan and returns its pose T_world<-sensor as a 4x4
float64 array: the LiDAR-frame pose poses_tum.txt holds (world = the first
scan's sensor frame).

points: (N, 3) or (N, 4) float32 or float64 array (x, y, z[, remission 0..1];
  float64 is rounded to float32, the library's point type), any strides.
labels: (N,) integer array of SemanticKITTI .label values (class in the low
  16 bits, instance in the high 16), or None (no semantics for this scan).
times: (N,) per-point times [s] relative to the scan's stamp (de-skewing), or None.
stamp: the scan's timestamp [s]; None: 0.1 s after the previous scan.
rings: (N,) beam index of every point, or None (rings from the storage order
  or the sensor profile's elevations, as for a .bin scan).)";

void bind(py::module_& m) {
  m.doc() = "saloam: semantic-aided LiDAR SLAM (SA-LOAM) for numpy arrays; see docs/python.md";

  py::object base = py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc("saloam.Error", "An error of the saloam library.", PyExc_RuntimeError, nullptr));
  py::object input_error = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      "saloam.InputError", "Bad input data: a file that is missing, truncated or malformed (the message names it).",
      base.ptr(), nullptr));
  py::tuple config_bases = py::make_tuple(base, py::handle(PyExc_ValueError));
  py::object config_error = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      "saloam.ConfigError", "A configuration key, value or option that cannot be used.", config_bases.ptr(), nullptr));
  m.attr("Error") = base;
  m.attr("InputError") = input_error;
  m.attr("ConfigError") = config_error;
  static PyObject* input_type = input_error.ptr();
  static PyObject* config_type = config_error.ptr();
  static PyObject* base_type = base.ptr();
  Py_INCREF(input_type);
  Py_INCREF(config_type);
  Py_INCREF(base_type);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(input_type, e.what());
    } catch (const ConfigError& e) {
      PyErr_SetString(config_type, e.what());
    } catch (const std::filesystem::filesystem_error& e) {
      PyErr_SetString(base_type, cli::describe_exception(e).c_str());
    }
  });

  m.attr("Frame") = py::module_::import("collections").attr("namedtuple")(
      "Frame", py::make_tuple("points", "labels", "times", "stamp", "rings"));
  m.attr("Frame").attr("__doc__") =
      "One scan: points (N, 4) float32 (x, y, z, remission), labels (N,) uint32 or None, times (N,) float32 "
      "per-point times or None, stamp (the scan's time [s]), rings (N,) uint16 or None. Odometry.register(*frame) "
      "takes it as it is.";

  m.def("set_log_level", [](const std::string& level) { spdlog::set_level(spdlog::level::from_str(level)); },
        "level"_a, "The library's log level on stderr: trace, debug, info, warn (the default), err, off.");

  m.def("config", [](const py::object& config, const py::object& set) {
          return config_to_dict(config_from_python(config, string_list(set)));
        },
        "config"_a = py::none(), "set"_a = py::none(),
        R"(The effective configuration as a dict, with the keys of `saloam config`.

config: None (the defaults), a dict over the defaults (nested sections as
  `saloam config` prints them, or dotted keys: {"odometry.features.alpha": 0.2}),
  or a YAML file or shipped configuration's name ("real_kitti", "paper").
set: "key=value" strings on top, as --set ("alpha=0.2" short names work).
Values are checked by the library (the same checks and messages as a
--config file): saloam.ConfigError otherwise.)");

  py::class_<FrameIterator>(m, "_FrameIterator")
      .def("__iter__", [](py::object self) { return self; })
      .def("__next__", [](FrameIterator& it) {
        py::object frame = read_frame(*it.source, it.next);
        if (frame.is_none()) throw py::stop_iteration();
        ++it.next;
        return frame;
      });

  py::class_<Source, std::shared_ptr<Source>>(m, "Source", "Frames of a recorded sequence; see open_source().")
      .def("__len__", [](const Source& s) { return s.info().size(); })
      .def("__getitem__",
           [](Source& s, py::ssize_t i) {
             const auto n = static_cast<py::ssize_t>(s.info().size());
             if (i < 0) i += n;
             if (i < 0 || (s.info().rereadable && i >= n)) throw py::index_error(fmt::format("frame {} of {}", i, n));
             py::object frame = read_frame(s, static_cast<std::size_t>(i));
             if (frame.is_none()) throw py::index_error(fmt::format("frame {}: the stream has ended", i));
             return frame;
           },
           "i"_a, "Frame i (a rereadable source: any frame, any number of times).")
      .def("__iter__", [](const std::shared_ptr<Source>& s) { return FrameIterator{s}; },
           "The frames from the first (a stream: once).")
      .def_property_readonly("stream_stats",
                             [](const Source& s) -> py::object {
                               std::lock_guard lock(s.mutex);
                               const auto stats = s.source->stream_stats();
                               return stats ? stream_stats_dict(*stats) : py::none();
                             },
                             "A live source's counts so far (packets, frames made, served, dropped, ...; ended_by "
                             "once it ended), as the run summary's `live`; None for a recorded source.")
      .def_property_readonly("config", [](const Source& s) { return config_to_dict(s.config); },
                             "The configuration a run over this source takes (the sensor profile applied).")
      .def_property_readonly("sensor", [](const Source& s) { return s.sensor; },
                             "The sensor profile's name ('' when none) and how it was chosen: sensor_choice.")
      .def_property_readonly("sensor_choice", [](const Source& s) { return s.sensor_how; })
      .def_property_readonly("name", [](const Source& s) { return s.info().name; })
      .def_property_readonly("format", [](const Source& s) { return s.info().format; })
      .def_property_readonly("has_labels", [](const Source& s) { return s.info().has_labels; })
      .def_property_readonly("rereadable", [](const Source& s) { return s.info().rereadable; })
      .def_property_readonly("first_frame", [](const Source& s) { return s.info().first_frame; })
      .def_property_readonly("times",
                             [](const Source& s) { return py::array_t<double>(py::cast(s.info().times)); },
                             "Every frame's timestamp [s].")
      .def_property_readonly("velo_to_cam",
                             [](const Source& s) -> py::object {
                               if (!s.info().velo_to_cam) return py::none();
                               return pose_to_array(*s.info().velo_to_cam);
                             },
                             "Tr (calib.txt): LiDAR to camera 0, or None (LiDAR-frame runs).")
      .def_property_readonly("reference_poses",
                             [](const Source& s) -> py::object {
                               if (!s.info().camera_poses) return py::none();
                               return poses_to_array(*s.info().camera_poses);
                             },
                             "The reference poses (poses.txt: camera frame when velo_to_cam is known, else "
                             "LiDAR frame), (N, 4, 4), or None.")
      .def("__repr__", [](const Source& s) {
        return fmt::format("<saloam.Source {} ({}, {} frames, sensor {})>", s.info().name, s.info().format,
                           s.info().size(), s.sensor.empty() ? "none" : s.sensor);
      });

  m.def("open_source", &open_source_py, "path"_a, py::kw_only(), "format"_a = "auto", "sensor"_a = "auto",
        "topic"_a = "", "labels"_a = py::none(), "frames"_a = "", "no_calib"_a = false, "intensity_scale"_a = "auto",
        "semantics"_a = true, "segment"_a = false, "segmenter"_a = "", "projection"_a = "", "config"_a = py::none(),
        "set"_a = py::none(), "metadata"_a = py::none(), "idle_timeout"_a = LiveOptions{}.idle_timeout_s,
        "queue"_a = LiveOptions{}.queue_frames,
        R"(Opens a sequence as `saloam odom PATH ...` does and returns a Source.

Iterating it (or source[i]) gives Frame tuples (points, labels, times, stamp,
rings) of numpy arrays that Odometry.register(*frame) / Slam.register(*frame)
take as they are. The options are the command line's: format ("auto",
"semantickitti", "kitti-raw", "pcd", "ply", "rosbag"), sensor ("auto", "none",
a profile name or file), topic, labels (a folder of .label files), frames
("A:B"), no_calib, intensity_scale ("auto", "1", "255", "65535"), semantics
(False: labels are not read, as --no-semantics), segment / segmenter /
projection (label scans in-process), metadata (a capture's Ouster JSON or
Velodyne calibration). config / set: as saloam.config();
source.config is that configuration with the sensor profile the source chose,
the one to give Odometry or Slam for the command line's results.

A live sensor: path "udp://[ADDRESS]:PORT" (port 0: a free one, which
source.name tells) with sensor ("vlp16", "hdl32e", "hdl64e") or an Ouster's
metadata. Iterating it gives the frames as the packets arrive, until no
packet came for idle_timeout seconds (0: never); a consumer slower than the
sensor loses whole frames beyond `queue` held ones, counted in
source.stream_stats.)");

  py::class_<Odometry>(m, "Odometry", "The semantic-assisted LOAM odometry (SA-LOAM Sec. III-B), scan by scan.")
      .def(py::init<const py::object&, const py::object&>(), "config"_a = py::none(), "set"_a = py::none(),
           "config / set: as saloam.config() (for a Source's scans: source.config).")
      .def("register", &Odometry::register_scan, "points"_a, "labels"_a = py::none(), "times"_a = py::none(),
           "stamp"_a = py::none(), "rings"_a = py::none(), kRegisterDoc)
      .def("poses", [](Odometry& o) { std::lock_guard lock(o.mutex); return poses_to_array(o.odometry->poses()); },
           "Every scan's pose so far, (N, 4, 4).")
      .def("stamps", [](Odometry& o) { std::lock_guard lock(o.mutex); return py::array_t<double>(py::cast(o.odometry->timestamps())); })
      .def("local_map", &Odometry::local_map,
           "The local map: {'edges': (N, 3) float64 world points, 'edges_labels': (N,) uint16 class ids, "
           "'planars': ..., 'planars_labels': ...}.")
      .def("last_registration", [](Odometry& o) { std::lock_guard lock(o.mutex); return registration_dict(*o.odometry); },
           "How the last scan's registration went (correspondences, degeneracy, features, map size).")
      .def("__len__", [](Odometry& o) { std::lock_guard lock(o.mutex); return o.odometry->poses().size(); })
      .def_property_readonly("config", [](const Odometry& o) { return config_to_dict(o.config); });

  py::class_<Slam>(m, "Slam", "The whole SLAM: odometry, loop closure, pose graph (SA-LOAM Sec. III-C), scan by scan.")
      .def(py::init<const py::object&, const py::object&, const std::string&>(), "config"_a = py::none(),
           "set"_a = py::none(), "model"_a = "",
           "config / set: as saloam.config(); model: SGPR weights (.sgw) for the sgpr and hybrid detectors.")
      .def("register", &Slam::register_scan, "points"_a, "labels"_a = py::none(), "times"_a = py::none(),
           "stamp"_a = py::none(), "rings"_a = py::none(),
           (std::string(kRegisterDoc) + "\n\nReturns the odometry pose; poses() gives the loop-closed ones.").c_str())
      .def("poses", [](Slam& s) { std::lock_guard lock(s.mutex); return poses_to_array(s.slam->optimized_poses()); },
           "Every scan's pose after loop closure, (N, 4, 4) (as the slam run's poses_tum.txt).")
      .def("odometry_poses",
           [](Slam& s) { std::lock_guard lock(s.mutex); return poses_to_array(s.slam->odometry_poses()); })
      .def("loops", &Slam::loops, "Every verified loop candidate (loops.csv's rows) as dicts; 'accepted' says which closed.")
      .def("keyframes", [](Slam& s) { std::lock_guard lock(s.mutex); return s.slam->keyframes().size(); })
      .def("save_map", &Slam::save_map, "path"_a, "sensor"_a = "", "velo_to_cam"_a = py::none(), "source"_a = "",
           "Saves the map for later runs (docs/map_format.md; `saloam localize --map`, Map, merge). The folder must "
           "not exist or be a saloam map; it is replaced as a whole.")
      .def("__len__", [](Slam& s) { std::lock_guard lock(s.mutex); return s.slam->odometry_poses().size(); })
      .def_property_readonly("config", [](const Slam& s) { return config_to_dict(s.config); });

  py::class_<Map>(m, "Map", "A saved map (slam --save-map, Slam.save_map, merge), read lazily.")
      .def(py::init<const py::object&>(), "path"_a)
      .def("info", &Map::info, "Keyframes, edges, sessions (source, keyframes, linked), detector, sensor.")
      .def("poses", &Map::poses, "The keyframes' optimised poses in the map frame, (N, 4, 4).")
      .def_property_readonly("config", [](const Map& m) { return config_to_dict(m.saved.config); })
      .def("localize", &Map::localize, "source"_a, "out"_a, py::kw_only(), "config"_a = py::none(),
           "set"_a = py::none(), "model"_a = "",
           "Relocalises a Source's frames in this map as `saloam localize` does, writing its outputs into `out`; "
           "returns the counts.");

  m.def("merge", &merge_maps, "map_a"_a, "map_b"_a, "out"_a, py::kw_only(), "config"_a = py::none(),
        "set"_a = py::none(), "model"_a = "",
        "Merges two saved maps as `saloam merge` does (in map_a's frame; maps that do not overlap stay separate "
        "sessions, 'linked' False). Returns the join's summary.");

  m.def("eval", &evaluate, "gt"_a, "est"_a, py::kw_only(), "align"_a = "se3", "calib"_a = py::none(),
        R"(The metrics of `saloam eval --json` as a dict: KITTI relative error, ATE, RPE, scale bias.

gt, est: trajectory files (KITTI or TUM, paired and converted exactly as
`saloam eval --gt GT --est EST [--calib]` does), or (N, 4, 4) pose arrays
paired by index. align: "se3", "sim3" or "none".)");

  py::class_<PySegmenter>(m, "_Segmenter")
      .def(py::init<const std::string&, const std::string&, const py::object&, const py::object&>(), "model"_a,
           "projection"_a, "config"_a, "plugin"_a)
      .def("label", &PySegmenter::label, "points"_a, "rings"_a = py::none(), "confidence"_a = false);

  m.def("write_trajectory",
        [](const py::object& path, const py::object& poses, const py::object& stamps, const std::string& format) {
          const std::filesystem::path file = fspath(path);
          const std::vector<Pose> p = poses_from_array(poses, "pose");
          if (format == "kitti") {
            write_kitti_poses(file, p);
            return;
          }
          if (format != "tum") throw py::value_error("format must be 'tum' or 'kitti'");
          Trajectory t;
          t.poses = p;
          t.timestamps = stamps.cast<std::vector<double>>();
          if (t.timestamps.size() != t.poses.size()) throw py::value_error("one stamp per pose");
          write_tum_trajectory(file, t);
        },
        "path"_a, "poses"_a, "stamps"_a = py::none(), "format"_a = "tum",
        "Writes poses as saloam's runs do: TUM (t x y z qx qy qz qw, needs stamps) or KITTI (12 numbers).");
  m.def("write_poses",
        [](const py::object& folder, const py::object& poses, const py::object& stamps, const py::object& velo_to_cam) {
          const std::filesystem::path dir = fspath(folder);
          const std::vector<Pose> p = poses_from_array(poses, "pose");
          const auto t = stamps.cast<std::vector<double>>();
          if (t.size() != p.size()) throw py::value_error("one stamp per pose");
          std::optional<Pose> tr;
          if (!velo_to_cam.is_none()) tr = pose_from_array(velo_to_cam, "velo_to_cam");
          py::gil_scoped_release release;
          // A sequence's folder holds its ground truth as poses.txt: an input, never overwritten.
          for (const char* part : {"velodyne", "times.txt", "calib.txt", "labels"}) {
            if (std::filesystem::exists(dir / part)) {
              throw InputError(dir, fmt::format("holds a sequence ({} is there): its poses.txt is the ground truth, "
                                                "not overwritten; write the poses into another folder", part));
            }
          }
          std::filesystem::create_directories(dir);
          TrajectoryWriter writer(dir / "poses.txt", dir / "poses_tum.txt", tr);
          for (std::size_t i = 0; i < p.size(); ++i) writer.write(t[i], p[i]);
          writer.commit();
        },
        "folder"_a, "poses"_a, "stamps"_a, "velo_to_cam"_a = py::none(),
        "Writes LiDAR-frame poses into folder/poses.txt (KITTI; camera frame Tr Q Tr^-1 when velo_to_cam is "
        "given) and folder/poses_tum.txt (TUM), byte for byte as `saloam odom` writes them.");
  m.def("read_trajectory",
        [](const py::object& path) {
          const Trajectory t = read_trajectory(std::filesystem::path(fspath(path)));
          return py::make_tuple(poses_to_array(t.poses), py::array_t<double>(py::cast(t.timestamps)));
        },
        "path"_a, "A KITTI or TUM file as (poses (N, 4, 4), stamps (N,) (empty for KITTI)).");
}

}  // namespace
}  // namespace saloam::python

PYBIND11_MODULE(_saloam, m) {
  saloam::cli::setup_logging();
  spdlog::set_level(spdlog::level::warn);
  saloam::python::bind(m);
}
