// WorldScene: the render Scene of an engine World, kept in step with it.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "pixelgym/engine/world.h"
#include "pixelgym/render/camera.h"
#include "pixelgym/render/scene.h"

namespace pixelgym {

/// Builds a Scene with one Instance per visual shape of a World (meshes with their materials,
/// primitives scaled from shared unit meshes) and updates the instance poses from the world.
/// Meshes are converted once per process and shared by every WorldScene.
class WorldScene {
 public:
  /// One instance per world.visual_shapes() entry, in that order, posed as the world is now. A
  /// mesh with a URDF colour is drawn in that colour, one without in its file's part colours.
  /// Keeps no reference to `world`.
  explicit WorldScene(const engine::World& world);

  /// Copies the current visual poses of `world` (the one it was built from) into the scene.
  /// Throws std::invalid_argument when the world's visual shape count differs from the scene's
  /// (shapes were added after it was built).
  void update(const engine::World& world);

  /// The scene to draw. update() rewrites only the instance poses: the light, floor, sky and
  /// shadow settings are the caller's to change.
  render::Scene& scene() { return scene_; }
  const render::Scene& scene() const { return scene_; }

  /// The world-aligned box around every instance (at the last update).
  Eigen::AlignedBox3f bounds() const;

 private:
  render::Scene scene_;
  std::vector<Eigen::Vector3f> local_scale_;
  std::vector<Eigen::Isometry3d> poses_;  // scratch for World::visual_poses
};

/// A camera that frames `box` whole, looking from the direction given by azimuth (degrees,
/// counter-clockwise from +x) and elevation (degrees above the horizon), from the closest
/// distance at which the box's corners fall within 95% of the image of `width` x `height` pixels
/// and `fov_y_deg`. Throws std::invalid_argument for an empty box.
render::Camera frame_box(const Eigen::AlignedBox3f& box, float azimuth_deg, float elevation_deg,
                         int width, int height, float fov_y_deg = 40.0F);

}  // namespace pixelgym
