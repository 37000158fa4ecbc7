#include "envs/vector/make_vec.h"

#include "envs/registry.h"
#include "envs/vector/async_vector_env.h"
#include "envs/vector/sync_vector_env.h"
#include "wrappers/wrapper_spec.h"

namespace pixelgym::vector {

std::unique_ptr<VectorEnv> make_vec(const std::string& id, int num_envs, const Params& kwargs,
                                    const std::vector<std::string>& wrappers,
                                    const VectorOptions& options) {
  // Bad ids, kwargs and wrapper specs are reported here, on the calling thread, without
  // building a world or a GL context.
  wrappers::describe_wrapped(describe(id, kwargs), wrappers);
  const EnvFactory make_env = [&](int /*index*/) {
    return wrappers::apply_wrappers(make(id, kwargs), wrappers);
  };
  if (options.mode == VectorMode::kAsync) {
    return std::make_unique<AsyncVectorEnv>(num_envs, make_env, options.num_threads,
                                            options.autoreset, options.share_gl_contexts);
  }
  return std::make_unique<SyncVectorEnv>(num_envs, make_env, options.autoreset,
                                         options.share_gl_contexts);
}

}  // namespace pixelgym::vector
