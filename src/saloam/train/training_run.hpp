#pragma once
// What every trainer's run shares (SGPR's and the segmentation's): the
// generator of an epoch, atomic writes of logs and checkpoints, libtorch's
// thread count and allocator settings. libtorch stays in the .cpp.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <random>

#include <nlohmann/json.hpp>

namespace saloam {

/// Sets libtorch's intra-op threads (fixed for reproducible results).
void set_training_threads(int threads);

/// A training step allocates and frees tens of tensors of several MB; keeps
/// freed memory in the heap for reuse instead of returning it to the system
/// every step (halves an SGPR step; changes no result). Idempotent.
void keep_freed_memory_for_reuse();

/// The generator of epoch `epoch` of a run with `seed`: resuming needs no saved generator state.
std::mt19937_64 epoch_generator(std::uint64_t seed, int epoch);

/// Writes `j` to `file` through an AtomicFile (core/output_file.hpp): a reader
/// never sees half a file, and a failed write is an InputError naming it.
void write_json_atomically(const std::filesystem::path& file, const nlohmann::json& j);

/// Writes a checkpoint: `fill(folder)` writes into a fresh `out/checkpoint.partial`,
/// which then replaces `out/checkpoint`, so an interruption never leaves a
/// half-written checkpoint.
void replace_checkpoint(const std::filesystem::path& out, const std::function<void(const std::filesystem::path&)>& fill);

/// The state.json of `out/checkpoint` (InputError when there is none to resume).
nlohmann::json read_checkpoint_state(const std::filesystem::path& out);

}  // namespace saloam
