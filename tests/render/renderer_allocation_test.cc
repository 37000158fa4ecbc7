// A warm renderer draws a frame without a heap allocation of its own: its per-frame scratch
// (drawn meshes, bounds, shadow casters, footprints, background key, read-back buffer) is kept
// between frames. Counts C++ allocations (operator new, replaced in this binary); Mesa's own C
// allocations are not counted.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>

#include "pixelgym/render/renderer.h"

namespace {
std::atomic<long> allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace pixelgym::render {
namespace {

// Boxes and a sphere with a coarse version, on the floor, with shadows.
Scene make_scene() {
  Scene scene;
  const auto box = make_box_mesh();
  const auto ball = with_low_detail(*make_sphere_mesh(24), make_sphere_mesh(8), 6.0F);
  for (int i = 0; i < 4; ++i) {
    Instance instance;
    instance.mesh = i % 2 == 0 ? box : ball;
    instance.scale = Eigen::Vector3f::Constant(0.2F + 0.05F * static_cast<float>(i));
    instance.segmentation_id = i + 1;
    scene.instances.push_back(instance);
  }
  scene.instances[3].casts_shadow = false;
  return scene;
}

void move(Scene& scene, float t) {
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const float phase = t + static_cast<float>(i);
    scene.instances[i].X_world_instance = Eigen::Translation3f(
        0.6F * std::cos(phase), 0.6F * std::sin(phase), 0.3F + 0.1F * static_cast<float>(i));
  }
}

TEST(RendererAllocationTest, WarmFramesAllocateNothing) {
  Renderer renderer;
  Scene scene = make_scene();
  for (int msaa : {0, 4}) {
    Camera camera = Camera::look_at({1.5F, -2.5F, 1.8F}, {0, 0, 0.3F});
    camera.msaa_samples = msaa;
    std::vector<std::uint8_t> rgb(84 * 84 * 3);
    std::vector<float> depth(84 * 84);
    std::vector<std::int32_t> ids(84 * 84);
    const RenderTargets targets{84, 84, rgb.data(), depth.data(), ids.data()};
    for (int frame = 0; frame < 3; ++frame) {  // warm-up: uploads, targets, scratch capacity
      move(scene, 0.1F * static_cast<float>(frame));
      renderer.render(scene, camera, targets);
    }
    const long before = allocations.load();
    for (int frame = 3; frame < 20; ++frame) {
      move(scene, 0.1F * static_cast<float>(frame));
      renderer.render(scene, camera, targets);
    }
    EXPECT_EQ(allocations.load() - before, 0) << "over 17 warm frames with msaa " << msaa;
  }
}

}  // namespace
}  // namespace pixelgym::render
