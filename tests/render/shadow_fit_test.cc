// Where the shadow map looks and where shadows can fall, without a GL context.
#include "pixelgym/render/shadow_fit.h"

#include <gtest/gtest.h>

#include "pixelgym/render/transforms.h"

namespace pixelgym::render {
namespace {

const Eigen::AlignedBox3f kUnitBox(Eigen::Vector3f::Constant(-0.5F),
                                   Eigen::Vector3f::Constant(0.5F));

Instance box_at(const Eigen::Vector3f& centre, const Eigen::Vector3f& size) {
  Instance instance;
  instance.mesh = make_box_mesh();
  instance.scale = size;
  instance.X_world_instance.translation() = centre;
  return instance;
}

TEST(ShadowFitTest, MapSizeIsThePowerOfTwoAtOrAboveTheImageWithinLimits) {
  const auto size_for = [](int width, int height) {
    Camera camera;
    camera.width = width;
    camera.height = height;
    return shadow_map_size(camera);
  };
  EXPECT_EQ(size_for(84, 84), 128);
  EXPECT_EQ(size_for(1, 1), 128);
  EXPECT_EQ(size_for(128, 128), 128);
  EXPECT_EQ(size_for(129, 64), 256);
  EXPECT_EQ(size_for(64, 300), 512);
  EXPECT_EQ(size_for(2048, 2048), 2048);
  EXPECT_EQ(size_for(4096, 100), 2048);
}

TEST(ShadowFitTest, NothingToFitWithoutCasters) {
  Scene scene;
  EXPECT_FALSE(fit_light_projection(scene, {}).has_value());
  scene.instances.push_back(box_at({0, 0, 1}, {1, 1, 1}));
  scene.instances[0].casts_shadow = false;
  EXPECT_FALSE(fit_light_projection(scene, {kUnitBox}).has_value());
}

// Every caster corner lands inside the clip cube, and the box is tight: on each axis some corner
// lies on each face.
TEST(ShadowFitTest, LightBoxHoldsEveryCasterTightly) {
  Scene scene;
  scene.light.direction = {-0.35F, 0.5F, -0.8F};
  scene.instances.push_back(box_at({0, 0, 1}, {0.5F, 0.2F, 2.0F}));
  scene.instances.push_back(box_at({1.5F, -0.5F, 0.3F}, {0.3F, 0.3F, 0.3F}));
  scene.instances.push_back(box_at({50, 50, 50}, {1, 1, 1}));  // a marker: casts nothing
  scene.instances[2].casts_shadow = false;
  const std::vector<Eigen::AlignedBox3f> bounds(3, kUnitBox);
  const std::optional<Eigen::Matrix4f> light = fit_light_projection(scene, bounds);
  ASSERT_TRUE(light.has_value());
  Eigen::Vector3f low = Eigen::Vector3f::Constant(1e9F);
  Eigen::Vector3f high = Eigen::Vector3f::Constant(-1e9F);
  for (int i = 0; i < 2; ++i) {
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3f world =
          (model_matrix(scene.instances[static_cast<std::size_t>(i)]) *
           kUnitBox.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner)).homogeneous())
              .head<3>();
      const Eigen::Vector3f clip = (*light * world.homogeneous()).head<3>();
      low = low.cwiseMin(clip);
      high = high.cwiseMax(clip);
    }
  }
  EXPECT_TRUE(low.isApprox(Eigen::Vector3f::Constant(-1), 1e-4F)) << low.transpose();
  EXPECT_TRUE(high.isApprox(Eigen::Vector3f::Constant(1), 1e-4F)) << high.transpose();
  // Nearer the light is smaller depth: the top of the tall box is nearer than the floor under it.
  const auto depth = [&light](const Eigen::Vector3f& p) { return (*light * p.homogeneous()).z(); };
  EXPECT_LT(depth({0, 0, 2}), depth({0, 0, 0}));
}

TEST(ShadowFitTest, FlatCasterStillGivesAFiniteBox) {
  Scene scene;
  scene.light.direction = {0, 0, -1};
  scene.instances.push_back(box_at({0, 0, 1}, {1, 1, 0}));  // a sheet facing the light
  const std::optional<Eigen::Matrix4f> light = fit_light_projection(scene, {kUnitBox});
  ASSERT_TRUE(light.has_value());
  EXPECT_TRUE(light->allFinite());
  EXPECT_NEAR((*light * Eigen::Vector4f(0, 0, 1, 1)).z(), 0.0F, 1e-3F);  // mid-depth of 1 mm
}

TEST(ShadowFitTest, FootprintIsTheBoxProjectedAlongTheLight) {
  Scene scene;
  scene.floor.height_m = 0.1F;
  scene.light.direction = {0, 0, -1};  // straight down: the footprint is the box's own square
  scene.instances.push_back(box_at({1, 2, 1}, {0.5F, 0.4F, 0.2F}));
  std::vector<Eigen::AlignedBox2f> rectangles;
  shadow_footprints(scene, {kUnitBox}, rectangles);
  ASSERT_EQ(rectangles.size(), 1U);
  EXPECT_TRUE(rectangles[0].min().isApprox(Eigen::Vector2f(0.75F, 1.8F), 1e-5F));
  EXPECT_TRUE(rectangles[0].max().isApprox(Eigen::Vector2f(1.25F, 2.2F), 1e-5F));
  // At 45 degrees along +x, a point at height z above the floor lands z further along x.
  scene.light.direction = {1, 0, -1};
  shadow_footprints(scene, {kUnitBox}, rectangles);
  ASSERT_EQ(rectangles.size(), 1U);
  EXPECT_NEAR(rectangles[0].min().x(), 0.75F + (0.9F - 0.1F), 1e-5F);  // bottom's near edge
  EXPECT_NEAR(rectangles[0].max().x(), 1.25F + (1.1F - 0.1F), 1e-5F);  // top's far edge
  EXPECT_NEAR(rectangles[0].min().y(), 1.8F, 1e-5F);
  EXPECT_NEAR(rectangles[0].max().y(), 2.2F, 1e-5F);
}

TEST(ShadowFitTest, NoFootprintBelowTheFloorForMarkersOrFromALowLight) {
  Scene scene;
  scene.light.direction = {0, 0, -1};
  scene.instances.push_back(box_at({0, 0, -1}, {1, 1, 1}));  // under the floor
  scene.instances.push_back(box_at({0, 0, 1}, {1, 1, 1}));
  scene.instances[1].casts_shadow = false;
  scene.instances.push_back(box_at({3, 0, 0.1F}, {1, 1, 1}));  // half sunk: still casts
  const std::vector<Eigen::AlignedBox3f> bounds(3, kUnitBox);
  std::vector<Eigen::AlignedBox2f> rectangles(5);  // stale contents are cleared
  shadow_footprints(scene, bounds, rectangles);
  ASSERT_EQ(rectangles.size(), 1U);
  EXPECT_NEAR(rectangles[0].center().x(), 3.0F, 1e-5F);
  scene.light.direction = {1, 0, 0};  // along the horizon
  shadow_footprints(scene, bounds, rectangles);
  EXPECT_TRUE(rectangles.empty());
  scene.light.direction = {1, 0, 0.2F};  // from below
  shadow_footprints(scene, bounds, rectangles);
  EXPECT_TRUE(rectangles.empty());
}

}  // namespace
}  // namespace pixelgym::render
