// `saloam segment-train`: hands its arguments to the trainer program,
// saloam-segment-train, installed beside saloam when libtorch was found at
// build time (a program of its own so that only it loads libtorch).

#include "command.hpp"

namespace saloam::cli {
namespace {

const CommandRegistration kRegistration{Command{
    "segment-train", "Train the segmentation network (libtorch, CPU) on labelled simulated or real sequences", 44,
    [](CLI::App& app) {
      // Every argument, --help included, is the trainer's to parse.
      app.set_help_flag();
      app.prefix_command();
      return [&app] { return forward_to_program("saloam-segment-train", app.remaining()); };
    }}};

}  // namespace
}  // namespace saloam::cli
