// `saloam sgpr-train`: hands its arguments to the trainer program,
// saloam-sgpr-train, installed beside saloam when libtorch was found at build
// time. Training is a program of its own so that only it loads libtorch,
// whose start-up would otherwise cost every saloam command about a second.

#include "command.hpp"

namespace saloam::cli {
namespace {

const CommandRegistration kRegistration{Command{
    "sgpr-train", "Train or fine-tune the SGPR network (libtorch, CPU) on simulated or real sequences", 43,
    [](CLI::App& app) {
      // Every argument, --help included, is the trainer's to parse.
      app.set_help_flag();
      app.prefix_command();
      return [&app] { return forward_to_program("saloam-sgpr-train", app.remaining()); };
    }}};

}  // namespace
}  // namespace saloam::cli
