#include "pixelgym/envs/tasks/world_scene.h"

#include <gtest/gtest.h>

#include "pixelgym/envs/array.h"
#include "pixelgym/render/renderer.h"
#include "tests/envs/scene_fixtures.h"
#include "tests/golden.h"

namespace pixelgym {
namespace {

using testing::FixtureScene;

Array draw(FixtureScene& f, render::Renderer& renderer) {
  Array frame(DType::kUInt8, {f.camera.height, f.camera.width, 3});
  renderer.render(f.view->scene(), f.camera,
                  {f.camera.width, f.camera.height, frame.data<std::uint8_t>()});
  return frame;
}

TEST(WorldSceneTest, OneInstancePerVisualShapeWithSegmentationIds) {
  FixtureScene f = testing::arm_scene(84, 84);
  ASSERT_EQ(f.view->scene().instances.size(), f.world->visual_shapes().size());
  EXPECT_EQ(f.view->scene().instances.size(), 9U + 5U + 1U + 1U);  // arm, table, cube, target
  for (std::size_t i = 0; i < f.view->scene().instances.size(); ++i) {
    EXPECT_EQ(f.view->scene().instances[i].segmentation_id,
              f.world->visual_shapes()[i].segmentation_id);
    EXPECT_GT(f.view->scene().instances[i].segmentation_id, 0);
  }
}

TEST(WorldSceneTest, UpdateFollowsTheWorld) {
  FixtureScene f = testing::cartpole_scene(84, 84);
  const Eigen::Isometry3f before = f.view->scene().instances.back().X_world_instance;  // the pole
  f.world->set_joint_state(engine::RobotId{0}, (Eigen::VectorXd(2) << -0.5, 0.0).finished(),
                           Eigen::VectorXd::Zero(2));
  f.view->update(*f.world);
  const Eigen::Isometry3f after = f.view->scene().instances.back().X_world_instance;
  EXPECT_NEAR(after.translation().x() - before.translation().x(), -0.8F - 0.5F * std::sin(0.4F),
              1e-4F);
}

TEST(WorldSceneTest, UrdfColoursOverrideMeshColoursOnlyWhenGiven) {
  FixtureScene f = testing::arm_scene(84, 84);
  // The arm's links are meshes without a URDF colour: their parts keep the .mtl colours.
  const render::Instance& link1 = f.view->scene().instances[1];
  ASSERT_FALSE(link1.mesh->parts.empty());
  EXPECT_TRUE(link1.mesh->parts[0].has_color);
}

TEST(WorldSceneTest, UrdfColoursOverrideTheMeshsOwnColours) {
  // tests/data/urdf_good/coloured_mesh.urdf: the same blue-topped, yellow-sided mesh three times
  // along x, with an inline green, a named red and no URDF colour. Seen from above, the tops are
  // green, red and (the mesh's own) blue.
  FixtureScene f;
  f.world = std::make_unique<engine::World>();
  f.world->add_robot(engine::default_model_cache().load_urdf(
      std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/coloured_mesh.urdf"));
  f.view = std::make_unique<WorldScene>(*f.world);
  const std::vector<render::Instance>& instances = f.view->scene().instances;
  ASSERT_EQ(instances.size(), 3U);
  for (int i = 0; i < 2; ++i) {
    for (const render::MeshData::Part& part : instances[i].mesh->parts)
      EXPECT_FALSE(part.has_color) << "instance " << i << ": the URDF colour must win";
  }
  EXPECT_TRUE(instances[0].material.base_color.isApprox(Eigen::Vector4f(0.1F, 0.7F, 0.2F, 1.0F)));
  EXPECT_TRUE(instances[1].material.base_color.isApprox(Eigen::Vector4f(0.8F, 0.1F, 0.1F, 1.0F)));
  for (const render::MeshData::Part& part : instances[2].mesh->parts) EXPECT_TRUE(part.has_color);

  f.camera =
      render::Camera::look_at({0.0F, 0.0F, 1.5F}, {0.0F, 0.0F, 0.0F}, Eigen::Vector3f::UnitY());
  f.camera.width = 84;
  f.camera.height = 84;
  render::Renderer renderer;
  const Array frame = draw(f, renderer);
  const Eigen::Matrix4f view_projection = f.camera.projection_matrix() * f.camera.view_matrix();
  const auto top_colour = [&](float x) {
    const Eigen::Vector4f clip = view_projection * Eigen::Vector4f(x, 0.0F, 0.2F, 1.0F);
    const int column = static_cast<int>((clip.x() / clip.w() * 0.5F + 0.5F) * 84.0F);
    const int row = static_cast<int>((clip.y() / clip.w() * 0.5F + 0.5F) * 84.0F);
    const std::uint8_t* pixel = frame.data<std::uint8_t>() + (row * 84 + column) * 3;
    return Eigen::Vector3i(pixel[0], pixel[1], pixel[2]);
  };
  const Eigen::Vector3i green = top_colour(-0.3F);
  const Eigen::Vector3i red = top_colour(0.0F);
  const Eigen::Vector3i blue = top_colour(0.3F);
  EXPECT_GT(green.y(), std::max(green.x(), green.z()) + 40) << green.transpose();
  EXPECT_GT(red.x(), std::max(red.y(), red.z()) + 40) << red.transpose();
  EXPECT_GT(blue.z(), std::max(blue.x(), blue.y()) + 40) << blue.transpose();
}

TEST(WorldSceneTest, FrameBoxShowsTheWholeBox) {
  FixtureScene f = testing::arm_scene(64, 48);
  const Eigen::AlignedBox3f box = f.view->bounds();
  const render::Camera camera = frame_box(box, -50.0F, 25.0F, 64, 48);
  const Eigen::Matrix4f vp = camera.projection_matrix() * camera.view_matrix();
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3f p = box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner));
    const Eigen::Vector4f clip = vp * p.homogeneous();
    EXPECT_LE(std::abs(clip.x() / clip.w()), 1.0F) << corner;
    EXPECT_LE(std::abs(clip.y() / clip.w()), 1.0F) << corner;
  }
  EXPECT_THROW(frame_box(Eigen::AlignedBox3f(), 0, 0, 64, 64), std::invalid_argument);
}

struct GoldenCase {
  const char* name;
  bool arm;
  int size;
  friend void PrintTo(const GoldenCase& c, std::ostream* out) { *out << c.name; }
};

class GoldenTest : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(GoldenTest, MatchesTheReferenceFrame) {
  const GoldenCase& c = GetParam();
  FixtureScene f =
      c.arm ? testing::arm_scene(c.size, c.size) : testing::cartpole_scene(c.size, c.size);
  render::Renderer renderer;
  const Array frame = draw(f, renderer);
  EXPECT_TRUE(testing::matches_golden(c.name, frame));
}

INSTANTIATE_TEST_SUITE_P(Scenes, GoldenTest,
                         ::testing::Values(GoldenCase{"cartpole_84", false, 84},
                                           GoldenCase{"cartpole_256", false, 256},
                                           GoldenCase{"arm_84", true, 84},
                                           GoldenCase{"arm_256", true, 256}),
                         [](const ::testing::TestParamInfo<GoldenCase>& param_info) {
                           return std::string(param_info.param.name);
                         });

}  // namespace
}  // namespace pixelgym
