#include "saloam/segmentation/segmenter_spec.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/core/yaml_documents.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxSpecBytes = std::size_t{1} << 20;
constexpr int kMaxRows = 1024, kMaxColumns = 16384, kMaxClasses = 256, kMaxWidth = 1024;

/// Reads one YAML map, refusing keys that are not names, are given twice or
/// are not known.
class MapReader {
 public:
  MapReader(const YAML::Node& node, std::string section, const fs::path& file, std::set<std::string> known)
      : node_(node), section_(std::move(section)), file_(file) {
    if (!node.IsMap()) fail(section_, "expected a map");
    if (const auto problem = key_problem(node, section_); !problem.empty()) throw InputError(file_, problem);
    for (const auto& kv : node) {
      const std::string key = kv.first.Scalar();  // a name: key_problem
      if (!known.contains(key)) fail(key, "unknown key");
    }
  }

  [[nodiscard]] bool has(const std::string& key) const { return static_cast<bool>(node_[key]); }
  [[nodiscard]] YAML::Node node(const std::string& key) const {
    if (!has(key)) fail(key, "missing");
    return node_[key];
  }
  [[nodiscard]] std::string text(const std::string& key) const { return scalar<std::string>(key); }
  [[nodiscard]] double number(const std::string& key, double lo, double hi) const {
    const auto x = scalar<double>(key);
    if (!(x >= lo && x <= hi)) fail(key, fmt::format("{} is outside [{}, {}]", x, lo, hi));
    return x;
  }
  [[nodiscard]] int integer(const std::string& key, int lo, int hi) const {
    const auto x = scalar<long long>(key);
    if (x < lo || x > hi) fail(key, fmt::format("{} is outside [{}, {}]", x, lo, hi));
    return static_cast<int>(x);
  }
  template <class T>
  [[nodiscard]] std::vector<T> list(const std::string& key, std::size_t max_size) const {
    const YAML::Node n = node(key);
    if (!n.IsSequence() || n.size() == 0 || n.size() > max_size)
      fail(key, fmt::format("expected a list of 1 to {} values", max_size));
    std::vector<T> out;
    for (const auto& item : n) out.push_back(convert<T>(item, key));
    return out;
  }
  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw InputError(file_, fmt::format("{}{}: {}", section_.empty() ? "" : section_ + ".", key, problem));
  }

 private:
  template <class T>
  T scalar(const std::string& key) const {
    const YAML::Node n = node(key);
    if (!n.IsScalar()) fail(key, "expected a single value");
    return convert<T>(n, key);
  }
  template <class T>
  T convert(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      fail(key, fmt::format("'{}' is not a {}", n.IsScalar() ? n.Scalar().substr(0, 40) : "list or map",
                            std::is_same_v<T, std::string> ? "text" : "number"));
    }
  }

  YAML::Node node_;
  std::string section_;
  fs::path file_;
};

ImageChannel channel_from_name(const std::string& name, const MapReader& reader) {
  for (const auto c : all_channels())
    if (channel_name(c) == name) return c;
  reader.fail("channels", fmt::format("unknown channel '{}' (range, x, y, z, remission, mask)", name.substr(0, 40)));
}

NetworkSpec read_network(const YAML::Node& node, const fs::path& file) {
  const MapReader r(node, "network", file, {"type", "file", "widths", "stem_stride", "context_blocks"});
  NetworkSpec spec;
  const std::string type = r.text("type");
  if (type == "segnet") spec.format = NetworkFormat::kSegNet;
  else if (type == "torchscript") spec.format = NetworkFormat::kTorchScript;
  else r.fail("type", fmt::format("'{}' is neither segnet nor torchscript", type.substr(0, 40)));
  const fs::path weights = r.text("file");
  if (weights.empty()) r.fail("file", "empty");
  spec.weights = (weights.is_absolute() ? weights : file.parent_path() / weights).lexically_normal().string();
  if (spec.format == NetworkFormat::kSegNet) {
    const auto widths = r.list<int>("widths", 3);
    if (widths.size() != 3) r.fail("widths", "expected three widths");
    for (int w : widths)
      if (w < 1 || w > kMaxWidth) r.fail("widths", fmt::format("{} is outside [1, {}]", w, kMaxWidth));
    std::copy(widths.begin(), widths.end(), spec.shape.widths.begin());
    spec.shape.stem_stride = r.integer("stem_stride", 1, 16);
    spec.shape.context_blocks = r.integer("context_blocks", 0, 16);
  } else {
    for (const char* key : {"widths", "stem_stride", "context_blocks"})
      if (r.has(key)) r.fail(key, "only for type segnet");
  }
  return spec;
}

void read_projection(const YAML::Node& node, const fs::path& file, SegmenterSpec& spec) {
  const MapReader r(node, "projection", file,
                    {"rows", "beams", "fov_up_deg", "fov_down_deg", "columns", "channels", "means", "stds"});
  ProjectionSpec& p = spec.projection;
  if (r.node("rows").IsScalar() && r.node("rows").Scalar() == "ring") {
    p.row_mode = RowMode::kRing;
    spec.beams = r.list<int>("beams", 16);
    for (int b : spec.beams)
      if (b < 4 || b > kMaxRows) r.fail("beams", fmt::format("{} is outside [4, {}]", b, kMaxRows));
    for (const char* key : {"fov_up_deg", "fov_down_deg"})
      if (r.has(key)) r.fail(key, "only for rows by elevation (rows: N)");
  } else {
    p.row_mode = RowMode::kElevation;
    p.rows = r.integer("rows", 4, kMaxRows);
    p.fov_up_deg = r.number("fov_up_deg", -90, 90);
    p.fov_down_deg = r.number("fov_down_deg", -90, 90);
    if (p.fov_down_deg >= p.fov_up_deg) r.fail("fov_down_deg", "must be below fov_up_deg");
    if (r.has("beams")) r.fail("beams", "only for rows: ring");
  }
  p.columns = r.integer("columns", 16, kMaxColumns);
  p.channels.clear();
  for (const auto& name : r.list<std::string>("channels", 6)) p.channels.push_back(channel_from_name(name, r));
  p.means = r.list<float>("means", 6);
  p.stds = r.list<float>("stds", 6);
  if (p.means.size() != p.channels.size()) r.fail("means", "needs one value per channel");
  if (p.stds.size() != p.channels.size()) r.fail("stds", "needs one value per channel");
  for (float m : p.means)
    if (!std::isfinite(m) || std::abs(m) > 1e6f) r.fail("means", "values must be finite and within +-1e6");
  for (float s : p.stds)
    if (!(s > 1e-6f && s < 1e6f)) r.fail("stds", "values must lie in (1e-6, 1e6)");
}

std::vector<std::uint16_t> read_classes(const YAML::Node& node, const fs::path& file) {
  if (node.IsScalar() && node.Scalar() == "semantickitti") return semantickitti_learning_classes();
  YAML::Node root;
  root["classes"] = node;
  const MapReader r(root, "", file, {"classes"});
  std::vector<std::uint16_t> classes;
  for (const auto& name : r.list<std::string>("classes", kMaxClasses)) {
    const auto id = semantic_class_id(name);
    if (!id) r.fail("classes", fmt::format("'{}' is not a SemanticKITTI class name", name.substr(0, 40)));
    classes.push_back(*id);
  }
  if (classes.size() < 2) r.fail("classes", "needs at least two classes");
  if (classes.front() != cls::kUnlabeled)
    r.fail("classes", "the first class (output 0) must be unlabeled: it is never predicted");
  return classes;
}

KnnOptions read_knn(const YAML::Node& node, const fs::path& file) {
  const MapReader r(node, "knn", file, {"k", "window", "cutoff", "sigma"});
  KnnOptions knn;
  knn.window = r.integer("window", 1, 15);
  if (knn.window % 2 == 0) r.fail("window", "must be odd");
  knn.k = r.integer("k", 1, knn.window * knn.window);
  knn.cutoff = r.number("cutoff", 1e-3, 1e3);
  knn.sigma = r.number("sigma", 1e-3, 1e3);
  return knn;
}

// Only a regular file of at most kMaxSpecBytes: a FIFO or a device in its
// place is refused, never waited on or read without end.
std::string read_limited(const fs::path& file) {
  return read_file(file, kMaxSpecBytes, "segmentation model description");
}

/// `decision:` of `spec`, whose classes are read: every key optional;
/// class_bias names classes of the model's output (unlabeled excluded).
void read_decision(const YAML::Node& node, const fs::path& file, SegmenterSpec& spec) {
  const MapReader d(node, "decision", file, {"dynamic_bias", "class_bias", "min_confidence"});
  if (d.has("dynamic_bias")) spec.dynamic_bias = d.number("dynamic_bias", 0.0, 20.0);
  if (d.has("min_confidence")) spec.min_confidence = d.number("min_confidence", 0.0, 1.0);
  if (!d.has("class_bias")) return;
  std::set<std::string> names;
  for (const auto id : spec.classes) {
    if (id != cls::kUnlabeled) names.emplace(class_name(id));
  }
  const YAML::Node biases = d.node("class_bias");
  const MapReader b(biases, "decision.class_bias", file, names);
  for (const auto& kv : biases) {
    const auto name = kv.first.Scalar();  // a known class name: MapReader checked every key
    spec.class_bias.emplace_back(*semantic_class_id(name), b.number(name, -20.0, 20.0));
  }
}

}  // namespace

std::vector<std::uint16_t> semantickitti_learning_classes() {
  std::vector<std::uint16_t> classes;
  for (int c = 0; c < kNumLearningClasses; ++c) classes.push_back(from_learning_class(static_cast<std::uint8_t>(c)));
  return classes;
}

SegmenterSpec parse_segmenter_spec(std::string_view yaml_text, const fs::path& origin) {
  const YamlDocument document = load_yaml_document(yaml_text, "a description");
  if (!document.problem.empty()) throw InputError(origin, document.problem);
  const YAML::Node& root = document.root;
  const MapReader r(root, "", origin, {"format", "network", "projection", "classes", "knn", "decision"});
  if (r.text("format") != kSegmenterFormat)
    r.fail("format", fmt::format("expected '{}'", kSegmenterFormat));
  SegmenterSpec spec;
  spec.file = origin;
  spec.network = read_network(r.node("network"), origin);
  read_projection(r.node("projection"), origin, spec);
  spec.classes = read_classes(r.node("classes"), origin);
  spec.knn = read_knn(r.node("knn"), origin);
  if (r.has("decision")) read_decision(r.node("decision"), origin, spec);
  spec.network.shape.in_channels = static_cast<int>(spec.projection.channels.size());
  spec.network.shape.classes = static_cast<int>(spec.classes.size());
  return spec;
}

std::vector<float> decision_offsets(const SegmenterSpec& spec) {
  std::vector<float> offsets;
  for (const auto id : spec.classes) {
    double offset = is_dynamic(id) ? spec.dynamic_bias : 0.0;
    for (const auto& [biased, bias] : spec.class_bias) offset += biased == id ? bias : 0.0;
    offsets.push_back(static_cast<float>(offset));
  }
  if (std::ranges::all_of(offsets, [](float offset) { return offset == 0.0f; })) offsets.clear();
  return offsets;
}

SegmenterSpec read_segmenter_spec(const fs::path& file) { return parse_segmenter_spec(read_limited(file), file); }

std::string segmenter_spec_yaml(const SegmenterSpec& spec, const fs::path& folder) {
  const fs::path weights(spec.network.weights);
  const fs::path relative = weights.lexically_relative(folder);
  const bool inside = !relative.empty() && *relative.begin() != "..";
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "format" << YAML::Value << std::string(kSegmenterFormat);
  out << YAML::Key << "network" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "type" << YAML::Value << (spec.network.format == NetworkFormat::kSegNet ? "segnet" : "torchscript");
  out << YAML::Key << "file" << YAML::Value << (inside ? relative : weights).string();
  if (spec.network.format == NetworkFormat::kSegNet) {
    const auto& s = spec.network.shape;
    out << YAML::Key << "widths" << YAML::Value << YAML::Flow << std::vector<int>(s.widths.begin(), s.widths.end());
    out << YAML::Key << "stem_stride" << YAML::Value << s.stem_stride;
    out << YAML::Key << "context_blocks" << YAML::Value << s.context_blocks;
  }
  out << YAML::EndMap;
  const ProjectionSpec& p = spec.projection;
  out << YAML::Key << "projection" << YAML::Value << YAML::BeginMap;
  if (p.row_mode == RowMode::kRing) {
    out << YAML::Key << "rows" << YAML::Value << "ring";
    out << YAML::Key << "beams" << YAML::Value << YAML::Flow << spec.beams;
  } else {
    out << YAML::Key << "rows" << YAML::Value << p.rows;
    out << YAML::Key << "fov_up_deg" << YAML::Value << p.fov_up_deg;
    out << YAML::Key << "fov_down_deg" << YAML::Value << p.fov_down_deg;
  }
  out << YAML::Key << "columns" << YAML::Value << p.columns;
  std::vector<std::string> channels;
  for (auto c : p.channels) channels.emplace_back(channel_name(c));
  out << YAML::Key << "channels" << YAML::Value << YAML::Flow << channels;
  out << YAML::Key << "means" << YAML::Value << YAML::Flow << p.means;
  out << YAML::Key << "stds" << YAML::Value << YAML::Flow << p.stds;
  out << YAML::EndMap;
  std::vector<std::string> classes;
  for (auto id : spec.classes) classes.emplace_back(class_name(id));
  out << YAML::Key << "classes" << YAML::Value << YAML::Flow << classes;
  out << YAML::Key << "knn" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "k" << YAML::Value << spec.knn.k << YAML::Key << "window" << YAML::Value << spec.knn.window;
  out << YAML::Key << "cutoff" << YAML::Value << spec.knn.cutoff << YAML::Key << "sigma" << YAML::Value << spec.knn.sigma;
  out << YAML::EndMap;
  if (spec.dynamic_bias != 0.0 || !spec.class_bias.empty() || spec.min_confidence != 0.0) {
    out << YAML::Key << "decision" << YAML::Value << YAML::Flow << YAML::BeginMap;
    if (spec.dynamic_bias != 0.0) out << YAML::Key << "dynamic_bias" << YAML::Value << spec.dynamic_bias;
    if (spec.min_confidence != 0.0) out << YAML::Key << "min_confidence" << YAML::Value << spec.min_confidence;
    if (!spec.class_bias.empty()) {
      out << YAML::Key << "class_bias" << YAML::Value << YAML::BeginMap;
      for (const auto& [id, bias] : spec.class_bias) out << YAML::Key << std::string(class_name(id)) << YAML::Value << bias;
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace saloam
