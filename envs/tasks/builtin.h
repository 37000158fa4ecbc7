// The envs that ship with pixelgym.
#pragma once

#include "pixelgym/envs/registry.h"

namespace pixelgym {

/// Registers every built-in env in `registry` (the default registry does this on first use).
/// Throws std::invalid_argument, as Registry::register_env, when one of their ids is registered
/// already; the envs registered before it stay.
void register_builtin_envs(Registry& registry);

}  // namespace pixelgym
