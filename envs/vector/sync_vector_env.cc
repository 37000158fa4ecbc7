#include "pixelgym/envs/vector/sync_vector_env.h"

#include <utility>

namespace pixelgym::vector {

SyncVectorEnv::SyncVectorEnv(int num_envs, const EnvFactory& make_env, AutoresetMode autoreset)
    : BatchRunner("SyncVectorEnv", num_envs, autoreset) {
  build(make_env);
}

SyncVectorEnv::SyncVectorEnv(std::vector<std::unique_ptr<Env>> envs, AutoresetMode autoreset)
    : BatchRunner("SyncVectorEnv", static_cast<int>(envs.size()), autoreset) {
  build([&envs](int i) { return std::move(envs[static_cast<std::size_t>(i)]); });
}

SyncVectorEnv::~SyncVectorEnv() { destroy_envs(); }

void SyncVectorEnv::start_all() {
  for (int i = 0; i < num_envs(); ++i) run_env(i);
}

}  // namespace pixelgym::vector
