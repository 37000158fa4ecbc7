#include "pixelgym/envs/vector/make_vec.h"

#include <utility>
#include <vector>

#include "pixelgym/envs/described_env.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/async_vector_env.h"
#include "pixelgym/envs/vector/memory_check.h"
#include "pixelgym/envs/vector/sync_vector_env.h"

namespace pixelgym::vector {

std::unique_ptr<VectorEnv> make_vec(const Registry& registry, const std::string& id, int num_envs,
                                    const Params& kwargs, const EnvWrapping& wrap,
                                    const VectorOptions& options) {
  // Bad ids, kwargs and wrappings are reported here, on the calling thread, without building a
  // world or a GL context.
  EnvDescription description = registry.describe(id, kwargs);
  const SpacePtr unwrapped_observation_space = description.observation_space;
  const std::unique_ptr<Env> wrapped =
      wrap ? wrap(std::make_unique<DescribedEnv>(std::move(description))) : nullptr;
  // Too many envs for the memory left are refused here, not after building envs until the
  // machine runs out.
  check_memory(
      "make_vec(\"" + id + "\")", num_envs,
      estimate_env_bytes(*unwrapped_observation_space,
                         wrapped ? wrapped->observation_space() : *unwrapped_observation_space),
      available_memory());

  const bool async = options.mode == VectorMode::kAsync;
  const int threads = async ? AsyncVectorEnv::threads_for(num_envs, options.num_threads) : 1;
  const std::shared_ptr<const EnvSpec> spec = registry.spec(id);
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
