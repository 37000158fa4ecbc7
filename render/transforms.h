// Private to render/: the matrices the renderer builds, as pure functions (no OpenGL).
#pragma once

#include <Eigen/Core>

#include "pixelgym/render/scene.h"

namespace pixelgym::render {

/// An instance's model matrix: its scale, then its pose.
Eigen::Matrix4f model_matrix(const Instance& instance);

/// A view matrix (world to eye) from `eye` looking along `direction` (any length), with an up
/// axis chosen by the function: world +z, or +x when `direction` is within ~25 degrees of
/// vertical.
Eigen::Matrix4f look_from(const Eigen::Vector3f& eye, const Eigen::Vector3f& direction);

/// OpenGL's orthographic projection (glOrtho): the box [left, right] x [bottom, top] x
/// [-far, -near] of eye space to clip space [-1, 1]^3.
Eigen::Matrix4f orthographic(float left, float right, float bottom, float top, float near_m,
                             float far_m);

/// The distance along the viewing axis (metres) of a window-space depth `window` in [0, 1] read
/// back from a perspective projection with planes `near_m` and `far_m`; `far_m` for 1 (nothing
/// drawn).
inline float eye_depth_from_window(float window, float near_m, float far_m) {
  const float ndc = 2.0F * window - 1.0F;
  return window >= 1.0F ? far_m
                        : 2.0F * near_m * far_m / ((far_m + near_m) - ndc * (far_m - near_m));
}

}  // namespace pixelgym::render
