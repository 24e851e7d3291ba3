// saloam-segment-train: trains SegNet, saloam's range-image segmentation
// network (libtorch, CPU), on labelled scans of simulated or real sequences
// described by a data recipe; writes best.pt/best.yaml (the model
// description --segmenter reads), checkpoints, training.json and curves.png
// (train/segment_trainer.hpp, docs/segmentation.md). Users run it as
// `saloam segment-train`, which hands its arguments over: a program of its
// own, so that only training loads libtorch.

#include <algorithm>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "program.hpp"
#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/train/data_recipe.hpp"
#include "saloam/train/segment_trainer.hpp"

namespace saloam::cli {
namespace {

namespace fs = std::filesystem;

struct SegmentTrainArgs {
  std::string data, out, resume, widths = "16,32,64";
  std::vector<std::string> class_weights;  ///< NAME=FACTOR
  std::vector<std::string> augments;       ///< NAME=VALUE
  bool no_cache = false;
  SegmentTrainOptions options;
};

std::array<int, 3> parse_widths(const std::string& text) {
  std::array<int, 3> widths{};
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  if (!(in >> widths[0] >> c1 >> widths[1] >> c2 >> widths[2]) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof())
    throw ConfigError("--widths: expected three numbers like 16,32,64, not '" + text + "'");
  for (int w : widths)
    if (w < 4 || w > 512) throw ConfigError("--widths: each width must lie in [4, 512]");
  return widths;
}

/// The recipe of a run, with absolute paths, kept in the output folder so
/// that --resume needs nothing else (JSON is YAML).
void keep_recipe(const fs::path& out, const DataRecipe& recipe) {
  write_file_atomically(out / "recipe.yaml", recipe_to_json(recipe).dump(2) + '\n');
}

std::vector<TrainingScanSet> build_sequences(const std::vector<SourceSpec>& specs, const fs::path& out, bool cache) {
  std::vector<TrainingScanSet> sequences;
  for (const auto& spec : specs) {
    sequences.push_back(build_training_scans(spec, FeatureConfig{}, cache ? std::optional(out / "scans") : std::nullopt,
                                            spdlog::get_level() <= spdlog::level::info));
    if (stop_requested()) return {};
    const auto& s = sequences.back();
    std::size_t points = 0;
    for (const auto& scan : s.scans) points += scan.size();
    spdlog::info("{}: {} scans, {:.0f} points on average", s.name, s.scans.size(),
                 s.scans.empty() ? 0.0 : static_cast<double>(points) / static_cast<double>(s.scans.size()));
  }
  return sequences;
}

/// --class-weight NAME=FACTOR, each class once (set_class_weight_factor checks the pair).
std::array<double, kNumLearningClasses> parse_class_weights(const std::vector<std::string>& items) {
  auto factors = uniform_class_factors();
  std::vector<std::string> given;
  for (const std::string& item : items) {
    const auto eq = item.find('=');
    const std::string name = item.substr(0, eq);
    double factor = 0;
    std::istringstream in(eq == std::string::npos ? std::string() : item.substr(eq + 1));
    if (!(in >> factor) || !(in >> std::ws).eof())
      throw ConfigError(fmt::format("--class-weight: expected CLASS=FACTOR, not '{}'", item));
    if (std::find(given.begin(), given.end(), name) != given.end())
      throw ConfigError(fmt::format("--class-weight: {} is given twice", name));
    given.push_back(name);
    set_class_weight_factor(factors, name, factor);
  }
  return factors;
}

SegmentTrainOptions run_options(const SegmentTrainArgs& args, const CLI::App& app) {
  SegmentTrainOptions options = args.options;
  options.show_progress = spdlog::get_level() <= spdlog::level::info;
  if (args.resume.empty()) {
    if (args.out.empty()) throw ConfigError("give --out DIR (a new run) or --resume DIR (continue a run)");
    if (args.data.empty()) throw ConfigError("--data RECIPE.yaml is required for a new run");
    options.out = args.out;
    if (fs::exists(options.out / "checkpoint"))
      throw ConfigError(fmt::format("{} already holds a training run: continue it with --resume {} or choose another --out",
                                    args.out, args.out));
    options.shape.widths = parse_widths(args.widths);
    options.class_weight_factors = parse_class_weights(args.class_weights);
    for (const std::string& item : args.augments) {
      const auto eq = item.find('=');
      if (eq == std::string::npos) throw ConfigError(fmt::format("--augment: expected NAME=VALUE, not '{}'", item));
      set_augment_option(options.augment, item.substr(0, eq), item.substr(eq + 1));
    }
    return options;
  }
  for (const auto* option : app.get_options())
    if (option->count() > 0 && option->get_name() != "--resume" && option->get_name() != "--epochs" &&
        option->get_name() != "--verbose" && option->get_name() != "--quiet")
      throw ConfigError(fmt::format("--resume continues the run with its own options: give only --epochs (not {})",
                                    option->get_name()));
  options.out = args.resume;
  return resumed_options(options.out, options);
}

int run_segment_train(const SegmentTrainArgs& args, const CLI::App& app) {
  const SegmentTrainOptions options = run_options(args, app);
  SourceSpec defaults;
  defaults.noisy_labels = false;  // segmentation learns from the ground truth
  const DataRecipe recipe =
      read_data_recipe(args.data.empty() ? options.out / "recipe.yaml" : fs::path(args.data), defaults);
  check_training_paths(recipe, args.data, options.resume ? fs::path() : options.init, options.out);
  keep_recipe(options.out, recipe);
  const auto train = build_sequences(recipe.train, options.out, !args.no_cache);
  if (stop_requested()) return 130;
  const auto validation = build_sequences(recipe.validation, options.out, !args.no_cache);
  if (stop_requested()) return 130;

  nlohmann::json info;
  info["data"] = recipe_to_json(recipe);
  std::cout << fmt::format("segment-train: {} {}, {} epochs of {} samples, batch {}, lr {:g}, seed {}, {} thread(s)\n",
                           options.resume ? "resuming" : "training", options.out.string(), options.epochs,
                           options.samples_per_epoch, options.batch, options.learning_rate, options.seed, options.threads);
  const auto result = train_segmenter(train, validation, options, info, [&](const SegmentEpochRecord& r) {
    std::cout << fmt::format("epoch {:>3}/{}: loss {:.4f}, lr {:.2g}, {:.1f} samples/s, validation mIoU {:.1f} % (8 big "
                             "classes {:.1f} %), {:.0f} s\n",
                             r.epoch, options.epochs, r.loss, r.learning_rate, r.samples_per_second, 100 * r.val_miou,
                             100 * r.val_big_miou, r.seconds)
              << std::flush;
  });
  if (result.best_epoch > 0)
    std::cout << fmt::format("best validation mIoU {:.1f} % (epoch {}); wrote {} (best), {} (last), training.json, "
                             "curves.png\n",
                             100 * result.history.at(static_cast<std::size_t>(result.best_epoch - 1)).val_miou,
                             result.best_epoch, (options.out / "best.yaml").string(), (options.out / "model.yaml").string());
  return result.interrupted ? 130 : 0;
}

std::function<int()> add_segment_train_options(CLI::App& app) {
  auto args = std::make_shared<SegmentTrainArgs>();
  auto& o = args->options;
  app.add_option("--data", args->data,
                 "Data recipe (YAML): train and validation sources with ground-truth labels, simulated (simulate: "
                 "POSES.txt, beams: 64|32|16) or folders (folder: DIR); see docs/segmentation.md");
  app.add_option("--out", args->out, "Output folder of a new run (models, checkpoint/, training.json, curves.png, scans/)");
  app.add_option("--resume", args->resume, "Continue the run in this folder from its last checkpoint (with its options)");
  app.add_option("--init", o.init, "A SegNet description (.yaml) to fine-tune (same architecture); default: from scratch");
  app.add_option("--epochs", o.epochs, "Epochs in all (a resumed run continues up to this)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--samples-per-epoch", o.samples_per_epoch, "Training samples per epoch")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000000}))
      ->capture_default_str();
  app.add_option("--batch", o.batch, "Samples per optimisation step")->check(CLI::Range(1, 1024))->capture_default_str();
  app.add_option("--pixels-per-sample", o.pixels_per_sample, "A sample is cut to about this many pixels")
      ->check(CLI::Range(1024, 1 << 22))
      ->capture_default_str();
  app.add_option("--columns", o.columns, "Columns of the range image")->check(CLI::Range(64, 16384))->capture_default_str();
  app.add_option("--lr", o.learning_rate, "Adam's peak learning rate")->check(positive_number())->capture_default_str();
  app.add_option("--weight-decay", o.weight_decay, "Adam weight decay (L2)")->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--lovasz", o.lovasz_weight, "Weight of the Lovasz-softmax loss (0: cross-entropy only)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--class-weight", args->class_weights,
                 "CLASS=FACTOR: multiply a class's loss weight (1 / sqrt of its frequency) by FACTOR, e.g. pole=2 to "
                 "favour its recall (repeatable; weights are then scaled to mean 1)");
  app.add_option("--augment", args->augments,
                 "NAME=VALUE: set one augmentation (repeatable), e.g. remission_constant=0; names and defaults in "
                 "docs/segmentation.md (training.json lists those used)");
  app.add_option("--seed", o.seed, "Seed of the initialisation, samples and augmentations")->capture_default_str();
  app.add_option("--threads", o.threads, "libtorch threads (results are reproducible for a fixed count)")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  app.add_option("--widths", args->widths, "SegNet's channels at its three levels")->capture_default_str();
  app.add_option("--stem-stride", o.shape.stem_stride, "SegNet: column stride of the stem")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  app.add_option("--context-blocks", o.shape.context_blocks, "SegNet: residual blocks at the lowest level")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  app.add_option("--validation-scans", o.validation_scans, "Validation scans scored per epoch (at most)")
      ->capture_default_str();
  app.add_flag("--no-cache", args->no_cache, "Rebuild the scans instead of reusing OUT/scans/");
  return [args, &app] { return run_segment_train(*args, app); };
}

}  // namespace
}  // namespace saloam::cli

int main(int argc, char** argv) {
  return saloam::cli::run_program(
      argc, argv, "Train the segmentation network SegNet (libtorch, CPU) on labelled simulated or real sequences",
      "saloam segment-train", saloam::cli::add_segment_train_options);
}
