#include "pixelgym/render/camera.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace pixelgym::render {
namespace {

using ::testing::HasSubstr;

std::string error_of(const Camera& camera) {
  try {
    camera.validate();
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "(valid)";
}

TEST(CameraTest, RejectsBadSizesFieldOfViewAndClipPlanes) {
  Camera camera;
  EXPECT_EQ(error_of(camera), "(valid)");
  for (const auto& [w, h] :
       std::vector<std::pair<int, int>>{{0, 84}, {84, -1}, {9000, 84}, {84, 8193}}) {
    Camera c;
    c.width = w;
    c.height = h;
    EXPECT_THAT(error_of(c), HasSubstr("width and height must be in [1, 8192]"));
  }
  for (float fov : {0.0F, 180.0F, -5.0F, 200.0F}) {
    Camera c;
    c.fov_y_deg = fov;
    EXPECT_THAT(error_of(c), HasSubstr("fov_y_deg must be in (0, 180)"));
  }
  Camera near_far;
  near_far.near_m = 2.0F;
  near_far.far_m = 1.0F;
  EXPECT_THAT(error_of(near_far), HasSubstr("near_m < far_m"));
  near_far.near_m = near_far.far_m;
  EXPECT_THAT(error_of(near_far), HasSubstr("near_m < far_m"));
  Camera msaa;
  msaa.msaa_samples = 3;
  EXPECT_THAT(error_of(msaa), HasSubstr("msaa_samples"));
}

TEST(CameraTest, LookAtLooksAtTheTargetWithUpUp) {
  const Camera camera = Camera::look_at({3, 0, 1}, {0, 0, 1});
  // The target lies on the camera's -z axis, straight ahead.
  const Eigen::Vector3f target_in_camera =
      camera.X_world_camera.inverse() * Eigen::Vector3f(0, 0, 1);
  EXPECT_TRUE(target_in_camera.isApprox(Eigen::Vector3f(0, 0, -3), 1e-6F));
  EXPECT_TRUE(camera.X_world_camera.linear().col(1).isApprox(Eigen::Vector3f::UnitZ(), 1e-6F));
  EXPECT_THROW(Camera::look_at({1, 1, 1}, {1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(Camera::look_at({0, 0, 5}, {0, 0, 0}), std::invalid_argument);  // up along the view
}

TEST(CameraTest, ProjectionPutsTheTargetAtTheImageCentreAndFlipsRows) {
  Camera camera = Camera::look_at({0, -4, 0}, {0, 0, 0});
  const Eigen::Matrix4f vp = camera.projection_matrix() * camera.view_matrix();
  Eigen::Vector4f centre = vp * Eigen::Vector4f(0, 0, 0, 1);
  EXPECT_NEAR(centre.x() / centre.w(), 0.0F, 1e-6F);
  EXPECT_NEAR(centre.y() / centre.w(), 0.0F, 1e-6F);
  // A point above the target lands at negative y: OpenGL's first row, the image's top.
  Eigen::Vector4f above = vp * Eigen::Vector4f(0, 0, 1, 1);
  EXPECT_LT(above.y() / above.w(), 0.0F);
}

}  // namespace
}  // namespace pixelgym::render
