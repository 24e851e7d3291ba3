#include "saloam/train/training_run.hpp"

#include <malloc.h>
#include <torch/torch.h>

#include <algorithm>
#include <fstream>

#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"

namespace saloam {

namespace fs = std::filesystem;

void set_training_threads(int threads) { torch::set_num_threads(std::max(1, threads)); }

void keep_freed_memory_for_reuse() {
  static const bool once = [] {
    mallopt(M_MMAP_THRESHOLD, 1 << 30);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    mallopt(M_TOP_PAD, 256 << 20);
    return true;
  }();
  (void)once;
}

std::mt19937_64 epoch_generator(std::uint64_t seed, int epoch) {
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         static_cast<std::uint32_t>(epoch), 0x5a4c4fu};
  return std::mt19937_64(sequence);
}

void write_json_atomically(const fs::path& file, const nlohmann::json& j) { write_file_atomically(file, j.dump(2) + '\n'); }

void replace_checkpoint(const fs::path& out, const std::function<void(const fs::path&)>& fill) {
  const fs::path partial = out / "checkpoint.partial";
  fs::remove_all(partial);
  create_folder(partial);
  fill(partial);
  fs::remove_all(out / "checkpoint");
  fs::rename(partial, out / "checkpoint");
}

// A checkpoint's state.json holds options and a few counters.
constexpr std::size_t kMaxCheckpointStateBytes = 16u << 20;

nlohmann::json read_checkpoint_state(const fs::path& out) {
  const fs::path file = out / "checkpoint" / "state.json";
  require_file(file, "checkpoint state (nothing to resume)");
  nlohmann::json state = nlohmann::json::parse(read_file(file, kMaxCheckpointStateBytes, "checkpoint state"), nullptr, false);
  if (state.is_discarded() || !state.contains("options")) throw InputError(file, "not a checkpoint state");
  return state;
}

}  // namespace saloam
