// ContextGroup: renderers that draw with one GL context, one after another, as the envs a
// vector env runs on one thread do. Every test compares bytes with renderers that have contexts
// of their own, so any GL state one renderer leaves behind for the next shows up as a difference.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "pixelgym/render/mesh_data.h"
#include "pixelgym/render/renderer.h"
#include "tests/render/box_and_ball_scene.h"
#include "tests/worker_thread.h"

namespace pixelgym::render {
namespace {

using pixelgym::testing::WorkerThread;

// Everything one frame gives.
struct Frame {
  std::vector<std::uint8_t> rgb;
  std::vector<float> depth;
  std::vector<std::int32_t> segmentation;
  bool operator==(const Frame& other) const {
    return rgb == other.rgb && depth == other.depth && segmentation == other.segmentation;
  }
};

// What renderer `r` draws: the renderers differ in every setting a renderer sets GL state for
// (image size, MSAA, shadows, floor, textures off, culling of closed meshes, depth and
// segmentation outputs), so that a setting left behind by one shows up in another's bytes.
struct Look {
  int size;
  int msaa;
  bool shadows;
  bool floor;
  bool depth_and_segmentation;
};

// Renderers 0 and 3 share an image size and sample count but not a camera, so their
// backgrounds are kept side by side.
const Look kLooks[] = {
    {32, 0, true, true, false}, {48, 4, false, true, true}, {40, 0, false, false, true},
    {32, 0, true, true, true},  {32, 2, true, true, true},
};
constexpr int kRenderers = 5;

Scene scene(int r, int frame) {
  const Look& look = kLooks[r];
  const float offset = 0.1F * static_cast<float>(r) + 0.03F * static_cast<float>(frame);
  Scene scene =
      testing::box_and_ball_scene(offset, /*box_segmentation_id=*/3, /*ball_segmentation_id=*/7);
  scene.shadows = look.shadows;
  scene.floor.enabled = look.floor;
  for (Instance& instance : scene.instances) {
    instance.material.specular = 0.1F + 0.2F * static_cast<float>(r);  // each renderer its own
  }
  return scene;
}

Frame draw(Renderer& renderer, int r, int frame) {
  const Look& look = kLooks[r];
  Camera camera = Camera::look_at({0.2F * static_cast<float>(r), -3, 0.5F}, {0, 0, 0.5F});
  camera.width = look.size;
  camera.height = look.size;
  camera.msaa_samples = look.msaa;
  const auto pixels = static_cast<std::size_t>(look.size * look.size);
  Frame out;
  out.rgb.resize(pixels * 3);
  RenderTargets targets{look.size, look.size, out.rgb.data()};
  if (look.depth_and_segmentation) {
    out.depth.resize(pixels);
    out.segmentation.resize(pixels);
    targets.depth = out.depth.data();
    targets.segmentation = out.segmentation.data();
  }
  renderer.render(scene(r, frame), camera, targets);
  return out;
}

// Frames [renderer][frame] of renderers with their own contexts, each drawn alone.
std::vector<std::vector<Frame>> own_contexts(int frames) {
  std::vector<std::vector<Frame>> out(kRenderers);
  for (int r = 0; r < kRenderers; ++r) {
    Renderer renderer;
    for (int f = 0; f < frames; ++f)
      out[static_cast<std::size_t>(r)].push_back(draw(renderer, r, f));
  }
  return out;
}

// Renderers made with `group`.
std::vector<std::unique_ptr<Renderer>> make_renderers(ContextGroup& group) {
  std::vector<std::unique_ptr<Renderer>> renderers;
  for (int r = 0; r < kRenderers; ++r) renderers.push_back(std::make_unique<Renderer>(group));
  return renderers;
}

TEST(ContextGroupTest, RenderersTakingTurnsGiveTheBytesOfRenderersWithTheirOwnContexts) {
  constexpr int kFrames = 3;
  const auto expected = own_contexts(kFrames);
  ContextGroup shared;
  EXPECT_FALSE(shared.created());
  auto renderers = make_renderers(shared);
  EXPECT_TRUE(shared.created());
  std::vector<std::vector<Frame>> got(kRenderers);
  for (int f = 0; f < kFrames; ++f) {
    // Turns in a different order every frame.
    for (int k = 0; k < kRenderers; ++k) {
      const int r = (f % 2 == 0) ? k : kRenderers - 1 - k;
      got[static_cast<std::size_t>(r)].push_back(
          draw(*renderers[static_cast<std::size_t>(r)], r, f));
    }
  }
  for (int r = 0; r < kRenderers; ++r) {
    for (int f = 0; f < kFrames; ++f) {
      EXPECT_TRUE(got[static_cast<std::size_t>(r)][static_cast<std::size_t>(f)] ==
                  expected[static_cast<std::size_t>(r)][static_cast<std::size_t>(f)])
          << "renderer " << r << ", frame " << f;
    }
  }
}

TEST(ContextGroupTest, MoreCamerasThanKeptBackgroundsGiveTheBytesOfOneCameraEach) {
  // 20 cameras at one size take turns with one renderer, so backgrounds are evicted and redrawn;
  // every frame equals that camera's frame from a renderer that never saw another camera.
  constexpr int kCameras = 20;
  const auto camera_at = [](int c) {
    Camera camera = Camera::look_at({-1.0F + 0.1F * static_cast<float>(c), -3, 0.5F}, {0, 0, 0.5F});
    camera.width = 24;
    camera.height = 24;
    return camera;
  };
  const auto frame = [&](Renderer& renderer, int c) {
    std::vector<std::uint8_t> rgb(24 * 24 * 3);
    renderer.render(scene(0, 0), camera_at(c), {24, 24, rgb.data()});
    return rgb;
  };
  Renderer cycling;
  std::vector<std::vector<std::uint8_t>> first;
  for (int c = 0; c < kCameras; ++c) first.push_back(frame(cycling, c));
  for (int c = 0; c < kCameras; ++c) {
    EXPECT_EQ(frame(cycling, c), first[static_cast<std::size_t>(c)]) << "camera " << c;
  }
  for (const int c : {0, 7, 19}) {
    Renderer fresh;
    EXPECT_EQ(frame(fresh, c), first[static_cast<std::size_t>(c)]) << "camera " << c;
  }
}

TEST(ContextGroupTest, OnlyRenderersGivenTheGroupShareIt) {
  ContextGroup outer;
  ContextGroup inner;
  const Renderer renderer(inner);
  EXPECT_TRUE(inner.created());
  EXPECT_FALSE(outer.created());
  const Renderer alone;  // a context of its own
  EXPECT_FALSE(outer.created());
  // Nothing is ambient: a renderer made on another thread while `outer` lives has its own too.
  WorkerThread worker;
  worker.run([] { const Renderer elsewhere; });
  EXPECT_FALSE(outer.created());
  EXPECT_THROW(ContextGroup(-1), std::invalid_argument);
}

TEST(ContextGroupTest, RenderersOutliveTheirContextGroupAndMoveBetweenThreads) {
  constexpr int kFrames = 4;
  const auto expected = own_contexts(kFrames);
  std::vector<std::unique_ptr<Renderer>> renderers;
  {
    ContextGroup shared;
    renderers = make_renderers(shared);
  }
  // As AsyncVectorEnv's worker 0 envs: drawn here, then on a worker thread, never at once; then
  // destroyed on the worker.
  WorkerThread worker;
  std::vector<std::vector<Frame>> got(kRenderers);
  for (int f = 0; f < kFrames; ++f) {
    const auto turn = [&] {
      for (int r = 0; r < kRenderers; ++r)
        got[static_cast<std::size_t>(r)].push_back(
            draw(*renderers[static_cast<std::size_t>(r)], r, f));
    };
    if (f % 2 == 0) {
      turn();
    } else {
      worker.run(turn);
    }
  }
  worker.run([&] { renderers.clear(); });
  EXPECT_TRUE(got == expected);
  // The thread that destroyed them still draws with contexts of its own.
  worker.run([&] {
    Renderer renderer;
    EXPECT_TRUE(draw(renderer, 0, 0) == expected[0][0]);
  });
}

TEST(ContextGroupTest, TwoContextGroupsDrawAtOnceOnTwoThreads) {
  constexpr int kFrames = 3;
  const auto expected = own_contexts(kFrames);
  WorkerThread a;
  WorkerThread b;
  ContextGroup shared_a;
  ContextGroup shared_b;
  std::vector<std::unique_ptr<Renderer>> on_a;
  std::vector<std::unique_ptr<Renderer>> on_b;
  a.run([&] { on_a = make_renderers(shared_a); });
  b.run([&] { on_b = make_renderers(shared_b); });
  std::vector<std::vector<Frame>> got_a(kRenderers);
  std::vector<std::vector<Frame>> got_b(kRenderers);
  for (int f = 0; f < kFrames; ++f) {
    const auto turn = [f](std::vector<std::unique_ptr<Renderer>>& renderers,
                          std::vector<std::vector<Frame>>& got) {
      return [&renderers, &got, f] {
        for (int r = 0; r < kRenderers; ++r)
          got[static_cast<std::size_t>(r)].push_back(
              draw(*renderers[static_cast<std::size_t>(r)], r, f));
      };
    };
    std::future<void> done_a = a.start(turn(on_a, got_a));
    std::future<void> done_b = b.start(turn(on_b, got_b));
    done_a.get();
    done_b.get();
  }
  a.run([&] { on_a.clear(); });
  b.run([&] { on_b.clear(); });
  EXPECT_TRUE(got_a == expected);
  EXPECT_TRUE(got_b == expected);
}

}  // namespace
}  // namespace pixelgym::render
