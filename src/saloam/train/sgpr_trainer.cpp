#include "saloam/train/sgpr_trainer.hpp"

#include <algorithm>
#include <fstream>
#include <numeric>
#include <random>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "saloam/train/sgpr_torch.hpp"
#include "saloam/train/training_run.hpp"
#include "saloam/viz/canvas.hpp"

namespace saloam {

namespace fs = std::filesystem;

struct SgprTrainer::Impl {
  SgprTorchNet net;
  std::unique_ptr<torch::optim::Adam> adam;

  Impl(const SgprOptimizerOptions& options) {
    adam = std::make_unique<torch::optim::Adam>(
        net->parameters(), torch::optim::AdamOptions(options.learning_rate).weight_decay(options.weight_decay));
  }
};

namespace {

std::vector<const SemanticGraph*> concat(std::span<const SemanticGraph* const> a, std::span<const SemanticGraph* const> b) {
  std::vector<const SemanticGraph*> out(a.begin(), a.end());
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

}  // namespace


SgprTrainer::SgprTrainer(std::uint64_t seed, const SgprOptimizerOptions& options) {
  keep_freed_memory_for_reuse();
  torch::manual_seed(seed);
  impl_ = std::make_unique<Impl>(options);
}

SgprTrainer::SgprTrainer(const SgprWeights& weights, const SgprOptimizerOptions& options) {
  keep_freed_memory_for_reuse();
  impl_ = std::make_unique<Impl>(options);
  load_sgpr_weights(impl_->net, weights);
}

SgprTrainer::~SgprTrainer() = default;

double SgprTrainer::step(std::span<const SemanticGraph* const> first, std::span<const SemanticGraph* const> second,
                         std::span<const float> targets) {
  const auto pairs = static_cast<std::int64_t>(targets.size());
  if (first.size() != targets.size() || second.size() != targets.size() || targets.empty())
    throw std::invalid_argument("SgprTrainer::step: first, second and targets must have the same non-zero size");
  auto& net = impl_->net;
  net->train();
  // All 2B graphs in one batch: batch-norm statistics over every graph of the
  // batch, as in the original, where each branch sees the batch's graphs.
  const torch::Tensor h = net->embed(sgpr_input(concat(first, second)));
  const torch::Tensor h1 = h.narrow(0, 0, pairs), h2 = h.narrow(0, pairs, pairs);
  // Both orders of every pair, as SGPR trains (the head is not symmetric).
  const torch::Tensor logits = torch::cat({net->logits(h1, h2), net->logits(h2, h1)});
  const torch::Tensor target = torch::from_blob(const_cast<float*>(targets.data()), {pairs}, torch::kFloat).repeat({2});
  // BCE on sigmoid(logit), in its numerically stable form.
  const torch::Tensor loss = torch::binary_cross_entropy_with_logits(logits, target);
  impl_->adam->zero_grad();
  loss.backward();
  impl_->adam->step();
  return loss.item<double>();
}

std::vector<double> SgprTrainer::logits(std::span<const SemanticGraph* const> first,
                                        std::span<const SemanticGraph* const> second) const {
  const torch::NoGradGuard no_grad;
  auto& net = impl_->net;
  net->eval();
  const auto pairs = static_cast<std::int64_t>(first.size());
  const torch::Tensor h = net->embed(sgpr_input(concat(first, second)));
  const torch::Tensor l = net->logits(h.narrow(0, 0, pairs), h.narrow(0, pairs, pairs)).to(torch::kDouble).contiguous();
  return {l.data_ptr<double>(), l.data_ptr<double>() + l.numel()};
}

SgprWeights SgprTrainer::weights() const { return sgpr_weights_of(impl_->net); }

void SgprTrainer::save_optimizer(const fs::path& file) const { torch::save(*impl_->adam, file.string()); }

void SgprTrainer::load_optimizer(const fs::path& file) {
  require_file(file, "optimizer state");
  try {
    torch::load(*impl_->adam, file.string());
  } catch (const c10::Error& e) {
    throw InputError(file, std::string("cannot read the optimizer state: ") + e.what_without_backtrace());
  }
}

// ---------------------------------------------------------------- training run

namespace {

nlohmann::json options_json(const SgprTrainOptions& o) {
  return {{"batch", o.batch},
          {"seed", o.seed},
          {"threads", o.threads},
          {"learning_rate", o.optimizer.learning_rate},
          {"weight_decay", o.optimizer.weight_decay},
          {"pairs_per_epoch", o.pairs_per_epoch},
          {"hard_fraction", o.hard_fraction},
          {"hard_pool", o.hard_pool},
          {"positive_distance", o.pairs.positive_distance},
          {"negative_distance", o.pairs.negative_distance},
          {"positive_min_gap", o.pairs.positive_min_gap},
          {"validation_exclude_recent", o.validation.exclude_recent},
          {"augment",
           {{"max_rotation", o.augment.max_rotation},
            {"jitter_sigma", o.augment.jitter_sigma},
            {"jitter_clip", o.augment.jitter_clip},
            {"scale_min", o.augment.scale_min},
            {"scale_max", o.augment.scale_max},
            {"shift", o.augment.shift},
            {"node_dropout", o.augment.node_dropout}}},
          {"init", o.init.empty() ? std::string("scratch") : fs::absolute(o.init).lexically_normal().string()}};
}

nlohmann::json record_json(const EpochRecord& r) {
  return {{"epoch", r.epoch},           {"loss", r.loss},
          {"pairs", r.pairs},           {"pairs_per_second", r.pairs_per_second},
          {"seconds", r.seconds},       {"val_max_f1", r.val_max_f1},
          {"val_recall_at_full_precision", r.val_recall_at_full_precision}};
}

EpochRecord record_from_json(const nlohmann::json& j) {
  EpochRecord r;
  r.epoch = j.at("epoch").get<int>();
  r.loss = j.at("loss").get<double>();
  r.pairs = j.at("pairs").get<std::size_t>();
  r.pairs_per_second = j.at("pairs_per_second").get<double>();
  r.seconds = j.at("seconds").get<double>();
  r.val_max_f1 = j.at("val_max_f1").get<double>();
  r.val_recall_at_full_precision = j.at("val_recall_at_full_precision").get<double>();
  return r;
}


/// One hard negative for `anchor`: uniformly one of its `pool` highest-scoring
/// negatives under the current model (the very hardest alone would repeat).
std::uint32_t hard_negative(const SgprNetwork& network, const std::vector<SgprEmbedding>& embeddings,
                            std::uint32_t anchor, const std::vector<std::uint32_t>& candidates, std::size_t pool,
                            std::mt19937_64& rng) {
  std::vector<SgprEmbedding> others;
  others.reserve(candidates.size());
  for (const auto j : candidates) others.push_back(embeddings[j]);
  const auto logits = network.logit_batch(embeddings[anchor], others);
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const std::size_t keep = std::min(std::max<std::size_t>(pool, 1), order.size());
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep), order.end(),
                    [&](std::size_t a, std::size_t b) { return logits[a] > logits[b] || (logits[a] == logits[b] && a < b); });
  return candidates[order[std::uniform_int_distribution<std::size_t>(0, keep - 1)(rng)]];
}

/// The pairs of one epoch: positives (all, or a random subset) and as many
/// negatives, each for one end of a positive (the anchor), a share of them hard.
std::vector<TrainingPair> epoch_pairs(const SgprWeights& weights, std::span<const GraphSequence> train,
                                      const std::vector<TrainingPair>& positives, const SgprTrainOptions& options,
                                      std::mt19937_64& rng) {
  const SgprNetwork network(weights);
  std::vector<std::vector<SgprEmbedding>> embeddings;
  if (options.hard_fraction > 0)
    for (const auto& s : train) embeddings.push_back(embed_graphs(network, s.graphs));
  std::vector<TrainingPair> chosen = positives;
  std::shuffle(chosen.begin(), chosen.end(), rng);
  chosen.resize(std::min(chosen.size(), std::max<std::size_t>(options.pairs_per_epoch / 2, 1)));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<TrainingPair> pairs = chosen;
  for (const auto& p : chosen) {
    const std::uint32_t anchor = unit(rng) < 0.5 ? p.first : p.second;
    const bool hard = unit(rng) < options.hard_fraction;
    const auto candidates = negative_candidates(train[p.sequence], anchor, options.pairs);
    if (candidates.empty()) continue;
    const std::uint32_t other =
        hard ? hard_negative(network, embeddings[p.sequence], anchor, candidates, options.hard_pool, rng)
             : candidates[std::uniform_int_distribution<std::size_t>(0, candidates.size() - 1)(rng)];
    pairs.push_back({p.sequence, anchor, other, false});
  }
  std::shuffle(pairs.begin(), pairs.end(), rng);
  return pairs;
}

struct EpochLoss {
  double loss = 0;
  std::size_t pairs = 0;
  double seconds = 0;
  bool interrupted = false;
};

EpochLoss train_epoch(SgprTrainer& trainer, std::span<const GraphSequence> train, const std::vector<TrainingPair>& pairs,
                      const SgprTrainOptions& options, int epoch, std::mt19937_64& rng) {
  EpochLoss result;
  const std::size_t batch = static_cast<std::size_t>(std::max(1, options.batch));
  ProgressBar progress(pairs.size(), fmt::format("epoch {}/{}", epoch, options.epochs), options.show_progress);
  const StageTimer timer;
  double loss_sum = 0;
  for (std::size_t begin = 0; begin < pairs.size(); begin += batch) {
    if (stop_requested()) {
      result.interrupted = true;
      break;
    }
    const std::size_t end = std::min(pairs.size(), begin + batch);
    std::vector<SemanticGraph> first, second;
    std::vector<float> targets;
    for (std::size_t k = begin; k < end; ++k) {
      const auto& p = pairs[k];
      // Each graph of the pair augmented on its own, as in SGPR.
      first.push_back(augment_graph(train[p.sequence].graphs[p.first], options.augment, rng));
      second.push_back(augment_graph(train[p.sequence].graphs[p.second], options.augment, rng));
      targets.push_back(p.positive ? 1.0F : 0.0F);
    }
    std::vector<const SemanticGraph*> a, b;
    for (std::size_t k = 0; k < first.size(); ++k) {
      a.push_back(&first[k]);
      b.push_back(&second[k]);
    }
    const double loss = trainer.step(a, b, targets);
    loss_sum += loss * static_cast<double>(targets.size());
    result.pairs += targets.size();
    progress.set_status(fmt::format("loss {:.4f}", loss_sum / static_cast<double>(result.pairs)));
    progress.advance(targets.size());
  }
  progress.finish();
  result.seconds = timer.elapsed_s();
  result.loss = result.pairs ? loss_sum / static_cast<double>(result.pairs) : 0.0;
  return result;
}

void plot_curves(const fs::path& file, const SgprTrainResult& result) {
  Plot plot(800, 500);
  double top = 1.0;
  for (const auto& r : result.history) top = std::max(top, r.loss);
  plot.set_range(0, std::max<double>(1, static_cast<double>(result.history.size())), 0, top * 1.02, false);
  plot.set_title("SGPR training");
  plot.set_labels("epoch", "loss / max F1");
  std::vector<Eigen::Vector2d> loss, f1{{0.0, result.initial_val_max_f1}};
  for (const auto& r : result.history) {
    loss.emplace_back(r.epoch, r.loss);
    f1.emplace_back(r.epoch, r.val_max_f1);
  }
  plot.line(loss, Rgb{31, 119, 180}, 2.0);
  plot.line(f1, Rgb{214, 39, 40}, 2.0);
  for (const auto& p : loss) plot.marker(p, Rgb{31, 119, 180}, 3.0);
  for (const auto& p : f1) plot.marker(p, Rgb{214, 39, 40}, 3.0);
  plot.legend({{"training loss (BCE)", Rgb{31, 119, 180}}, {"validation max F1", Rgb{214, 39, 40}}});
  plot.save_png(file);
}

/// What --resume needs.
void write_checkpoint(const fs::path& out, const SgprTrainer& trainer, const SgprTrainResult& result,
                      const nlohmann::json& options) {
  replace_checkpoint(out, [&](const fs::path& dir) {
    write_sgpr_weights(dir / "model.sgw", trainer.weights());
    trainer.save_optimizer(dir / "optimizer.pt");
    nlohmann::json state;
    state["epochs_done"] = result.history.empty() ? 0 : result.history.back().epoch;
    state["options"] = options;
    state["initial_val_max_f1"] = result.initial_val_max_f1;
    state["best_epoch"] = result.best_epoch;
    state["history"] = nlohmann::json::array();
    for (const auto& r : result.history) state["history"].push_back(record_json(r));
    write_json_atomically(dir / "state.json", state);
  });
}

/// A run's trainer and what it has done so far.
struct TrainingRun {
  std::unique_ptr<SgprTrainer> trainer;
  SgprTrainResult result;
};

TrainingRun resume_run(const fs::path& out, const nlohmann::json& options, const SgprOptimizerOptions& optimizer) {
  const fs::path dir = out / "checkpoint";
  const nlohmann::json state = read_checkpoint_state(out);
  // The initial weights matter only for the first epoch: a resumed run need not name them again.
  nlohmann::json before = state["options"], now = options;
  before.erase("init");
  now.erase("init");
  if (!before.contains("positive_min_gap")) before["positive_min_gap"] = 0;  // runs from before the option
  if (before != now)
    throw ConfigError(fmt::format("--resume: the options differ from those of the run in {} ({} there, {} now); resume "
                                  "with the same options (only --epochs may change)",
                                  out.string(), before.dump(), now.dump()));
  TrainingRun run;
  run.trainer = std::make_unique<SgprTrainer>(read_sgpr_weights(dir / "model.sgw"), optimizer);
  run.trainer->load_optimizer(dir / "optimizer.pt");
  run.result.initial_val_max_f1 = state.at("initial_val_max_f1").get<double>();
  run.result.best_epoch = state.at("best_epoch").get<int>();
  for (const auto& r : state.at("history")) run.result.history.push_back(record_from_json(r));
  spdlog::info("resuming after epoch {} of {}", run.result.history.empty() ? 0 : run.result.history.back().epoch,
               out.string());
  return run;
}

/// A new run from seeded or given (--init) weights; their validation F1 is
/// the one to beat, and they are the best weights until an epoch beats it.
TrainingRun start_run(const SgprTrainOptions& options, std::span<const GraphSequence> validation) {
  TrainingRun run;
  run.trainer = options.init.empty()
                    ? std::make_unique<SgprTrainer>(options.seed, options.optimizer)
                    : std::make_unique<SgprTrainer>(read_sgpr_weights(options.init), options.optimizer);
  run.result.initial_val_max_f1 =
      validate_sgpr(SgprNetwork(run.trainer->weights()), validation, options.validation).max_f1;
  write_sgpr_weights(options.out / "best.sgw", run.trainer->weights());
  return run;
}

EpochRecord epoch_record(int epoch, const EpochLoss& trained, const PrSummary& val, double seconds) {
  EpochRecord record;
  record.epoch = epoch;
  record.loss = trained.loss;
  record.pairs = trained.pairs;
  record.pairs_per_second = trained.seconds > 0 ? static_cast<double>(trained.pairs) / trained.seconds : 0.0;
  record.val_max_f1 = val.max_f1;
  record.val_recall_at_full_precision = val.recall_at_full_precision;
  record.seconds = seconds;
  return record;
}

double best_f1(const SgprTrainResult& r) {
  double best = r.initial_val_max_f1;
  for (const auto& e : r.history)
    if (e.epoch == r.best_epoch) best = e.val_max_f1;
  return best;
}

/// training.json: `log` (the run's description and options) with the epochs so far.
nlohmann::json training_log(nlohmann::json log, const SgprTrainResult& result) {
  log["initial_val_max_f1"] = result.initial_val_max_f1;
  log["best_epoch"] = result.best_epoch;
  log["best_val_max_f1"] = best_f1(result);
  log["epochs"] = nlohmann::json::array();
  for (const auto& r : result.history) log["epochs"].push_back(record_json(r));
  return log;
}

}  // namespace

SgprTrainResult train_sgpr(std::span<const GraphSequence> train, std::span<const GraphSequence> validation,
                           const SgprTrainOptions& options, const nlohmann::json& run_info,
                           const std::function<void(const EpochRecord&)>& on_epoch) {
  if (options.epochs < 1) throw ConfigError("--epochs must be at least 1");
  if (options.batch < 1) throw ConfigError("--batch must be at least 1");
  const auto positives = positive_pairs(train, options.pairs);
  if (positives.empty())
    throw ConfigError(fmt::format("the training data have no positive pair (two scans within {} m, at least {} frames "
                                  "apart): add revisits, or a smaller frame step or --positive-min-gap",
                                  options.pairs.positive_distance, options.pairs.positive_min_gap));
  set_training_threads(options.threads);
  create_folder(options.out);
  const nlohmann::json options_key = options_json(options);
  TrainingRun run = options.resume ? resume_run(options.out, options_key, options.optimizer)
                                   : start_run(options, validation);
  SgprTrainResult& result = run.result;
  spdlog::info("{} positive pairs in the training data; validation max F1 of the initial weights {:.4f}",
               positives.size(), result.initial_val_max_f1);

  const int first_epoch = result.history.empty() ? 1 : result.history.back().epoch + 1;
  for (int epoch = first_epoch; epoch <= options.epochs; ++epoch) {
    const StageTimer timer;
    std::mt19937_64 rng = epoch_generator(options.seed, epoch);
    const auto pairs = epoch_pairs(run.trainer->weights(), train, positives, options, rng);
    const EpochLoss trained = train_epoch(*run.trainer, train, pairs, options, epoch, rng);
    if (trained.interrupted) {
      result.interrupted = true;
      spdlog::warn("interrupted in epoch {}: it is dropped; the checkpoint after epoch {} is kept (continue with --resume)",
                   epoch, epoch - 1);
      break;
    }
    const SgprWeights weights = run.trainer->weights();
    const PrSummary val = validate_sgpr(SgprNetwork(weights), validation, options.validation);
    const EpochRecord record = epoch_record(epoch, trained, val, timer.elapsed_s());
    const bool best = val.max_f1 > best_f1(result);
    result.history.push_back(record);
    if (best) {
      result.best_epoch = epoch;
      write_sgpr_weights(options.out / "best.sgw", weights);
    }
    write_sgpr_weights(options.out / "model.sgw", weights);
    write_checkpoint(options.out, *run.trainer, result, options_key);
    nlohmann::json log = run_info;
    log["options"] = options_key;
    log["epochs_planned"] = options.epochs;
    log["positive_pairs_available"] = positives.size();
    write_json_atomically(options.out / "training.json", training_log(std::move(log), result));
    plot_curves(options.out / "curves.png", result);
    if (on_epoch) on_epoch(record);
  }
  return result;
}

}  // namespace saloam
