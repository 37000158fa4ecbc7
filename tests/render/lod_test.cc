// Level of detail and face culling, without a GL context.
#include "pixelgym/render/lod.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pixelgym::render {
namespace {

constexpr float kPi = 3.14159265358979323846F;

// A fine mesh with a coarse version drawn below 10 pixels of radius.
std::shared_ptr<const MeshData> fine_with_coarse() {
  return with_low_detail(*make_sphere_mesh(24), make_sphere_mesh(6), 10.0F);
}

Instance instance_at(const std::shared_ptr<const MeshData>& mesh, float distance, float scale) {
  Instance instance;
  instance.mesh = mesh;
  instance.scale = Eigen::Vector3f::Constant(scale);
  instance.X_world_instance.translation() = Eigen::Vector3f(0, distance, 0);
  return instance;
}

// The distance at which an instance's radius covers exactly `mesh.low_detail_below_px` pixels.
float switch_distance(const MeshData& mesh, float scale, const Camera& camera) {
  const float size = scale * mesh.low_detail_radius;
  return size * 0.5F * static_cast<float>(camera.height) /
         (std::tan(camera.fov_y_deg * kPi / 360.0F) * mesh.low_detail_below_px);
}

TEST(LodTest, CoarseMeshOnlyBelowItsPixelSize) {
  const auto mesh = fine_with_coarse();
  const Camera camera;  // at the origin, 84 x 84, 45 degrees
  const float d = switch_distance(*mesh, 0.2F, camera);
  ASSERT_GT(d, 0.5F);
  EXPECT_EQ(select_detail(instance_at(mesh, 0.98F * d, 0.2F), camera), mesh);
  EXPECT_EQ(select_detail(instance_at(mesh, 1.02F * d, 0.2F), camera), mesh->low_detail);
  // A taller image shows the same instance with more pixels: fine again.
  Camera tall = camera;
  tall.height = 2 * camera.height;
  EXPECT_EQ(select_detail(instance_at(mesh, 1.02F * d, 0.2F), tall), mesh);
  // A narrower field of view magnifies it too.
  Camera zoomed = camera;
  zoomed.fov_y_deg = 30.0F;
  EXPECT_EQ(select_detail(instance_at(mesh, 1.02F * d, 0.2F), zoomed), mesh);
}

TEST(LodTest, TheSmallerOfTheXAndYScalesDecidesAndZDoesNot) {
  const auto mesh = fine_with_coarse();
  const Camera camera;
  const float d = switch_distance(*mesh, 0.2F, camera);
  Instance thin = instance_at(mesh, 0.9F * d, 0.2F);
  EXPECT_EQ(select_detail(thin, camera), mesh);
  thin.scale.y() = 0.1F;  // half as wide on one axis: small enough for the coarse mesh
  EXPECT_EQ(select_detail(thin, camera), mesh->low_detail);
  thin.scale = {0.2F, 0.2F, 0.01F};  // a flat disc: z is the axis segments do not resolve
  EXPECT_EQ(select_detail(thin, camera), mesh);
  thin.scale = {-0.2F, 0.2F, 0.2F};  // mirrored: the size is the same
  EXPECT_EQ(select_detail(thin, camera), mesh);
}

TEST(LodTest, MeshWithoutCoarseVersionIsAlwaysItself) {
  const auto mesh = make_sphere_mesh(24);
  const Instance far_away = instance_at(mesh, 1000.0F, 0.01F);
  EXPECT_EQ(select_detail(far_away, Camera{}), mesh);
}

TEST(LodTest, OnlyClosedUnmirroredMeshesAreCulled) {
  const auto box = make_box_mesh();
  ASSERT_TRUE(box->closed);
  Instance instance;
  instance.mesh = box;
  EXPECT_TRUE(cullable(instance, *box));
  instance.scale = {-1, 1, 1};  // one mirror turns the winding inside out
  EXPECT_FALSE(cullable(instance, *box));
  instance.scale = {-1, -1, 1};  // two mirrors are a rotation
  EXPECT_TRUE(cullable(instance, *box));
  MeshData open = *box;
  open.closed = false;
  instance.scale = {1, 1, 1};
  EXPECT_FALSE(cullable(instance, open));
}

}  // namespace
}  // namespace pixelgym::render
