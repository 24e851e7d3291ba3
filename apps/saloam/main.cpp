// saloam: semantic-aided LiDAR SLAM with loop closure. Thin command-line
// front end: every subcommand lives in its own cmd_*.cpp.

#include <algorithm>

#include "command.hpp"
#include "program.hpp"

int main(int argc, char** argv) {
  using namespace saloam::cli;
  setup_logging();
  CLI::App app{"saloam: semantic-aided LiDAR SLAM with loop closure (SA-LOAM)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "saloam 0.1.0");
  Verbosity verbosity;
  verbosity.add_to(app);

  auto& registry = command_registry();
  std::stable_sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.order < b.order; });
  std::function<int()> runner;
  for (auto& command : registry) {
    CLI::App* sub = app.add_subcommand(command.name, command.description);
    auto run = command.setup(*sub);
    sub->callback([run, &runner] { runner = run; });
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    return print_parse_error(e);
  }
  verbosity.apply();
  return run_guarded([&] { return runner ? runner() : 1; });
}
