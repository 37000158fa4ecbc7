// make_vec: a vector env of a registered env, each copy with the same kwargs and wrapping
// (gymnasium.make_vec).
#pragma once

#include <memory>
#include <string>

#include "pixelgym/envs/params.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/vector_env.h"
#include "pixelgym/envs/wrapper.h"

namespace pixelgym::vector {

/// How make_vec runs the envs.
enum class VectorMode : std::uint8_t {
  /// SyncVectorEnv: a loop on the calling thread.
  kSync,
  /// AsyncVectorEnv: a pool of worker threads.
  kAsync,
  /// ProcessVectorEnv: worker processes writing into shared memory.
  kProcess,
};

/// "sync", "async" or "process".
const char* vector_mode_name(VectorMode mode);
/// The mode `name` spells (as vector_mode_name, case-insensitive). Throws std::invalid_argument
/// listing the names.
VectorMode parse_vector_mode(const std::string& name);

/// make_vec's settings beside the env's own kwargs.
struct VectorOptions {
  /// Which runner make_vec builds.
  VectorMode mode = VectorMode::kSync;
  /// AsyncVectorEnv's worker threads: 0 for one per core; clamped to num_envs. Only kAsync.
  int num_threads = 0;
  /// What the vector env does with an env whose episode ended (see AutoresetMode).
  AutoresetMode autoreset = AutoresetMode::kNextStep;
  /// Whether the envs one thread runs share their render resources' GL context (the pixel tasks:
  /// one context per thread, whose compiled shaders, meshes and framebuffers its envs share);
  /// false gives every env a context of its own. Frames are byte-identical either way.
  bool share_gl_contexts = true;
  /// ProcessVectorEnv's worker processes: 0 for one per core; clamped to num_envs. Only kProcess.
  int num_workers = 0;
  /// kProcess: whether the calling process runs worker 0's envs itself (as AsyncVectorEnv's
  /// calling thread runs thread 0's), so that W workers are W - 1 child processes and the caller;
  /// false puts every env in a child process (see ProcessVectorEnv).
  bool caller_steps_envs = true;
};

/// `num_envs` copies of `registry.make(id, kwargs, options)`, each passed through `wrap` (when set;
/// see EnvWrapping, and wrappers::wrapping for the `--wrap` text form), run as `options` say.
///
/// Rendering resources: make_vec owns what the envs share. Under kProcess, each worker process
/// makes the spec's render resources once (make_render_resources(0, share_gl_contexts)) for its
/// envs, and `like` (env(i)) is a DescribedEnv with the wrapping applied. For each thread that runs
/// envs (SyncVectorEnv: one; AsyncVectorEnv: worker w runs env i when w = i % threads) it makes the
/// spec's render resources once (EnvSpec::make_render_resources(w, share_gl_contexts)) and hands
/// them to each env of that thread through MakeOptions. So for the pixel tasks the envs of worker
/// w draw with copy w of Mesa (render::MesaCopy: threads with different copies rasterize in
/// parallel) and, by default, with one GL context.
///
/// Errors: std::invalid_argument for an unknown id or kwarg, and for a wrapping that does not fit
/// the env, before any env is built (the id and kwargs are described, and `wrap` is applied to a
/// DescribedEnv stand-in: a wrapping must not reset, step or render the env it wraps); then as
/// the SyncVectorEnv / AsyncVectorEnv constructors.
///
/// Memory: before any env is built, `num_envs` times an estimate of one env's memory (from its
/// spaces: estimate_env_bytes) is compared with the memory available (available_memory:
/// MemAvailable, or the process's cgroup limit when lower); std::invalid_argument naming
/// num_envs, the estimate and the memory available when it does not fit (check_memory).
std::unique_ptr<VectorEnv> make_vec(const Registry& registry, const std::string& id, int num_envs,
                                    const Params& kwargs = {}, const EnvWrapping& wrap = nullptr,
                                    const VectorOptions& options = {});

/// make_vec over default_registry() (the built-in envs; defined in pixelgym::tasks, as
/// default_registry is).
std::unique_ptr<VectorEnv> make_vec(const std::string& id, int num_envs, const Params& kwargs = {},
                                    const EnvWrapping& wrap = nullptr,
                                    const VectorOptions& options = {});

}  // namespace pixelgym::vector
