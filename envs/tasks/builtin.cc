#include "envs/tasks/builtin.h"

#include "envs/tasks/cartpole.h"
#include "envs/tasks/grid_world.h"

namespace pixelgym {

void register_builtin_envs(Registry& registry) {
  // One line per task.
  registry.register_env(GridWorld::spec_v0());
  for (EnvSpec& spec : CartPoleTask::specs()) registry.register_env(std::move(spec));
}

}  // namespace pixelgym
