// Uses an installed pixelgym (tests/install/CMakeLists.txt): a built-in pixel env whose robot is
// read from the installed assets, a wrapper, the env checker and a rollout whose frames are drawn.
// Prints the assets folder in use, then "consumer ran to the end"; exits 1 with the reason on any
// failure.
#include <pixelgym/engine/robot_model.h>
#include <pixelgym/envs/checker.h>
#include <pixelgym/envs/registry.h>
#include <pixelgym/wrappers/wrapper_spec.h>

#include <cstdint>
#include <exception>
#include <iostream>
#include <memory>

namespace {

std::unique_ptr<pixelgym::Env> make_env() {
  return pixelgym::wrappers::wrapping({"grayscale"})(pixelgym::make(
      "CartPoleSwingup-v0", {{"obs_mode", "pixels"}, {"render_width", 64}, {"render_height", 64}}));
}

}  // namespace

int main() {
  try {
    std::cout << "assets: " << pixelgym::engine::assets_folder() << "\n";
    {
      auto checked = make_env();
      const pixelgym::CheckReport report = pixelgym::check_env(*checked);
      for (const pixelgym::CheckResult& failure : report.failures()) {
        std::cerr << "check_env: " << failure.name << ": " << failure.reason << "\n";
      }
      if (!report.passed()) return 1;
    }
    auto env = make_env();
    env->reset(std::uint64_t{0});
    env->action_space().seed(0);
    std::int64_t lit = 0;
    for (int t = 0; t < 20; ++t) {
      env->step(env->action_space().sample());
      const pixelgym::Array pixels = env->render();
      for (std::int64_t i = 0; i < pixels.size(); ++i) lit += pixels.data<std::uint8_t>()[i] > 0;
    }
    if (lit == 0) {
      std::cerr << "consumer: every pixel of 20 frames was black\n";
      return 1;
    }
    std::cout << "observation space " << env->observation_space().to_string() << "\n";
    std::cout << "consumer ran to the end\n";
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "consumer: " << error.what() << "\n";
    return 1;
  }
}
