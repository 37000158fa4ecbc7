// make_vec: a vector env of a registered env, each copy with the same kwargs and wrapper stack
// (gymnasium.make_vec).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "envs/params.h"
#include "envs/vector/vector_env.h"

namespace pixelgym::vector {

/// How make_vec runs the envs.
enum class VectorMode : std::uint8_t {
  kSync,   // SyncVectorEnv: a loop on the calling thread
  kAsync,  // AsyncVectorEnv: a pool of worker threads
};

/// make_vec's settings beside the env's own kwargs.
struct VectorOptions {
  VectorMode mode = VectorMode::kSync;
  /// AsyncVectorEnv's worker threads: 0 for one per core; clamped to num_envs. Ignored by kSync.
  int num_threads = 0;
  AutoresetMode autoreset = AutoresetMode::kNextStep;
  /// Whether the envs one thread runs draw with one shared GL context (see VectorEnv: GL
  /// contexts); false gives every env its own.
  bool share_gl_contexts = true;
};

/// `num_envs` copies of `make(id, kwargs)`, each wrapped by `wrappers` (the `--wrap` text form,
/// applied in order: the first wraps the env, the last is outermost; see
/// wrappers::apply_wrappers), run as `options` say. Throws std::invalid_argument for an unknown
/// id, kwarg or wrapper spec (before any env is built: the first env is described first), and
/// as the VectorEnv constructors do.
std::unique_ptr<VectorEnv> make_vec(const std::string& id, int num_envs, const Params& kwargs = {},
                                    const std::vector<std::string>& wrappers = {},
                                    const VectorOptions& options = {});

}  // namespace pixelgym::vector
