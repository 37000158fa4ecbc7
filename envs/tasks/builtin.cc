#include "envs/tasks/builtin.h"

#include "envs/tasks/acrobot.h"
#include "envs/tasks/arm_push.h"
#include "envs/tasks/arm_reach.h"
#include "envs/tasks/cartpole.h"
#include "envs/tasks/grid_world.h"
#include "envs/tasks/pendulum.h"
#include "envs/tasks/reacher.h"

namespace pixelgym {

void register_builtin_envs(Registry& registry) {
  // One line per task.
  registry.register_env(GridWorld::spec_v0());
  for (EnvSpec& spec : CartPoleTask::specs()) registry.register_env(std::move(spec));
  registry.register_env(PendulumTask::spec_v0());
  registry.register_env(AcrobotTask::spec_v0());
  for (EnvSpec& spec : ReacherTask::specs()) registry.register_env(std::move(spec));
  registry.register_env(ArmReachTask::spec_v0());
  registry.register_env(ArmPushTask::spec_v0());
}

}  // namespace pixelgym
