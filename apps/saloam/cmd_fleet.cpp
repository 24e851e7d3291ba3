// `saloam fleet DRIVES... --out MAP`: fleet mapping on Dask (docs/fleet.md).
// The work is the Python package's (saloam.fleet: a Dask task per drive's
// SLAM, a tree of pairwise merges): this command replaces itself by the
// interpreter the package was built for, running `-m saloam.fleet` with the
// package first on PYTHONPATH and this program as the one the tasks run.

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <unistd.h>

#include "command.hpp"
#include "saloam/core/error.hpp"

namespace saloam::cli {
namespace {

/// The folder holding the package `saloam`: the build tree's python/ beside
/// the program, or <prefix>/SALOAM_INSTALL_PYTHON_RELATIVE when installed.
std::optional<std::filesystem::path> python_package_dir() {
  const auto bin = program_dir();
  if (!bin) return std::nullopt;
  std::error_code error;
  for (const auto& dir : {*bin / "python", (*bin / SALOAM_INSTALL_PYTHON_RELATIVE).lexically_normal()}) {
    if (std::filesystem::is_regular_file(dir / "saloam" / "fleet.py", error)) return dir;
  }
  return std::nullopt;
}

int run_fleet(const std::vector<std::string>& arguments) {
  const auto package = python_package_dir();
  if (!package) {
    spdlog::error("saloam fleet needs the Python package (saloam/fleet.py beside the program in python/, or in "
                  "<prefix>/{}): this saloam was built without it (install pybind11-dev python3-dev "
                  "python3-distributed, e.g. scripts/install_deps.sh, and rebuild)",
                  SALOAM_INSTALL_PYTHON_RELATIVE);
    return 2;
  }
  const char* old_path = std::getenv("PYTHONPATH");
  const std::string python_path = package->string() + (old_path && *old_path ? ":" + std::string(old_path) : "");
  setenv("PYTHONPATH", python_path.c_str(), 1);
  if (const auto bin = program_dir()) setenv("SALOAM_CLI", (*bin / "saloam").c_str(), 1);
  std::vector<std::string> args{SALOAM_PYTHON_EXECUTABLE, "-m", "saloam.fleet"};
  args.insert(args.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  execv(argv[0], argv.data());
  throw InputError(SALOAM_PYTHON_EXECUTABLE, std::string("cannot run: ") + std::strerror(errno));
}

const CommandRegistration kRegistration{Command{
    "fleet",
    "Fleet mapping on Dask: every drive's SLAM a task, the maps merged by a tree of pairwise merges "
    "(DRIVES... --out MAP [--scheduler tcp://HOST:8786] [--workers N]; `saloam fleet --help`)",
    29, [](CLI::App& app) {
      auto arguments = std::make_shared<std::vector<std::string>>();
      app.set_help_flag();  // --help is the Python side's
      app.allow_extras();
      app.prefix_command();
      return [arguments, &app] {
        *arguments = app.remaining();
        return run_fleet(*arguments);
      };
    }}};

}  // namespace
}  // namespace saloam::cli
