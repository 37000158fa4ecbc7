#include "envs/vector/sync_vector_env.h"

#include <utility>

namespace pixelgym::vector {

SyncVectorEnv::SyncVectorEnv(int num_envs, const EnvFactory& make_env, AutoresetMode autoreset,
                             bool share_gl_contexts)
    : VectorEnv("SyncVectorEnv", num_envs, autoreset, share_gl_contexts) {
  build(make_env, 1);
}

SyncVectorEnv::SyncVectorEnv(std::vector<std::unique_ptr<Env>> envs, AutoresetMode autoreset,
                             bool share_gl_contexts)
    : VectorEnv("SyncVectorEnv", static_cast<int>(envs.size()), autoreset, share_gl_contexts) {
  build([&envs](int i) { return std::move(envs[static_cast<std::size_t>(i)]); }, 1);
}

SyncVectorEnv::~SyncVectorEnv() { destroy_envs(); }

void SyncVectorEnv::start_all() {
  for (int i = 0; i < num_envs(); ++i) run_env(i);
}

}  // namespace pixelgym::vector
