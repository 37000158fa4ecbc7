#include "pixelgym/render/transforms.h"

#include <Eigen/Geometry>
#include <cmath>

namespace pixelgym::render {

Eigen::Matrix4f model_matrix(const Instance& instance) {
  Eigen::Affine3f model = Eigen::Affine3f(instance.X_world_instance.matrix());
  model.scale(instance.scale);
  return model.matrix();
}

Eigen::Matrix4f look_from(const Eigen::Vector3f& eye, const Eigen::Vector3f& direction) {
  const Eigen::Vector3f back = -direction.normalized();
  const Eigen::Vector3f helper =
      std::abs(back.z()) > 0.9F ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitZ();
  const Eigen::Vector3f right = helper.cross(back).normalized();
  const Eigen::Vector3f up = back.cross(right);
  Eigen::Matrix4f view = Eigen::Matrix4f::Identity();
  view.block<1, 3>(0, 0) = right.transpose();
  view.block<1, 3>(1, 0) = up.transpose();
  view.block<1, 3>(2, 0) = back.transpose();
  view(0, 3) = -right.dot(eye);
  view(1, 3) = -up.dot(eye);
  view(2, 3) = -back.dot(eye);
  return view;
}

Eigen::Matrix4f orthographic(float left, float right, float bottom, float top, float near_m,
                             float far_m) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m(0, 0) = 2.0F / (right - left);
  m(1, 1) = 2.0F / (top - bottom);
  m(2, 2) = -2.0F / (far_m - near_m);
  m(0, 3) = -(right + left) / (right - left);
  m(1, 3) = -(top + bottom) / (top - bottom);
  m(2, 3) = -(far_m + near_m) / (far_m - near_m);
  return m;
}

}  // namespace pixelgym::render
