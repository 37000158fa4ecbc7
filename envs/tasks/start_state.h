// Starts drawn again until nothing touches, as dm_control's finger (its _set_random_joint_angles:
// at most 1000 draws) and ball_in_cup (without a limit; it never needs many) draw theirs.
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <string>

#include "pixelgym/engine/world.h"

namespace pixelgym {

/// Draws the joint positions `q` of `robot` with `draw(q)` and sets them at rest, until
/// World::detect_contacts finds no contact. Throws std::runtime_error "{task}: no start without
/// contacts in 1000 draws" when none of 1000 draws is free.
template <typename Draw>
void draw_start_without_contacts(engine::World& world, engine::RobotId robot, Eigen::VectorXd& q,
                                 const std::string& task, Draw&& draw) {
  constexpr int kMaxDraws = 1000;
  for (int attempt = 0; attempt < kMaxDraws; ++attempt) {
    draw(q);
    world.set_joint_state(robot, q, Eigen::VectorXd::Zero(q.size()));
    if (world.detect_contacts().empty()) return;
  }
  throw std::runtime_error(task + ": no start without contacts in " + std::to_string(kMaxDraws) +
                           " draws");
}

}  // namespace pixelgym
