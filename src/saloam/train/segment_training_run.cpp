// The training run of SegNet (segment_trainer.hpp: train_segmenter, resumed_options):
// epochs planned from the recipe, validation, checkpoints, records and curves;
// the network's own training step is segment_trainer.cpp.
#include "saloam/train/segment_trainer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <future>
#include <map>
#include <optional>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/eval/segmentation_score.hpp"
#include "saloam/segmentation/segmenter.hpp"
#include "saloam/segmentation/torch/segnet.hpp"
#include "saloam/train/training_run.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam {

namespace fs = std::filesystem;

namespace {

/// The factors other than 1, by class name (runs before the option had none).
nlohmann::json class_factors_json(const std::array<double, kNumLearningClasses>& factors) {
  nlohmann::json j = nlohmann::json::object();
  for (int c = 1; c < kNumLearningClasses; ++c)
    if (factors[c] != 1.0) j[std::string(learning_class_name(static_cast<std::uint8_t>(c)))] = factors[c];
  return j;
}

std::array<double, kNumLearningClasses> class_factors_from_json(const nlohmann::json& j) {
  auto factors = uniform_class_factors();
  for (const auto& [name, factor] : j.items()) set_class_weight_factor(factors, name, factor.get<double>());
  return factors;
}

nlohmann::json augment_json(ScanAugmentOptions augment) {
  nlohmann::json j = nlohmann::json::object();
  visit_fields(augment, [&](std::string_view name, const auto& member, auto&&...) { j[std::string(name)] = member; });
  return j;
}

ScanAugmentOptions augment_from_json(const nlohmann::json& j) {
  ScanAugmentOptions augment;
  visit_fields(augment, [&](std::string_view name, auto& member, auto&&...) {
    member = j.at(std::string(name)).get<std::decay_t<decltype(member)>>();
  });
  return augment;
}

nlohmann::json options_json(const SegmentTrainOptions& o) {
  return {{"samples_per_epoch", o.samples_per_epoch},
          {"batch", o.batch},
          {"pixels_per_sample", o.pixels_per_sample},
          {"columns", o.columns},
          {"learning_rate", o.learning_rate},
          {"weight_decay", o.weight_decay},
          {"lovasz_weight", o.lovasz_weight},
          {"class_weight_factors", class_factors_json(o.class_weight_factors)},
          {"seed", o.seed},
          {"threads", o.threads},
          {"widths", o.shape.widths},
          {"stem_stride", o.shape.stem_stride},
          {"context_blocks", o.shape.context_blocks},
          {"validation_scans", o.validation_scans},
          {"init", o.init.empty() ? std::string("scratch") : fs::absolute(o.init).lexically_normal().string()},
          {"augment", augment_json(o.augment)}};
}

SegmentTrainOptions options_from_json(const nlohmann::json& j, SegmentTrainOptions o) {
  o.samples_per_epoch = j.at("samples_per_epoch").get<std::size_t>();
  o.batch = j.at("batch").get<int>();
  o.pixels_per_sample = j.at("pixels_per_sample").get<int>();
  o.columns = j.at("columns").get<int>();
  o.learning_rate = j.at("learning_rate").get<double>();
  o.weight_decay = j.at("weight_decay").get<double>();
  o.lovasz_weight = j.at("lovasz_weight").get<double>();
  o.class_weight_factors = class_factors_from_json(j.value("class_weight_factors", nlohmann::json::object()));
  o.seed = j.at("seed").get<std::uint64_t>();
  o.threads = j.at("threads").get<int>();
  o.shape.widths = j.at("widths").get<std::array<int, 3>>();
  o.shape.stem_stride = j.at("stem_stride").get<int>();
  o.shape.context_blocks = j.at("context_blocks").get<int>();
  o.validation_scans = j.at("validation_scans").get<std::size_t>();
  if (const auto init = j.value("init", std::string("scratch")); init != "scratch") o.init = init;
  o.augment = augment_from_json(j.at("augment"));
  return o;
}

nlohmann::json record_json(const SegmentEpochRecord& r) {
  nlohmann::json iou = nlohmann::json::object();
  for (int c = 1; c < kNumLearningClasses; ++c)
    if (!std::isnan(r.val_iou[c])) iou[std::string(learning_class_name(static_cast<std::uint8_t>(c)))] = r.val_iou[c];
  return {{"epoch", r.epoch},     {"loss", r.loss},         {"learning_rate", r.learning_rate},
          {"samples", r.samples}, {"samples_per_second", r.samples_per_second},
          {"seconds", r.seconds}, {"val_miou", r.val_miou}, {"val_big_miou", r.val_big_miou},
          {"val_iou", iou}};
}

SegmentEpochRecord record_from_json(const nlohmann::json& j) {
  SegmentEpochRecord r;
  r.epoch = j.at("epoch").get<int>();
  r.loss = j.at("loss").get<double>();
  r.learning_rate = j.at("learning_rate").get<double>();
  r.samples = j.at("samples").get<std::size_t>();
  r.samples_per_second = j.at("samples_per_second").get<double>();
  r.seconds = j.at("seconds").get<double>();
  r.val_miou = j.at("val_miou").get<double>();
  r.val_big_miou = j.at("val_big_miou").get<double>();
  r.val_iou.fill(std::nan(""));
  for (int c = 1; c < kNumLearningClasses; ++c) {
    const std::string name(learning_class_name(static_cast<std::uint8_t>(c)));
    if (j.at("val_iou").contains(name)) r.val_iou[c] = j.at("val_iou").at(name).get<double>();
  }
  return r;
}

/// Learning rate at `progress` (epochs done, fractional) of `epochs`: linear
/// warm-up over the first epoch, then a cosine down to 1 %.
double learning_rate_at(double base, double progress, int epochs) {
  if (progress < 1.0) return base * std::max(progress, 0.01);
  if (epochs <= 1) return base;
  const double t = std::clamp((progress - 1.0) / (epochs - 1.0), 0.0, 1.0);
  return base * (0.01 + 0.99 * 0.5 * (1.0 + std::cos(M_PI * t)));
}

struct PlannedSample {
  std::uint32_t sequence = 0, scan = 0;
  std::uint64_t seed = 0;
  /// With augment.mix > 0: a second scan of the same beam count (sequence, scan), drawn as the first.
  std::optional<std::pair<std::uint32_t, std::uint32_t>> partner;
};
using Batch = std::vector<PlannedSample>;

/// A scan of the same beam count as `sample`'s, drawn as samples are (a few
/// tries; none when every draw has another beam count).
template <class Pick>
std::optional<std::pair<std::uint32_t, std::uint32_t>> draw_partner(const std::vector<TrainingScanSet>& train,
                                                                    const std::vector<PlannedSample>& all, Pick& pick,
                                                                    const PlannedSample& sample) {
  const int beams = train[sample.sequence].scans[sample.scan].beams;
  for (int attempt = 0; attempt < 16; ++attempt) {
    const PlannedSample& other = all[pick()];
    if (train[other.sequence].scans[other.scan].beams == beams) return std::pair{other.sequence, other.scan};
  }
  return std::nullopt;
}

/// The batches of one epoch: scans drawn with their set's weight (uniformly
/// when every set weighs the same), grouped by beam count into batches, in
/// random order.
std::vector<Batch> plan_epoch(const std::vector<TrainingScanSet>& train, const SegmentTrainOptions& options, int epoch) {
  std::vector<PlannedSample> all;
  std::vector<double> weights;
  for (std::uint32_t s = 0; s < train.size(); ++s)
    for (std::uint32_t k = 0; k < train[s].scans.size(); ++k) {
      all.push_back({s, k, 0, std::nullopt});
      weights.push_back(train[s].weight);
    }
  const bool uniform = std::all_of(train.begin(), train.end(), [&](const auto& s) { return s.weight == train[0].weight; });
  std::mt19937_64 rng = epoch_generator(options.seed, epoch);
  std::uniform_int_distribution<std::size_t> pick_uniform(0, all.size() - 1);
  std::discrete_distribution<std::size_t> pick_weighted(weights.begin(), weights.end());
  const auto pick = [&] { return uniform ? pick_uniform(rng) : pick_weighted(rng); };
  std::map<int, Batch> by_beams;
  for (std::size_t j = 0; j < options.samples_per_epoch; ++j) {
    PlannedSample sample = all[pick()];
    sample.seed = rng();
    if (options.augment.mix > 0) sample.partner = draw_partner(train, all, pick, sample);
    by_beams[train[sample.sequence].scans[sample.scan].beams].push_back(sample);
  }
  std::vector<Batch> batches;
  for (auto& [beams, samples] : by_beams)
    for (std::size_t i = 0; i < samples.size(); i += static_cast<std::size_t>(options.batch))
      batches.emplace_back(samples.begin() + static_cast<std::ptrdiff_t>(i),
                           samples.begin() + static_cast<std::ptrdiff_t>(std::min(samples.size(), i + options.batch)));
  std::shuffle(batches.begin(), batches.end(), rng);
  return batches;
}

std::vector<TrainingSample> prepare(const Batch& batch, const std::vector<TrainingScanSet>& train,
                                    const ProjectionSpec& projection, const SegmentTrainOptions& options) {
  std::vector<TrainingSample> samples;
  for (const auto& p : batch) {
    const TrainingScan& scan = train[p.sequence].scans[p.scan];
    const int crop = options.pixels_per_sample / std::max(scan.beams, 1);
    const TrainingScan* partner = p.partner ? &train[p.partner->first].scans[p.partner->second] : nullptr;
    samples.push_back(make_training_sample(scan, projection, options.augment, p.seed, crop, partner));
  }
  return samples;
}

struct EpochLoss {
  double loss = 0;
  std::size_t samples = 0;
  double seconds = 0;
  double learning_rate = 0;
  bool interrupted = false;
};

EpochLoss train_epoch(SegmentTrainer& trainer, const std::vector<TrainingScanSet>& train, const ProjectionSpec& projection,
                      const SegmentTrainOptions& options, int epoch) {
  const std::vector<Batch> batches = plan_epoch(train, options, epoch);
  ProgressBar progress(batches.size(), fmt::format("epoch {}", epoch), options.show_progress);
  EpochLoss out;
  const auto start = std::chrono::steady_clock::now();
  double loss_sum = 0;
  auto next = std::async(std::launch::async, prepare, std::cref(batches.front()), std::cref(train),
                         std::cref(projection), std::cref(options));
  for (std::size_t b = 0; b < batches.size(); ++b) {
    const std::vector<TrainingSample> samples = next.get();
    if (b + 1 < batches.size())
      next = std::async(std::launch::async, prepare, std::cref(batches[b + 1]), std::cref(train), std::cref(projection),
                        std::cref(options));
    if (stop_requested()) {
      out.interrupted = true;
      break;
    }
    out.learning_rate = learning_rate_at(options.learning_rate,
                                         (epoch - 1) + static_cast<double>(b) / static_cast<double>(batches.size()),
                                         options.epochs);
    const double loss = trainer.step(samples, out.learning_rate);
    loss_sum += loss * static_cast<double>(samples.size());
    out.samples += samples.size();
    progress.set_status(fmt::format("loss {:.3f}", loss_sum / static_cast<double>(out.samples)));
    progress.advance();
  }
  if (next.valid()) next.wait();
  progress.finish();
  out.loss = out.samples > 0 ? loss_sum / static_cast<double>(out.samples) : 0.0;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

/// Validation scans, at most `limit`, evenly spread over all sequences.
std::vector<const TrainingScan*> validation_subset(const std::vector<TrainingScanSet>& validation, std::size_t limit) {
  std::vector<const TrainingScan*> all;
  for (const auto& s : validation)
    for (const auto& scan : s.scans) all.push_back(&scan);
  if (all.size() <= limit || limit == 0) return all;
  std::vector<const TrainingScan*> out;
  for (std::size_t k = 0; k < limit; ++k) out.push_back(all[k * all.size() / limit]);
  return out;
}

/// Scores `segmenter` on the scans through the inference path.
SegmentationScore score_scans(const Segmenter& segmenter, const std::vector<const TrainingScan*>& scans) {
  SegmentationScore score;
  const auto& classes = segmenter.spec().classes;
  for (const TrainingScan* scan : scans) {
    const auto predicted = segmenter.output_classes(scan_cloud(*scan), training_scan_rings(*scan), scan->beams);
    std::vector<std::uint16_t> truth(scan->size()), labels(scan->size());
    for (std::size_t i = 0; i < scan->size(); ++i) {
      truth[i] = from_learning_class(scan->target[i]);
      labels[i] = classes[static_cast<std::size_t>(predicted[i])];
    }
    score.add(truth, labels);
  }
  return score;
}

void fill_validation(SegmentEpochRecord& record, const SegmentationScore& score) {
  record.val_miou = score.miou();
  double big = 0;
  int present = 0;
  for (int c = 0; c < kNumLearningClasses; ++c) record.val_iou[c] = c == 0 ? std::nan("") : score.iou(c);
  for (int c : kBigClasses)
    if (!std::isnan(record.val_iou[c])) {
      big += record.val_iou[c];
      ++present;
    }
  record.val_big_miou = present > 0 ? big / present : std::nan("");
}

void plot_curves(const fs::path& file, const SegmentTrainResult& result) {
  Plot plot(800, 500);
  double top = 1.0;
  for (const auto& r : result.history) top = std::max(top, r.loss);
  plot.set_range(0, std::max<double>(1, static_cast<double>(result.history.size())), 0, top * 1.02, false);
  plot.set_title("segmentation training");
  plot.set_labels("epoch", "loss / mean IoU");
  std::vector<Eigen::Vector2d> loss, miou, big;
  for (const auto& r : result.history) {
    loss.emplace_back(r.epoch, r.loss);
    miou.emplace_back(r.epoch, r.val_miou);
    big.emplace_back(r.epoch, r.val_big_miou);
  }
  const Rgb blue{31, 119, 180}, red{214, 39, 40}, green{44, 160, 44};
  plot.line(loss, blue, 2.0);
  plot.line(miou, red, 2.0);
  plot.line(big, green, 2.0);
  plot.legend({{"training loss", blue}, {"validation mean IoU", red}, {"validation mean IoU, 8 big classes", green}});
  plot.save_png(file);
}

/// Writes NAME.pt and NAME.yaml (the description naming NAME.pt) into out.
void write_model(const SegmentTrainer& trainer, SegmenterSpec spec, const fs::path& out, const std::string& name) {
  const fs::path weights = out / (name + ".pt");
  trainer.save_model(weights);
  spec.network.weights = weights.string();
  write_file_atomically(out / (name + ".yaml"),
                        "# A SegNet model trained by saloam segment-train (docs/segmentation.md).\n" +
                            segmenter_spec_yaml(spec, out));
}

nlohmann::json projection_json(const ProjectionSpec& p) { return {{"means", p.means}, {"stds", p.stds}}; }

/// The model's description: ring rows, the beam counts trained on, the
/// training data's channel statistics, the 20 SemanticKITTI classes.
SegmenterSpec initial_spec(const std::vector<TrainingScanSet>& train, const SegmentTrainOptions& options) {
  SegmenterSpec spec;
  spec.network.shape = options.shape;
  spec.projection.row_mode = RowMode::kRing;
  spec.projection.columns = options.columns;
  spec.classes = semantickitti_learning_classes();
  spec.network.shape.in_channels = static_cast<int>(spec.projection.channels.size());
  spec.network.shape.classes = static_cast<int>(spec.classes.size());
  for (const auto& s : train)
    for (const auto& scan : s.scans)
      if (std::find(spec.beams.begin(), spec.beams.end(), scan.beams) == spec.beams.end()) spec.beams.push_back(scan.beams);
  std::sort(spec.beams.begin(), spec.beams.end());
  return spec;
}

void check_data(const std::vector<TrainingScanSet>& train, const SegmentTrainOptions& options) {
  if (options.epochs < 1) throw ConfigError("--epochs must be at least 1");
  if (options.batch < 1) throw ConfigError("--batch must be at least 1");
  std::size_t scans = 0;
  for (const auto& s : train) {
    scans += s.scans.size();
    for (const auto& scan : s.scans)
      if (const auto problem = segnet_size_problem(options.shape, scan.beams, options.columns); !problem.empty())
        throw ConfigError(fmt::format("{}: a {}-beam scan does not fit the network: {}", s.name, scan.beams, problem));
  }
  if (scans == 0) throw ConfigError("the training data hold no scan");
}

}  // namespace

SegmentTrainOptions resumed_options(const fs::path& out, const SegmentTrainOptions& given) {
  const nlohmann::json state = read_checkpoint_state(out);
  try {
    SegmentTrainOptions options = options_from_json(state.at("options"), given);
    options.resume = true;
    return options;
  } catch (const nlohmann::json::exception&) {
    throw InputError(out / "checkpoint" / "state.json", "not a segment-train checkpoint (options unreadable)");
  }
}

namespace {

/// A run's network, description and history so far: fresh (channel
/// statistics fitted on the training data), fine-tuned from --init, or
/// resumed from the checkpoint in options.out.
struct RunState {
  SegmenterSpec spec;
  std::unique_ptr<SegmentTrainer> trainer;
  SegmentTrainResult result;
};

RunState start_run(const std::vector<TrainingScanSet>& train, const SegmentTrainOptions& options,
                   const nlohmann::json& options_key) {
  RunState run;
  run.spec = initial_spec(train, options);
  run.trainer = std::make_unique<SegmentTrainer>(run.spec.network.shape, options.seed, options);
  run.trainer->set_class_weights(class_weights_from_counts(class_counts(train), options.class_weight_factors));
  if (options.resume) {
    const nlohmann::json state = read_checkpoint_state(options.out);
    if (state["options"] != options_key)
      throw ConfigError(fmt::format("--resume: the options differ from those of the run in {} ({} there, {} now); resume "
                                    "with the same options (only --epochs may change)",
                                    options.out.string(), state["options"].dump(), options_key.dump()));
    run.spec.projection.means = state.at("projection").at("means").get<std::vector<float>>();
    run.spec.projection.stds = state.at("projection").at("stds").get<std::vector<float>>();
    run.trainer->load_model(options.out / "checkpoint" / "model.pt");
    run.trainer->load_optimizer(options.out / "checkpoint" / "optimizer.pt");
    run.result.best_epoch = state.at("best_epoch").get<int>();
    for (const auto& r : state.at("history")) run.result.history.push_back(record_from_json(r));
    spdlog::info("resuming after epoch {} of {}", run.result.history.size(), options.out.string());
  } else if (!options.init.empty()) {
    const SegmenterSpec init = read_segmenter_spec(options.init);
    if (init.network.format != NetworkFormat::kSegNet || init.network.shape.widths != run.spec.network.shape.widths ||
        init.network.shape.stem_stride != run.spec.network.shape.stem_stride ||
        init.network.shape.context_blocks != run.spec.network.shape.context_blocks ||
        init.projection.channels != run.spec.projection.channels || init.classes != run.spec.classes)
      throw InputError(options.init, "--init: not a SegNet of this run's architecture, channels and classes");
    run.spec.projection.means = init.projection.means;
    run.spec.projection.stds = init.projection.stds;
    run.trainer->load_model(init.network.weights);
  } else {
    fit_channel_statistics(train, run.spec.projection, 10);
  }
  return run;
}

SegmentEpochRecord epoch_record(int epoch, const EpochLoss& trained, const SegmentationScore& validation,
                                std::chrono::steady_clock::time_point start) {
  SegmentEpochRecord record;
  record.epoch = epoch;
  record.loss = trained.loss;
  record.learning_rate = trained.learning_rate;
  record.samples = trained.samples;
  record.samples_per_second = trained.seconds > 0 ? static_cast<double>(trained.samples) / trained.seconds : 0.0;
  fill_validation(record, validation);
  record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return record;
}

/// After an epoch: the models, the checkpoint, training.json and the curves.
void write_epoch(const RunState& run, const SegmentTrainOptions& options, const nlohmann::json& options_key,
                 const nlohmann::json& run_info, const std::array<std::uint64_t, kNumLearningClasses>& counts) {
  const auto& history = run.result.history;
  if (run.result.best_epoch == history.back().epoch) write_model(*run.trainer, run.spec, options.out, "best");
  write_model(*run.trainer, run.spec, options.out, "model");
  replace_checkpoint(options.out, [&](const fs::path& dir) {
    run.trainer->save_model(dir / "model.pt");
    run.trainer->save_optimizer(dir / "optimizer.pt");
    nlohmann::json state{{"epochs_done", history.back().epoch}, {"options", options_key},
                         {"best_epoch", run.result.best_epoch}, {"projection", projection_json(run.spec.projection)},
                         {"history", nlohmann::json::array()}};
    for (const auto& r : history) state["history"].push_back(record_json(r));
    write_json_atomically(dir / "state.json", state);
  });
  nlohmann::json log = run_info;
  log["options"] = options_key;
  log["epochs_planned"] = options.epochs;
  log["class_points"] = counts;
  log["projection"] = projection_json(run.spec.projection);
  log["best_epoch"] = run.result.best_epoch;
  log["epochs"] = nlohmann::json::array();
  for (const auto& r : history) log["epochs"].push_back(record_json(r));
  write_json_atomically(options.out / "training.json", log);
  plot_curves(options.out / "curves.png", run.result);
}

}  // namespace

SegmentTrainResult train_segmenter(const std::vector<TrainingScanSet>& train, const std::vector<TrainingScanSet>& validation,
                                   const SegmentTrainOptions& options, const nlohmann::json& run_info,
                                   const std::function<void(const SegmentEpochRecord&)>& on_epoch) {
  check_data(train, options);
  set_training_threads(options.threads);
  create_folder(options.out);
  const nlohmann::json options_key = options_json(options);
  RunState run = start_run(train, options, options_key);
  const auto counts = class_counts(train);
  const auto subset = validation_subset(validation, options.validation_scans);
  const int first_epoch = run.result.history.empty() ? 1 : run.result.history.back().epoch + 1;
  for (int epoch = first_epoch; epoch <= options.epochs; ++epoch) {
    const auto start = std::chrono::steady_clock::now();
    const EpochLoss trained = train_epoch(*run.trainer, train, run.spec.projection, options, epoch);
    if (trained.interrupted) {
      run.result.interrupted = true;
      spdlog::warn("interrupted in epoch {}: it is dropped; the checkpoint after epoch {} is kept (continue with --resume)",
                   epoch, epoch - 1);
      break;
    }
    const SegmentEpochRecord record =
        epoch_record(epoch, trained, score_scans(Segmenter(run.spec, run.trainer->runner()), subset), start);
    auto& result = run.result;
    if (result.best_epoch == 0 || record.val_miou > result.history.at(result.best_epoch - 1).val_miou)
      result.best_epoch = epoch;
    result.history.push_back(record);
    write_epoch(run, options, options_key, run_info, counts);
    if (on_epoch) on_epoch(record);
  }
  return run.result;
}

}  // namespace saloam
