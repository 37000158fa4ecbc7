// What every algorithm does with torch state around a checkpoint: torch::save into a checkpoint
// blob and torch::load back, a digest of a module's parameters, and the intra-op thread count.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <functional>
#include <ostream>
#include <sstream>
#include <string>

#include "pixelgym/trainer/checkpoint_file.h"

namespace pixelgym::trainer {

/// The bytes `save` writes (a torch::save into the stream), as a checkpoint blob.
std::string to_blob(const std::function<void(std::ostream&)>& save);

/// torch::save of `value` (a module pointer, an optimizer, a tensor) as a checkpoint blob.
template <typename T>
std::string save_blob(const T& value) {
  return to_blob([&](std::ostream& out) { torch::save(value, out); });
}

/// Blob `name` of `checkpoint`. Throws std::runtime_error naming checkpoint.path and the blob
/// when it is not there.
const std::string& checkpoint_blob(const LoadedCheckpoint& checkpoint, const std::string& name);

/// torch::load of blob `name` of `checkpoint` into `into`. Throws as checkpoint_blob, and as
/// torch::load for bytes that are not what `into` saves.
template <typename T>
void load_blob(const LoadedCheckpoint& checkpoint, const std::string& name, T& into) {
  std::istringstream in(checkpoint_blob(checkpoint, name), std::ios::binary);
  torch::load(into, in);
}

/// The state of a CPU generator as a checkpoint blob, and back (throws std::invalid_argument,
/// from torch, for a state that is not a CPU generator's).
std::string generator_blob(const at::Generator& generator);
void load_generator(const LoadedCheckpoint& checkpoint, const std::string& name,
                    at::Generator& generator);

/// A 64-bit digest (FNV-1a) of `module`'s parameters, then its buffers, in their order: equal
/// exactly when the bytes are (the ranks of a distributed run compare theirs).
std::uint64_t parameter_digest(const torch::nn::Module& module);

/// Sets LibTorch's intra-op threads: `requested`, or when 0 one per core this process may run on
/// (sched_getaffinity); OMP_NUM_THREADS, when set, wins over that default (not over
/// `requested`). Returns the count in use.
int set_torch_threads(int requested);

}  // namespace pixelgym::trainer
