// Camera: where to look from, and the image to make.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pixelgym::render {

/// A pinhole camera. Its frame follows OpenGL: it looks along its -z axis with +y up and +x to the
/// right of the image. Images have row 0 at the top.
struct Camera {
  /// The camera's pose in the world (its frame as above).
  Eigen::Isometry3f X_world_camera = Eigen::Isometry3f::Identity();
  /// Vertical field of view, degrees, in (0, 180); the horizontal one follows from the aspect.
  float fov_y_deg = 45.0F;
  /// Distances of the near and far clipping planes along the viewing axis, m: 0 < near < far.
  float near_m = 0.05F;
  float far_m = 50.0F;
  /// Image size in pixels, each in [1, 8192].
  int width = 84;
  int height = 84;
  /// Multisample anti-aliasing samples: 0 (off, the default for observations), 2, 4 or 8;
  /// Renderer::render refuses more than its GL offers (llvmpipe: 4).
  int msaa_samples = 0;

  /// A camera at `eye` looking at `target`, with `up` (world) pointing up in the image; the other
  /// fields keep their defaults. Throws std::invalid_argument when eye == target or `up` is
  /// parallel to the view direction.
  static Camera look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
                        const Eigen::Vector3f& up = Eigen::Vector3f::UnitZ());

  /// Throws std::invalid_argument naming the field for a size outside [1, 8192], a field of view
  /// outside (0, 180), near <= 0, near >= far, MSAA samples not in {0, 2, 4, 8}, or a
  /// non-finite pose.
  void validate() const;

  /// OpenGL's view matrix (world to camera).
  Eigen::Matrix4f view_matrix() const;
  /// OpenGL's perspective projection, with y flipped so that rows come out top first.
  Eigen::Matrix4f projection_matrix() const;
};

}  // namespace pixelgym::render
