#include "pixelgym/envs/vector/make_vec.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <utility>
#include <vector>

#include "pixelgym/envs/described_env.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/async_vector_env.h"
#include "pixelgym/envs/vector/memory_check.h"
#include "pixelgym/envs/vector/process_vector_env.h"
#include "pixelgym/envs/vector/sync_vector_env.h"

namespace pixelgym::vector {

const char* vector_mode_name(VectorMode mode) {
  switch (mode) {
    case VectorMode::kSync:
      return "sync";
    case VectorMode::kAsync:
      return "async";
    case VectorMode::kProcess:
      return "process";
  }
  return "unknown";
}

VectorMode parse_vector_mode(const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (VectorMode mode : {VectorMode::kSync, VectorMode::kAsync, VectorMode::kProcess}) {
    if (lower == vector_mode_name(mode)) return mode;
  }
  throw std::invalid_argument("vector mode must be sync, async or process, got \"" + name + "\"");
}

std::unique_ptr<VectorEnv> make_vec(const Registry& registry, const std::string& id, int num_envs,
                                    const Params& kwargs, const EnvWrapping& wrap,
                                    const VectorOptions& options) {
  // Bad ids, kwargs and wrappings are reported here, on the calling thread, without building a
  // world or a GL context.
  EnvDescription description = registry.describe(id, kwargs);
  const SpacePtr unwrapped_observation_space = description.observation_space;
  std::unique_ptr<Env> wrapped = wrap ? wrap(std::make_unique<DescribedEnv>(description)) : nullptr;
  // Too many envs for the memory left are refused here, not after building envs until the
  // machine runs out.
  check_memory(
      "make_vec(\"" + id + "\")", num_envs,
      estimate_env_bytes(*unwrapped_observation_space,
                         wrapped ? wrapped->observation_space() : *unwrapped_observation_space),
      available_memory());

  const std::shared_ptr<const EnvSpec> spec = registry.spec(id);
  if (options.mode == VectorMode::kProcess) {
    std::shared_ptr<const Env> like = wrapped
                                          ? std::shared_ptr<const Env>(std::move(wrapped))
                                          : std::make_shared<DescribedEnv>(std::move(description));
    const bool share = options.share_gl_contexts;
    // Called in each worker process, after fork(): the registry and the wrapping are the
    // parent's, copied with the process.
    const ProcessVectorEnv::WorkerFactory make_worker_envs = [&registry, &id, &kwargs, &wrap, spec,
                                                              share](int /*worker*/) {
      MakeOptions worker_options;
      if (spec->make_render_resources)
        worker_options.render = spec->make_render_resources(0, share);
      return EnvFactory([&registry, &id, &kwargs, &wrap, worker_options](int /*index*/) {
        std::unique_ptr<Env> env = registry.make(id, kwargs, worker_options);
        return wrap ? wrap(std::move(env)) : std::move(env);
      });
    };
    return std::make_unique<ProcessVectorEnv>(num_envs, make_worker_envs, std::move(like),
                                              options.num_workers, options.autoreset,
                                              options.caller_steps_envs);
  }
  const bool async = options.mode == VectorMode::kAsync;
  const int threads = async ? AsyncVectorEnv::threads_for(num_envs, options.num_threads) : 1;
  std::vector<MakeOptions> thread_options(static_cast<std::size_t>(threads));
  if (spec->make_render_resources) {
    for (int w = 0; w < threads; ++w) {
      thread_options[static_cast<std::size_t>(w)].render =
          spec->make_render_resources(w, options.share_gl_contexts);
    }
  }
  const EnvFactory make_env = [&](int index) {
    std::unique_ptr<Env> env =
        registry.make(id, kwargs, thread_options[static_cast<std::size_t>(index % threads)]);
    return wrap ? wrap(std::move(env)) : std::move(env);
  };
  if (async) {
    return std::make_unique<AsyncVectorEnv>(num_envs, make_env, options.num_threads,
                                            options.autoreset);
  }
  return std::make_unique<SyncVectorEnv>(num_envs, make_env, options.autoreset);
}

}  // namespace pixelgym::vector
