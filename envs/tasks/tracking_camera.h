// dm_control's cameras: one that follows a robot's centre of mass, as its trackcom cameras do,
// and the fixed ones of its finger and ball_in_cup.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "pixelgym/engine/world.h"
#include "pixelgym/render/camera.h"

namespace pixelgym {

/// Where the camera is relative to the centre of mass (dm_control: the camera's position minus
/// the centre of mass in the model's drawn pose), the direction it looks and its up, all fixed in
/// the world.
struct TrackingCamera {
  Eigen::Vector3f offset;
  Eigen::Vector3f forward;
  Eigen::Vector3f up;

  /// The camera for `robot`'s centre of mass now, with dm_control's 45 degree field of view.
  render::Camera at(const engine::World& world, engine::RobotId robot) const {
    const Eigen::Vector3f eye = world.center_of_mass(robot).cast<float>() + offset;
    render::Camera camera = render::Camera::look_at(eye, eye + forward, up);
    camera.fov_y_deg = 45.0F;
    return camera;
  }
};

/// dm_control's finger and ball_in_cup cameras (the same two in both), fixed in the world with a
/// 45 degree field of view: "cam1" (camera 1) at (0, -1, 0.4) looking along +y; any other name
/// "cam0" (camera 0) at (0, -1, 0.8), xyaxes (1, 0, 0), (0, 1, 2): looking along (0, 2, -1).
inline render::Camera finger_and_cup_camera(const std::string& name) {
  const bool level = name == "cam1";
  const float s = 1.0F / std::sqrt(5.0F);
  const Eigen::Vector3f eye(0.0F, -1.0F, level ? 0.4F : 0.8F);
  const Eigen::Vector3f forward =
      level ? Eigen::Vector3f::UnitY() : Eigen::Vector3f(0.0F, 2.0F * s, -s);
  const Eigen::Vector3f up = level ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f(0.0F, s, 2.0F * s);
  render::Camera camera = render::Camera::look_at(eye, eye + forward, up);
  camera.fov_y_deg = 45.0F;
  return camera;
}

}  // namespace pixelgym
