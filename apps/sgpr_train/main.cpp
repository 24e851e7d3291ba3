// saloam-sgpr-train: train or fine-tune the SGPR place-recognition network
// (libtorch, CPU) on graphs of simulated or real sequences described by a
// data recipe; writes `.sgw` models for the Eigen inference, checkpoints,
// training.json and curves.png. Users run it as `saloam sgpr-train`, which
// hands its arguments over: a program of its own, so that only training
// loads libtorch (whose start-up costs every other command about a second).

#include <cstdint>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <type_traits>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "program.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/profiling.hpp"
#include "saloam/train/graph_dataset.hpp"
#include "saloam/train/sgpr_trainer.hpp"

namespace saloam::cli {
namespace {

struct SgprTrainArgs {
  std::string data, out, resume, init;
  int epochs = 20;
  int batch = 16;
  double lr = 1e-3;
  double weight_decay = 5e-4;
  std::uint64_t seed = 1;
  int threads = 1;
  std::size_t pairs_per_epoch = 4000;
  double hard_fraction = 0.5;
  std::uint32_t positive_min_gap = 0;
  double dropout = 0.1;
  double jitter = 0.1;
  bool no_cache = false;
};

namespace fs = std::filesystem;

/// The recipe of a run, with absolute paths, kept in the output folder so
/// that --resume needs nothing else (JSON is YAML: read_data_recipe reads it).
void keep_recipe(const fs::path& out, const DataRecipe& recipe) {
  write_file_atomically(out / "recipe.yaml", recipe_to_json(recipe).dump(2) + '\n');
}

std::vector<GraphSequence> build_sequences(const std::vector<SourceSpec>& specs, const fs::path& out, bool cache) {
  std::vector<GraphSequence> sequences;
  for (const auto& spec : specs) {
    const StageTimer timer;
    sequences.push_back(build_graph_sequence(spec, GraphBuilderConfig{}, cache ? std::optional(out / "graphs") : std::nullopt,
                                             spdlog::get_level() <= spdlog::level::info));
    if (stop_requested()) return {};
    const auto& s = sequences.back();
    double nodes = 0;
    for (const auto& g : s.graphs) nodes += static_cast<double>(g.size());
    spdlog::info("{}: {} graphs, {:.1f} nodes on average ({:.1f} s)", s.name, s.graphs.size(),
                 s.graphs.empty() ? 0.0 : nodes / static_cast<double>(s.graphs.size()),
                 timer.elapsed_s());
  }
  return sequences;
}

/// For --resume: the options of the run in `dir` (its checkpoint's) wherever
/// the command line does not give them, so that `--resume DIR --epochs N`
/// continues a run whatever options it was started with.
SgprTrainArgs with_run_options(SgprTrainArgs args, const CLI::App& app, const fs::path& dir) {
  const fs::path file = dir / "checkpoint" / "state.json";
  std::ifstream in(file);
  if (!in) return args;  // train_sgpr reports the missing checkpoint
  const nlohmann::json state = nlohmann::json::parse(in, nullptr, false);
  if (state.is_discarded() || !state.contains("options")) throw InputError(file, "not a checkpoint state");
  const nlohmann::json& o = state["options"];
  const auto take = [&](const char* option, const char* key, auto& value, const nlohmann::json& from) {
    if (app.count(option) == 0 && from.contains(key)) value = from[key].get<std::decay_t<decltype(value)>>();
  };
  take("--batch", "batch", args.batch, o);
  take("--seed", "seed", args.seed, o);
  take("--threads", "threads", args.threads, o);
  take("--lr", "learning_rate", args.lr, o);
  take("--weight-decay", "weight_decay", args.weight_decay, o);
  take("--pairs-per-epoch", "pairs_per_epoch", args.pairs_per_epoch, o);
  take("--hard-fraction", "hard_fraction", args.hard_fraction, o);
  take("--positive-min-gap", "positive_min_gap", args.positive_min_gap, o);
  if (o.contains("augment")) {
    take("--node-dropout", "node_dropout", args.dropout, o["augment"]);
    take("--jitter", "jitter_sigma", args.jitter, o["augment"]);
  }
  return args;
}

/// Where the run goes: --out for a new run (not one that holds a run
/// already), or --resume's folder.
void choose_output(const SgprTrainArgs& args, SgprTrainOptions& options) {
  if (!args.resume.empty()) {
    if (!args.out.empty() && fs::path(args.out) != fs::path(args.resume))
      throw ConfigError("--resume DIR continues the run in DIR: leave out --out (or give the same folder)");
    options.out = args.resume;
    options.resume = true;
  } else if (args.out.empty()) {
    throw ConfigError("give --out DIR (a new run) or --resume DIR (continue a run)");
  } else {
    options.out = args.out;
  }
  if (!options.resume && fs::exists(options.out / "checkpoint"))
    throw ConfigError(fmt::format("{} already holds a training run: continue it with --resume {} or choose another --out",
                                  options.out.string(), options.out.string()));
}

/// The options given on the command line (and --resume's run).
void take_options(const SgprTrainArgs& args, SgprTrainOptions& options) {
  if (!args.init.empty()) require_file(args.init, "initial SGPR weights");
  options.init = args.init;
  options.epochs = args.epochs;
  options.batch = args.batch;
  options.seed = args.seed;
  options.threads = args.threads;
  options.optimizer.learning_rate = args.lr;
  options.optimizer.weight_decay = args.weight_decay;
  options.pairs_per_epoch = args.pairs_per_epoch;
  options.hard_fraction = args.hard_fraction;
  options.pairs.positive_min_gap = args.positive_min_gap;
  options.augment.node_dropout = args.dropout;
  options.augment.jitter_sigma = args.jitter;
  options.augment.jitter_clip = 3.0 * args.jitter;
  options.show_progress = spdlog::get_level() <= spdlog::level::info;
}

/// What training.json records of the data.
nlohmann::json data_info(const DataRecipe& recipe, const std::vector<GraphSequence>& train) {
  nlohmann::json info;
  info["data"] = recipe_to_json(recipe);
  info["training_graphs"] = 0;
  for (const auto& s : train) info["training_graphs"] = info["training_graphs"].get<std::size_t>() + s.graphs.size();
  return info;
}

void print_start(const SgprTrainOptions& options) {
  std::cout << fmt::format("sgpr-train: {} from {}, {} epochs, batch {}, lr {:g}, seed {}, {} thread(s)\n",
                           options.resume ? "resuming" : "training",
                           options.resume ? options.out.string() : options.init.empty() ? "scratch" : options.init.string(),
                           options.epochs, options.batch, options.optimizer.learning_rate, options.seed, options.threads);
}

void print_epoch(const EpochRecord& r, int epochs) {
  std::cout << fmt::format("epoch {:>3}/{}: loss {:.4f}, {:.0f} pairs/s, validation max F1 {:.4f} (recall at 100 % "
                           "precision {:.3f}), {:.0f} s\n",
                           r.epoch, epochs, r.loss, r.pairs_per_second, r.val_max_f1, r.val_recall_at_full_precision,
                           r.seconds)
            << std::flush;
}

void print_result(const SgprTrainResult& result, const SgprTrainOptions& options) {
  std::cout << fmt::format("validation max F1: initial weights {:.4f}, best {:.4f} (epoch {}); wrote {} (best), {} "
                           "(last), training.json, curves.png\n",
                           result.initial_val_max_f1,
                           result.best_epoch == 0 ? result.initial_val_max_f1
                                                  : result.history.at(static_cast<std::size_t>(result.best_epoch - 1)).val_max_f1,
                           result.best_epoch, (options.out / "best.sgw").string(), (options.out / "model.sgw").string());
}

int run_sgpr_train(const SgprTrainArgs& given, const CLI::App& app) {
  const SgprTrainArgs args = given.resume.empty() ? given : with_run_options(given, app, given.resume);
  SgprTrainOptions options;
  choose_output(args, options);
  if (args.data.empty() && !options.resume) throw ConfigError("--data RECIPE.yaml is required for a new run");
  const DataRecipe recipe = read_data_recipe(!args.data.empty() ? fs::path(args.data) : options.out / "recipe.yaml");
  take_options(args, options);
  check_training_paths(recipe, args.data, options.resume ? fs::path() : options.init, options.out);
  keep_recipe(options.out, recipe);

  const auto train = build_sequences(recipe.train, options.out, !args.no_cache);
  if (stop_requested()) return 130;
  const auto validation = build_sequences(recipe.validation, options.out, !args.no_cache);
  if (stop_requested()) return 130;
  print_start(options);
  const auto result = train_sgpr(train, validation, options, data_info(recipe, train),
                                 [&](const EpochRecord& r) { print_epoch(r, options.epochs); });
  print_result(result, options);
  return result.interrupted ? 130 : 0;
}

std::function<int()> add_sgpr_train_options(CLI::App& app) {
  auto args = std::make_shared<SgprTrainArgs>();
  app.add_option("--data", args->data,
                 "Data recipe (YAML): train and validation sources, simulated (simulate: POSES.txt) or folders "
                 "(folder: DIR); see docs/place_recognition.md. A resumed run reuses DIR/recipe.yaml");
  app.add_option("--out", args->out, "Output folder of a new run (models, checkpoint/, training.json, curves.png)");
  app.add_option("--resume", args->resume, "Continue the run in this folder from its last checkpoint");
  app.add_option("--init", args->init, "Weights (.sgw) to fine-tune; default: from scratch (seeded)");
  app.add_option("--epochs", args->epochs, "Epochs in all (a resumed run continues up to this)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--batch", args->batch, "Pairs per optimisation step (each scored in both orders)")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  app.add_option("--lr", args->lr, "Adam learning rate")->check(positive_number())->capture_default_str();
  app.add_option("--weight-decay", args->weight_decay, "Adam weight decay (L2)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--seed", args->seed, "Seed of the initialisation, pairs and augmentations")->capture_default_str();
  app.add_option("--threads", args->threads, "libtorch threads (results are reproducible for a fixed count)")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  app.add_option("--pairs-per-epoch", args->pairs_per_epoch, "Training pairs per epoch (half positive, half negative)")
      ->check(CLI::Range(std::size_t{2}, std::size_t{100000000}))
      ->capture_default_str();
  app.add_option("--hard-fraction", args->hard_fraction, "Share of the negatives mined from the current model")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--positive-min-gap", args->positive_min_gap,
                 "Positives at least this many frames apart in their sequence (0: all pairs within 3 m, as SGPR)")
      ->capture_default_str();
  app.add_option("--node-dropout", args->dropout, "Augmentation: probability of dropping each node")
      ->check(CLI::Range(0.0, 0.9))
      ->capture_default_str();
  app.add_option("--jitter", args->jitter, "Augmentation: node position jitter, sigma [m] (clipped at 3 sigma)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  app.add_flag("--no-cache", args->no_cache, "Rebuild the graphs instead of reusing OUT/graphs/");
  return [args, &app] { return run_sgpr_train(*args, app); };
}

}  // namespace
}  // namespace saloam::cli

int main(int argc, char** argv) {
  return saloam::cli::run_program(
      argc, argv, "Train or fine-tune the SGPR network (libtorch, CPU) on simulated or real sequences",
      "saloam sgpr-train", saloam::cli::add_sgpr_train_options);
}
