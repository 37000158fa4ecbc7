// The line `train` prints first: which parts of the observation the policy reads.
#pragma once

#include <string>

#include "pixelgym/envs/space.h"

namespace pixelgym::trainer {

/// One env's observation space in a line, each part as "NAME DTYPE SHAPE" joined by " + ":
/// "pixels uint8 (84, 84, 3) + joint_pos float32 (2,)" for a Dict, "image uint8 (84, 84, 3)" for
/// a bare uint8 Box of rank 2 or more, "state float32 (5,)" for another Box, the space's
/// to_string() for anything else. A Dict of an image and other parts ends with a hint of the
/// obs_mode kwarg that keeps one of them (the pixel tasks' "rgb" and "state").
std::string observation_summary(const Space& observation_space);

}  // namespace pixelgym::trainer
