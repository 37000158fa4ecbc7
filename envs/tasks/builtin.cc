#include "pixelgym/envs/tasks/builtin.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "pixelgym/envs/tasks/acrobot.h"
#include "pixelgym/envs/tasks/arm_push.h"
#include "pixelgym/envs/tasks/arm_reach.h"
#include "pixelgym/envs/tasks/ball_in_cup.h"
#include "pixelgym/envs/tasks/cartpole.h"
#include "pixelgym/envs/tasks/cheetah.h"
#include "pixelgym/envs/tasks/finger.h"
#include "pixelgym/envs/tasks/grid_world.h"
#include "pixelgym/envs/tasks/pendulum.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reacher.h"
#include "pixelgym/envs/tasks/urdf_reach.h"
#include "pixelgym/envs/tasks/walker.h"
#include "pixelgym/envs/vector/make_vec.h"

namespace pixelgym {

void register_builtin_envs(Registry& registry) {
  // One line per task.
  std::vector<EnvSpec> specs;
  const auto add = [&specs](std::vector<EnvSpec> more) {
    for (EnvSpec& spec : more) specs.push_back(std::move(spec));
  };
  add({GridWorld::spec_v0()});
  add(CartPoleTask::specs());
  add({PendulumTask::spec_v0()});
  add({AcrobotTask::spec_v0()});
  add(ReacherTask::specs());
  add({ArmReachTask::spec_v0()});
  add({ArmPushTask::spec_v0()});
  add({UrdfReachTask::spec_v0()});
  add({CheetahTask::spec_v0()});
  add(WalkerTask::specs());
  add({FingerTask::spec_v0()});
  add({BallInCupTask::spec_v0()});
  // The Distracting Control Suite's six tasks (PlaNet's), with its ground-plane alpha per domain.
  const std::vector<std::pair<std::string, float>> distracting = {
      {"CartPoleSwingup-v1", 0.3F}, {"ReacherEasy-v1", 0.0F},    {"CheetahRun-v0", 1.0F},
      {"FingerSpin-v0", 0.3F},      {"BallInCupCatch-v0", 0.3F}, {"WalkerWalk-v0", 1.0F}};
  for (const auto& [id, floor_opacity] : distracting) {
    const auto base = std::find_if(specs.begin(), specs.end(),
                                   [&id = id](const EnvSpec& spec) { return spec.id == id; });
    if (base == specs.end()) throw std::logic_error("no built-in " + id + " to vary");
    specs.push_back(distracting_task_spec(*base, floor_opacity));
  }
  for (EnvSpec& spec : specs) registry.register_env(std::move(spec));
}

// The process-wide registry and its free functions (declared in envs/registry.h and
// envs/vector/make_vec.h) live here, with the envs it holds, so that the protocol library
// (pixelgym::envs) links no task.

Registry& default_registry() {
  // Filled whole or not at all: when a registration throws, the next call starts afresh instead
  // of finding the envs registered before it ("already registered").
  static Registry* registry = [] {
    static std::optional<Registry> instance;
    instance.emplace();
    try {
      register_builtin_envs(*instance);
    } catch (...) {
      instance.reset();
      throw;
    }
    return &*instance;
  }();
  return *registry;
}

std::unique_ptr<Env> make(const std::string& id, const Params& kwargs, const MakeOptions& options) {
  return default_registry().make(id, kwargs, options);
}

void register_env(EnvSpec spec) { default_registry().register_env(std::move(spec)); }

EnvDescription describe(const std::string& id, const Params& kwargs) {
  return default_registry().describe(id, kwargs);
}

std::vector<std::string> registered_ids() { return default_registry().registered_ids(); }

Params parse_kwargs(const std::string& id, const std::vector<std::string>& entries) {
  return default_registry().parse_kwargs(id, entries);
}

namespace vector {

std::unique_ptr<VectorEnv> make_vec(const std::string& id, int num_envs, const Params& kwargs,
                                    const EnvWrapping& wrap, const VectorOptions& options) {
  return make_vec(default_registry(), id, num_envs, kwargs, wrap, options);
}

}  // namespace vector

}  // namespace pixelgym
