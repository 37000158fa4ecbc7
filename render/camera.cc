#include "pixelgym/render/camera.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace pixelgym::render {
namespace {

constexpr int kMaxImageSize = 8192;
constexpr float kPi = 3.14159265358979323846F;

}  // namespace

Camera Camera::look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
                       const Eigen::Vector3f& up) {
  const Eigen::Vector3f forward = target - eye;
  if (forward.norm() < 1e-9F)
    throw std::invalid_argument("Camera::look_at: eye and target are the same point");
  const Eigen::Vector3f back = -forward.normalized();
  const Eigen::Vector3f right = up.cross(back);
  if (right.norm() < 1e-6F) {
    throw std::invalid_argument("Camera::look_at: up is parallel to the viewing direction");
  }
  Camera camera;
  camera.X_world_camera.linear().col(0) = right.normalized();
  camera.X_world_camera.linear().col(2) = back;
  camera.X_world_camera.linear().col(1) = back.cross(right.normalized());
  camera.X_world_camera.translation() = eye;
  return camera;
}

void Camera::validate() const {
  const auto fail = [](const std::string& message) {
    throw std::invalid_argument("Camera: " + message);
  };
  if (width < 1 || width > kMaxImageSize || height < 1 || height > kMaxImageSize) {
    fail("width and height must be in [1, " + std::to_string(kMaxImageSize) + "], got " +
         std::to_string(width) + "x" + std::to_string(height));
  }
  if (!(fov_y_deg > 0.0F && fov_y_deg < 180.0F)) {
    fail("fov_y_deg must be in (0, 180), got " + std::to_string(fov_y_deg));
  }
  if (!(near_m > 0.0F) || !(far_m > near_m) || !std::isfinite(far_m)) {
    fail("needs 0 < near_m < far_m < inf, got near_m " + std::to_string(near_m) + " and far_m " +
         std::to_string(far_m));
  }
  if (msaa_samples != 0 && msaa_samples != 2 && msaa_samples != 4 && msaa_samples != 8) {
    fail("msaa_samples must be 0, 2, 4 or 8, got " + std::to_string(msaa_samples));
  }
  if (!X_world_camera.matrix().allFinite()) fail("the pose is not finite");
}

Eigen::Matrix4f Camera::view_matrix() const {
  return X_world_camera.inverse(Eigen::Isometry).matrix();
}

Eigen::Matrix4f Camera::projection_matrix() const {
  const float f = 1.0F / std::tan(fov_y_deg * kPi / 360.0F);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  Eigen::Matrix4f projection = Eigen::Matrix4f::Zero();
  projection(0, 0) = f / aspect;
  projection(1, 1) = -f;  // flipped: OpenGL's row 0 is the bottom, images start at the top
  projection(2, 2) = (far_m + near_m) / (near_m - far_m);
  projection(2, 3) = 2.0F * far_m * near_m / (near_m - far_m);
  projection(3, 2) = -1.0F;
  return projection;
}

}  // namespace pixelgym::render
