// The rule for a command's paths (core/path_rules.hpp): random sets of inputs
// and outputs (plain files, folders added to, folders replaced whole), each
// path made of components that exist or not, `.`, `..`, empty ones (`//`), a
// symbolic link to a folder and two hard links to one file, given absolute or
// relative to the working folder (through `..` up from it). A small model
// resolves every path on its own (lexically from the scratch tree's
// canonical root, the link replaced by its target) and says which pair
// breaks the rule first, in the order check() visits them:
//   output vs input     the same place (equal, or the two names of the hard-linked file),
//                       the input inside the output, or the output inside the input
//   output vs output    the same place, or one inside an output replaced whole
// check() must refuse exactly when the model finds a breach, with an
// InputError that starts with that output and names the other path and both
// options; and accept everything else.
//
// Input bytes: [entries] then per entry [kind] [absolute?] [count] and
// `count` component bytes (each taken modulo the component table).

#include <unistd.h>

#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "fuzz_support.hpp"
#include "saloam/core/path_rules.hpp"

namespace fs = std::filesystem;

namespace {

using Parts = std::vector<std::string>;

// What a path may be made of. In the scratch root: folders a/, a/b/, b/; a
// link L -> a; files h1 and h2, one file under two names. "ab" and "new" do
// not exist ("ab" shares a prefix with "a" as text, not as a component).
const char* const kComponents[] = {"a", "b", "ab", "new", ".", "..", "", "L", "h1", "h2"};
constexpr std::size_t kMaxEntries = 6, kMaxComponents = 6;

struct Scratch {
  fs::path base;  ///< removed when the process ends
  fs::path root;  ///< canonical; deep enough that kMaxComponents `..` stay within the temporary folder
  std::string relative;  ///< root from the working folder, through `..`: what relative paths start with
  Parts root_parts;

  Scratch() {
    base = fs::temp_directory_path() / fmt::format("saloam_fuzz_paths_{}", ::getpid());
    const fs::path deep = base / "d1" / "d2" / "d3" / "d4" / "d5" / "d6" / "root";
    fs::create_directories(deep / "a" / "b");
    fs::create_directories(deep / "b");
    std::error_code ignored;
    fs::create_directory_symlink("a", deep / "L", ignored);
    if (!fs::exists(deep / "h1")) {
      { std::FILE* f = std::fopen((deep / "h1").c_str(), "w"); if (f) std::fclose(f); }
      fs::create_hard_link(deep / "h1", deep / "h2", ignored);
    }
    root = fs::canonical(deep);
    for (const fs::path& p : root) {
      if (!p.empty() && p != "/") root_parts.push_back(p.string());
    }
    relative = root.lexically_relative(fs::current_path()).string();
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(base, ignored);
  }
};

const Scratch& scratch() {
  static const Scratch s;
  return s;
}

// The model's resolution: absolute components, lexically, with the link and
// the hard link resolved as the file system would.
Parts resolve(const std::vector<std::string>& components) {
  const Scratch& s = scratch();
  Parts out = s.root_parts;
  for (const std::string& c : components) {
    if (c.empty() || c == ".") continue;
    if (c == "..") {
      if (!out.empty()) out.pop_back();
      continue;
    }
    if (c == "L" && out == s.root_parts) {
      out.push_back("a");
      continue;
    }
    out.push_back(c);
  }
  return out;
}

bool within(const Parts& inner, const Parts& outer) {
  return outer.size() <= inner.size() && std::equal(outer.begin(), outer.end(), inner.begin());
}

// One place: the same components, or h1 and h2 (one file; only these exact
// paths: "h2/new" is not inside h1).
bool same_place(const Parts& a, const Parts& b) {
  if (a == b) return true;
  const auto linked = [](const Parts& p) {
    Parts h1 = scratch().root_parts, h2 = scratch().root_parts;
    h1.push_back("h1");
    h2.push_back("h2");
    return p == h1 || p == h2;
  };
  return linked(a) && linked(b);
}

struct Entry {
  bool input = true;
  saloam::OutputUse use = saloam::OutputUse::kFile;
  std::string option, given;
  Parts resolved;
};

std::string named(const Entry& e) { return fmt::format("{} {}", e.option, e.given); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saloam;
  fuzz::quiet_logs();
  const Scratch& s = scratch();
  std::size_t at = 0;
  const auto next = [&]() -> std::optional<std::uint8_t> {
    if (at >= size) return std::nullopt;
    return data[at++];
  };
  const auto count = next();
  if (!count) return 0;
  std::vector<Entry> entries;
  for (std::size_t k = 0; k < 1 + *count % kMaxEntries; ++k) {
    const auto kind = next(), absolute = next(), n = next();
    if (!kind || !absolute || !n) break;
    std::vector<std::string> components;
    for (std::size_t c = 0; c < *n % (kMaxComponents + 1); ++c) {
      const auto b = next();
      if (!b) break;
      components.emplace_back(kComponents[*b % std::size(kComponents)]);
    }
    std::string given = *absolute % 2 ? s.root.string() : s.relative;
    for (const std::string& c : components) given += "/" + c;
    Entry e;
    e.input = *kind % 4 == 0;
    e.use = std::array{OutputUse::kFile, OutputUse::kFile, OutputUse::kFolder, OutputUse::kReplacedFolder}[*kind % 4];
    e.option = fmt::format("--{}{}", e.input ? "in" : "out", k);
    e.given = given;
    e.resolved = resolve(components);
    entries.push_back(std::move(e));
  }

  // The model: the first breach in check()'s order.
  std::optional<std::pair<const Entry*, const Entry*>> breach;  // (the output named first, the other path)
  std::vector<const Entry*> inputs, outputs;
  for (const Entry& e : entries) (e.input ? inputs : outputs).push_back(&e);
  for (const Entry* out : outputs) {
    for (const Entry* in : inputs) {
      if (!breach && (same_place(in->resolved, out->resolved) || within(in->resolved, out->resolved) ||
                      within(out->resolved, in->resolved))) {
        breach = {out, in};
      }
    }
  }
  for (std::size_t i = 0; i < outputs.size() && !breach; ++i) {
    for (std::size_t j = i + 1; j < outputs.size() && !breach; ++j) {
      const Entry* a = outputs[i];
      const Entry* b = outputs[j];
      if (same_place(a->resolved, b->resolved)) {
        breach = {b, a};
      } else if (a->use == OutputUse::kReplacedFolder && within(b->resolved, a->resolved)) {
        breach = {a, b};
      } else if (b->use == OutputUse::kReplacedFolder && within(a->resolved, b->resolved)) {
        breach = {b, a};
      }
    }
  }

  PathRules rules;
  for (const Entry& e : entries) {
    if (e.input) {
      rules.input(e.option, e.given);
    } else {
      rules.output(e.option, e.given, e.use);
    }
  }
  try {
    rules.check();
  } catch (const InputError& error) {
    SALOAM_FUZZ_CHECK(breach.has_value());  // refused only when a rule is broken
    const std::string_view message = error.what();
    SALOAM_FUZZ_CHECK(message.starts_with(breach->first->given + ": "));
    SALOAM_FUZZ_CHECK(message.find(named(*breach->first)) != std::string_view::npos);
    SALOAM_FUZZ_CHECK(message.find(named(*breach->second)) != std::string_view::npos);
    return 0;
  }
  SALOAM_FUZZ_CHECK(!breach.has_value());  // every breach refused
  return 0;
}
