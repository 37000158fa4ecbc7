// The scene the renderer's threading tests draw: a box and a ball moved apart by `offset`, with
// the default light, floor and shadows.
#pragma once

#include <Eigen/Geometry>

#include "pixelgym/render/mesh_data.h"
#include "pixelgym/render/renderer.h"

namespace pixelgym::render::testing {

inline Scene box_and_ball_scene(float offset, int box_segmentation_id = 0,
                                int ball_segmentation_id = 0) {
  Scene scene;
  Instance box;
  box.mesh = make_box_mesh();
  box.scale = Eigen::Vector3f(0.4F, 0.4F, 0.6F);
  box.X_world_instance.translation() = Eigen::Vector3f(offset, 0, 0.3F);
  box.material.base_color = {0.8F, 0.3F, 0.2F, 1};
  box.segmentation_id = box_segmentation_id;
  scene.instances.push_back(box);
  Instance ball;
  ball.mesh = make_sphere_mesh();
  ball.scale = Eigen::Vector3f::Constant(0.25F);
  ball.X_world_instance.translation() = Eigen::Vector3f(0.6F - offset, 0.4F, 0.25F);
  ball.material.base_color = {0.2F, 0.5F, 0.9F, 1};
  ball.segmentation_id = ball_segmentation_id;
  scene.instances.push_back(ball);
  return scene;
}

}  // namespace pixelgym::render::testing
