// The envs that ship with pixelgym.
#pragma once

#include "envs/registry.h"

namespace pixelgym {

/// Registers every built-in env in `registry` (the default registry does this on first use).
void register_builtin_envs(Registry& registry);

}  // namespace pixelgym
