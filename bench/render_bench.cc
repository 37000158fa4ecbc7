// Frames per second of the renderer on a moving scene, as the floor program measures its own.
//
// usage: render_bench SCENE WIDTH HEIGHT FRAMES [shadows]     SCENE: cartpole | arm
// prints: scene=... size=WxH shadows=0|1 frames=N seconds=S frames_per_s=F renderer=...
//
// Each frame moves the robot (joint state), updates the scene poses, renders and reads back RGB:
// the render half of an env step. bench/render_vs_floor.sh runs it beside ../shared/peers/floor.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "pixelgym/render/renderer.h"
#include "tests/envs/scene_fixtures.h"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s cartpole|arm WIDTH HEIGHT FRAMES [shadows]\n", argv[0]);
    return 2;
  }
  const std::string scene_name = argv[1];
  const int width = std::atoi(argv[2]);
  const int height = std::atoi(argv[3]);
  const int frames = std::atoi(argv[4]);
  const bool shadows = argc > 5 && std::string(argv[5]) == "shadows";
  if (scene_name != "cartpole" && scene_name != "arm") {
    std::fprintf(stderr, "unknown scene %s\n", scene_name.c_str());
    return 2;
  }
  const bool arm = scene_name == "arm";
  pixelgym::testing::FixtureScene f = arm ? pixelgym::testing::arm_scene(width, height)
                                          : pixelgym::testing::cartpole_scene(width, height);
  f.view->scene().shadows = shadows;
  pixelgym::render::Renderer renderer;
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
                                3);
  const int dofs = f.world->num_dofs(pixelgym::engine::RobotId{0});
  Eigen::VectorXd q = f.world->joint_positions(pixelgym::engine::RobotId{0});
  const Eigen::VectorXd q0 = q;
  unsigned long checksum = 0;
  std::chrono::steady_clock::time_point start;
  for (int i = -100; i < frames; ++i) {
    if (i == 0) start = std::chrono::steady_clock::now();
    for (int d = 0; d < dofs; ++d) q[d] = q0[d] + 0.4 * std::sin(0.01 * i + d);
    f.world->set_joint_state(pixelgym::engine::RobotId{0}, q, Eigen::VectorXd::Zero(dofs));
    f.view->update(*f.world);
    renderer.render(f.view->scene(), f.camera, {width, height, rgb.data()});
    checksum += rgb[rgb.size() / 2];
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "scene=%s size=%dx%d shadows=%d frames=%d seconds=%.3f frames_per_s=%.0f renderer=%s "
      "checksum=%lu\n",
      scene_name.c_str(), width, height, shadows ? 1 : 0, frames, seconds, frames / seconds,
      renderer.description().c_str(), checksum);
  return 0;
}
