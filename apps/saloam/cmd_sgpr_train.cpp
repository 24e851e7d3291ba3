// `saloam sgpr-train`: hands its arguments to the trainer program,
// saloam-sgpr-train, installed beside saloam when libtorch was found at build
// time. Training is a program of its own so that only it loads libtorch,
// whose start-up would otherwise cost every saloam command about a second.

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "command.hpp"
#include "saloam/core/error.hpp"

namespace saloam::cli {
namespace {

constexpr const char* kTrainer = "saloam-sgpr-train";

int forward_to_trainer(const std::vector<std::string>& arguments) {
  const auto bin = program_dir();
  const auto trainer = bin ? *bin / kTrainer : std::filesystem::path(kTrainer);
  std::error_code error;
  if (!bin || !std::filesystem::is_regular_file(trainer, error)) {
    spdlog::error("this saloam was built without libtorch: sgpr-train is not available (install libtorch-dev, e.g. "
                  "scripts/install_deps.sh, and rebuild; the trainer is the program {})",
                  trainer.string());
    return 2;
  }
  std::vector<std::string> args{trainer.string()};
  if (spdlog::get_level() >= spdlog::level::warn) args.emplace_back("--quiet");
  if (spdlog::get_level() <= spdlog::level::debug) args.emplace_back("--verbose");
  args.insert(args.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  execv(argv[0], argv.data());
  throw InputError(trainer, std::string("cannot run the trainer: ") + std::strerror(errno));
}

const CommandRegistration kRegistration{Command{
    "sgpr-train", "Train or fine-tune the SGPR network (libtorch, CPU) on simulated or real sequences", 43,
    [](CLI::App& app) {
      // Every argument, --help included, is the trainer's to parse.
      app.set_help_flag();
      app.prefix_command();
      return [&app] { return forward_to_trainer(app.remaining()); };
    }}};

}  // namespace
}  // namespace saloam::cli
