// The renderer's matrices, without a GL context.
#include "pixelgym/render/transforms.h"

#include <gtest/gtest.h>

#include "pixelgym/render/camera.h"

namespace pixelgym::render {
namespace {

Eigen::Vector3f apply(const Eigen::Matrix4f& m, const Eigen::Vector3f& p) {
  const Eigen::Vector4f q = m * p.homogeneous();
  return q.head<3>() / q.w();
}

TEST(TransformsTest, ModelMatrixScalesThenPlaces) {
  Instance instance;
  instance.scale = {2, 3, 4};
  instance.X_world_instance = Eigen::Translation3f(1, 0, 0) *
                              Eigen::AngleAxisf(0.5F * 3.14159265F, Eigen::Vector3f::UnitZ());
  // (1, 1, 1) scales to (2, 3, 4), turns 90 degrees about z to (-3, 2, 4), moves to (-2, 2, 4).
  EXPECT_TRUE(apply(model_matrix(instance), {1, 1, 1}).isApprox(Eigen::Vector3f(-2, 2, 4), 1e-5F));
}

TEST(TransformsTest, LookFromPutsTheEyeAtTheOriginLookingDownMinusZ) {
  for (const Eigen::Vector3f& direction :
       {Eigen::Vector3f(0, 0, -1), Eigen::Vector3f(-0.35F, 0.5F, -0.8F),
        Eigen::Vector3f(1, 0, 0)}) {
    const Eigen::Vector3f eye(1, 2, 3);
    const Eigen::Matrix4f view = look_from(eye, direction);
    EXPECT_TRUE(apply(view, eye).isZero(1e-5F));
    const Eigen::Vector3f ahead = apply(view, eye + 2.0F * direction.normalized());
    EXPECT_TRUE(ahead.isApprox(Eigen::Vector3f(0, 0, -2), 1e-5F)) << ahead.transpose();
    const Eigen::Matrix3f rotation = view.topLeftCorner<3, 3>();
    EXPECT_TRUE(rotation.isUnitary(1e-5F));  // a rotation: no scale, no shear
    EXPECT_NEAR(rotation.determinant(), 1.0F, 1e-5F);
  }
}

TEST(TransformsTest, OrthographicMapsItsBoxToTheClipCube) {
  const Eigen::Matrix4f m = orthographic(-1, 3, 2, 4, 0.5F, 10);
  EXPECT_TRUE(apply(m, {-1, 2, -0.5F}).isApprox(Eigen::Vector3f(-1, -1, -1), 1e-5F));
  EXPECT_TRUE(apply(m, {3, 4, -10}).isApprox(Eigen::Vector3f(1, 1, 1), 1e-5F));
}

TEST(TransformsTest, EyeDepthInvertsThePerspectiveProjection) {
  Camera camera;
  camera.near_m = 0.1F;
  camera.far_m = 20.0F;
  const Eigen::Matrix4f projection = camera.projection_matrix();
  for (float distance : {0.1F, 0.5F, 2.0F, 7.5F, 19.9F}) {
    const float ndc = apply(projection, {0, 0, -distance}).z();
    const float window = 0.5F * ndc + 0.5F;
    EXPECT_NEAR(eye_depth_from_window(window, camera.near_m, camera.far_m), distance,
                1e-4F * distance)
        << distance;
  }
  EXPECT_EQ(eye_depth_from_window(1.0F, camera.near_m, camera.far_m), camera.far_m);
}

}  // namespace
}  // namespace pixelgym::render
