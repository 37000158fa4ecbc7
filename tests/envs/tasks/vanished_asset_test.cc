// Assets that vanish or turn unreadable under a process (issue 31's faults). An env reads its
// URDF and meshes once, when it is made: one made before its asset folder vanished resets, steps
// and renders as before; making one from a folder whose file is unreadable fails naming the file.
// The assets are copies in a temporary folder, found through PIXELGYM_ASSET_PATH.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"

namespace pixelgym {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A copy of assets/arm/ under a fresh temporary folder, which is returned.
fs::path copy_of_arm_assets(const std::string& name) {
  const fs::path root =
      fs::temp_directory_path() / ("pixelgym_assets_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root);
  fs::copy(fs::path(PIXELGYM_SOURCE_DIR) / "assets" / "arm", root / "arm",
           fs::copy_options::recursive);
  return root;
}

// Makes ArmReach-v0 (32x32 pixels) with PIXELGYM_ASSET_PATH naming `folder`.
std::unique_ptr<Env> make_arm_from(const fs::path& folder) {
  ::setenv("PIXELGYM_ASSET_PATH", folder.c_str(), 1);
  try {
    auto env = make("ArmReach-v0", {{"obs_mode", "pixels"}, {"width", 32}, {"height", 32}});
    ::unsetenv("PIXELGYM_ASSET_PATH");
    return env;
  } catch (...) {
    ::unsetenv("PIXELGYM_ASSET_PATH");
    throw;
  }
}

TEST(VanishedAssetTest, AnEnvMadeBeforeItsAssetsVanishedResetsStepsAndRendersAsBefore) {
  const fs::path root = copy_of_arm_assets("vanished");
  std::unique_ptr<Env> env = make_arm_from(root);
  std::unique_ptr<Env> reference =
      make("ArmReach-v0", {{"obs_mode", "pixels"}, {"width", 32}, {"height", 32}});
  fs::remove_all(root);
  ASSERT_FALSE(fs::exists(root / "arm" / "arm.urdf"));

  Rng actions(7);
  for (std::uint64_t seed : {1, 2}) {
    ASSERT_TRUE(env->reset(seed).obs.equals(reference->reset(seed).obs)) << "seed " << seed;
    for (int t = 0; t < 20; ++t) {
      const Value action = env->action_space().sample(actions);
      const StepResult a = env->step(action);
      const StepResult b = reference->step(action);
      ASSERT_TRUE(a.obs.equals(b.obs)) << "seed " << seed << ", step " << t;
      ASSERT_EQ(a.reward, b.reward);
    }
    ASSERT_TRUE(env->render().equals(reference->render())) << "seed " << seed;
  }
}

// The message of make_arm_from(root)'s failure.
std::string error_making_arm_from(const fs::path& root) {
  try {
    make_arm_from(root);
  } catch (const std::exception& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(VanishedAssetTest, AMissingOrUnreadableMeshIsAnErrorNamingItWhenTheEnvIsMade) {
  const fs::path root = copy_of_arm_assets("unreadable");
  const fs::path mesh = root / "arm" / "meshes" / "link3.obj";
  fs::remove(mesh);
  EXPECT_THAT(error_making_arm_from(root),
              HasSubstr((root / "arm" / "arm.urdf").string() +
                        ": link \"link3\" visual 0: cannot resolve \"meshes/link3.obj\""));
  // Not a mesh (as root, permissions would not stop the read): bytes no importer reads.
  std::ofstream(mesh, std::ios::binary) << std::string(64, '\x01');
  EXPECT_THAT(error_making_arm_from(root), HasSubstr("mesh " + mesh.string() + ": "));
  fs::remove_all(root);
}

}  // namespace
}  // namespace pixelgym
