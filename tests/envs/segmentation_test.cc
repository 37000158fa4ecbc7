// Segmentation ids over the whole registry: one id per owner (robot link or body), and each
// owner's id drawn exactly where the owner is seen.
//
// What "visible" means here: an owner (all visual shapes of one robot link, or one body) is drawn
// ALONE in its env's scene from the task's camera (floor and sky kept, every other instance
// removed); the pixels it covers there are where it is drawn. An owner that covers no pixel alone
// is outside the frustum or too small to hit a pixel centre, and is not required to appear. In
// the full scene, every pixel the owner covers alone must show its id, or a surface no farther
// from the camera (something in front of it: depth from the same render); and its id must appear
// nowhere else. So a pixel of an owner hidden behind another is not required, an owner hidden
// entirely is allowed, and two owners that share an id fail the second rule wherever the other
// one shows.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/render/renderer.h"
#include "tests/envs/env_ids.h"

namespace pixelgym {
namespace {

struct Images {
  std::vector<std::int32_t> segmentation;
  std::vector<float> depth;
};

Images draw(render::Renderer& renderer, const render::Scene& scene, const render::Camera& camera) {
  const auto pixels =
      static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  Images images{std::vector<std::int32_t>(pixels), std::vector<float>(pixels)};
  render::RenderTargets targets;
  targets.width = camera.width;
  targets.height = camera.height;
  targets.segmentation = images.segmentation.data();
  targets.depth = images.depth.data();
  renderer.render(scene, camera, targets);
  return images;
}

// Every owner of visual shapes in `world` and its segmentation id, named as VisualShape::owner
// names it ("robot/link" or the body name).
std::map<std::string, int> owner_ids(const engine::World& world) {
  std::map<std::string, int> ids;
  std::set<int> seen;
  const auto add = [&](const std::string& owner, int id) {
    EXPECT_GT(id, 0) << owner << ": ids start at 1 (0 is the background)";
    EXPECT_TRUE(ids.emplace(owner, id).second) << "two owners are named \"" << owner << "\"";
    EXPECT_TRUE(seen.insert(id).second) << owner << " shares segmentation id " << id;
  };
  for (int r = 0; r < world.num_robots(); ++r) {
    const engine::RobotId robot{r};
    const engine::RobotModel& model = world.robot_model(robot);
    for (std::size_t l = 0; l < model.links().size(); ++l) {
      add(model.name() + "/" + model.links()[l].name,
          world.segmentation_id(robot, static_cast<int>(l)));
    }
  }
  for (int b = 0; b < world.num_bodies(); ++b) {
    const engine::BodyId body{b};
    add(world.body_options(body).name, world.segmentation_id(body));
  }
  return ids;
}

class SegmentationTest : public ::testing::TestWithParam<std::string> {
 protected:
  // The env after reset(seed=0) and a few steps, or null (with the test skipped) when the env
  // has no World (GridWorld-v0 draws its grid directly).
  std::unique_ptr<Env> make_env() {
    std::unique_ptr<Env> env = make(GetParam());
    if (dynamic_cast<PixelEnv*>(&env->unwrapped()) == nullptr) return nullptr;
    env->reset(0);
    Rng rng(0);
    for (int s = 0; s < 5; ++s) env->step(env->action_space().sample(rng));
    return env;
  }
};

TEST_P(SegmentationTest, EveryOwnerHasItsOwnIdAndItsShapesCarryIt) {
  std::unique_ptr<Env> env = make_env();
  if (env == nullptr) GTEST_SKIP() << GetParam() << " has no engine World (nothing to segment)";
  const auto& pixel_env = static_cast<PixelEnv&>(env->unwrapped());
  const engine::World& world = pixel_env.world();
  const std::map<std::string, int> ids = owner_ids(world);
  const render::Scene& scene = pixel_env.scene().scene();
  ASSERT_EQ(scene.instances.size(), world.visual_shapes().size());
  for (std::size_t i = 0; i < world.visual_shapes().size(); ++i) {
    const engine::VisualShape& shape = world.visual_shapes()[i];
    ASSERT_EQ(ids.count(shape.owner), 1U)
        << "visual shape " << i << ": unknown owner " << shape.owner;
    EXPECT_EQ(shape.segmentation_id, ids.at(shape.owner)) << shape.owner;
    EXPECT_EQ(scene.instances[i].segmentation_id, shape.segmentation_id) << shape.owner;
  }
}

TEST_P(SegmentationTest, EachVisibleOwnersIdIsDrawnWhereItIsAndNowhereElse) {
  std::unique_ptr<Env> env = make_env();
  if (env == nullptr) GTEST_SKIP() << GetParam() << " has no engine World (nothing to segment)";
  const auto& pixel_env = static_cast<PixelEnv&>(env->unwrapped());
  const engine::World& world = pixel_env.world();
  const render::Scene& scene = pixel_env.scene().scene();
  render::Renderer renderer;
  int visible_owners = 0;
  int owners_out_of_view = 0;  // no pixel alone
  int owners_hidden = 0;       // pixels alone, all behind something else
  for (const std::string& camera_name : pixel_env.task().camera_names()) {
    render::Camera camera = pixel_env.task().camera(camera_name, world);
    camera.width = pixel_env.config().width;
    camera.height = pixel_env.config().height;
    const Images full = draw(renderer, scene, camera);
    // Instances by owner (not by id: owners that share an id must be told apart).
    std::map<std::string, std::vector<std::size_t>> instances_of;
    for (std::size_t i = 0; i < scene.instances.size(); ++i)
      instances_of[world.visual_shapes()[i].owner].push_back(i);
    for (const auto& [owner, instances] : instances_of) {
      const int id = scene.instances[instances.front()].segmentation_id;
      render::Scene alone_scene = scene;
      alone_scene.instances.clear();
      for (std::size_t i : instances) alone_scene.instances.push_back(scene.instances[i]);
      const Images alone = draw(renderer, alone_scene, camera);
      const std::string what =
          camera_name + " camera, " + owner + " (id " + std::to_string(id) + ")";
      int covered = 0;
      int shown = 0;
      int wrongly_hidden = 0;
      int shown_elsewhere = 0;
      for (std::size_t p = 0; p < full.segmentation.size(); ++p) {
        const bool drawn_here = alone.segmentation[p] == id;
        covered += drawn_here ? 1 : 0;
        if (drawn_here && full.segmentation[p] == id) ++shown;
        // Something else may cover it only from no farther away (a tenth of a millimetre of
        // depth-buffer slack for coplanar surfaces).
        if (drawn_here && full.segmentation[p] != id && full.depth[p] > alone.depth[p] + 1e-4F)
          ++wrongly_hidden;
        if (!drawn_here && full.segmentation[p] == id) ++shown_elsewhere;
      }
      EXPECT_EQ(wrongly_hidden, 0) << what << ": pixels where it is nearest show another id";
      EXPECT_EQ(shown_elsewhere, 0) << what << ": its id appears where it is not drawn";
      if (covered == 0) {
        ++owners_out_of_view;
      } else if (shown == 0) {
        ++owners_hidden;
      } else {
        ++visible_owners;
      }
    }
  }
  // Every env shows something of its world.
  EXPECT_GT(visible_owners, 0);
  std::printf("%s (all cameras): %d owners seen, %d hidden behind others, %d not in view\n",
              GetParam().c_str(), visible_owners, owners_hidden, owners_out_of_view);
}

INSTANTIATE_TEST_SUITE_P(AllEnvs, SegmentationTest, ::testing::ValuesIn(registered_ids()),
                         testing::env_id_test_name);

}  // namespace
}  // namespace pixelgym
