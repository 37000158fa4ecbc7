// A camera that follows a robot's centre of mass, as dm_control's trackcom cameras do.
#pragma once

#include <Eigen/Core>

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

}  // namespace pixelgym
