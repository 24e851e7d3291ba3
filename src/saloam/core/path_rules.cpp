#include "saloam/core/path_rules.hpp"

#include <fmt/format.h>

#include "saloam/core/error.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

// The path's components without empty ones and `.` (a trailing separator).
std::vector<fs::path> components(const fs::path& path) {
  std::vector<fs::path> parts;
  for (const fs::path& part : path) {
    if (!part.empty() && part != ".") parts.push_back(part);
  }
  return parts;
}

// Same path, or one file under two names (a hard link; both must exist).
bool same_place(const fs::path& a, const fs::path& b) {
  if (components(a) == components(b)) return true;
  std::error_code ec;
  return fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec) && !ec;
}

// `inner` is `outer` or lies inside it: by components, or because an
// existing folder along `inner` is `outer` itself under another name (a bind
// mount of it: the same device and inode, which no path comparison sees).
bool lies_within(const fs::path& inner, const fs::path& outer) {
  if (path_within(inner, outer)) return true;
  std::error_code ec;
  if (!fs::is_directory(outer, ec)) return false;
  for (fs::path p = inner; !p.empty(); p = p.parent_path()) {
    if (fs::exists(p, ec) && fs::equivalent(p, outer, ec) && !ec) return true;
    if (p == p.root_path()) break;
  }
  return false;
}

std::string named(const std::string& option, const fs::path& given) {
  return option.empty() ? given.string() : fmt::format("{} {}", option, given.string());
}

}  // namespace

fs::path comparable_path(const fs::path& path) {
  std::error_code ec;
  fs::path absolute = fs::absolute(path, ec);
  if (ec) absolute = path;
  // Component by component, as a run that creates the missing folders
  // would reach it: `..` goes up from what the path so far resolved to, and
  // a link is followed wherever it appears, also after a missing folder and
  // `..` ("new/../link": weakly_canonical takes it lexically, not the link).
  fs::path out = absolute.root_path();
  for (const fs::path& part : absolute.relative_path()) {
    if (part.empty() || part == ".") continue;
    if (part == "..") {
      out = out.parent_path();
      continue;
    }
    out /= part;
    if (fs::is_symlink(out, ec)) {
      const fs::path target = fs::canonical(out, ec);
      if (!ec) out = target;  // a dangling or looping link stays as named
    }
  }
  return out;
}

bool path_within(const fs::path& inner, const fs::path& outer) {
  const std::vector<fs::path> in = components(inner);
  const std::vector<fs::path> out = components(outer);
  if (out.size() > in.size()) return false;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (in[i] != out[i]) return false;
  }
  return true;
}

PathRules& PathRules::input(std::string_view option, const fs::path& path) {
  if (!path.empty()) inputs_.push_back({std::string(option), path, comparable_path(path), OutputUse::kFile});
  return *this;
}

PathRules& PathRules::output(std::string_view option, const fs::path& path, OutputUse use) {
  if (!path.empty()) outputs_.push_back({std::string(option), path, comparable_path(path), use});
  return *this;
}

void PathRules::check() const {
  for (const Entry& out : outputs_) {
    for (const Entry& in : inputs_) {
      const std::string what = named(out.option, out.given), input = named(in.option, in.given);
      if (same_place(out.path, in.path)) {
        throw InputError(out.given, fmt::format("{} is the input {}: an output never replaces an input (choose another "
                                                "output)", what, input));
      }
      if (lies_within(in.path, out.path)) {
        throw InputError(out.given, fmt::format("{} holds the input {}: an output never contains an input (choose "
                                                "another output)", what, input));
      }
      if (lies_within(out.path, in.path)) {
        throw InputError(out.given, fmt::format("{} lies inside the input {}: an output is never written into an "
                                                "input (choose another output)", what, input));
      }
    }
  }
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    for (std::size_t j = i + 1; j < outputs_.size(); ++j) {
      const Entry& a = outputs_[i];
      const Entry& b = outputs_[j];
      if (same_place(a.path, b.path)) {
        throw InputError(b.given, fmt::format("{} is also {}: two outputs of one run name the same place",
                                              named(b.option, b.given), named(a.option, a.given)));
      }
      for (const auto& [replaced, other] : {std::pair{&a, &b}, std::pair{&b, &a}}) {
        if (replaced->use == OutputUse::kReplacedFolder && lies_within(other->path, replaced->path)) {
          throw InputError(replaced->given,
                           fmt::format("{} holds the output {}: replacing the folder would delete it (choose "
                                       "another folder)", named(replaced->option, replaced->given),
                                       named(other->option, other->given)));
        }
      }
    }
  }
}

}  // namespace saloam
