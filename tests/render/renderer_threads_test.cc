// Renderers used from several threads, as the vector envs use them: one renderer (one OSMesa
// context) per env, each drawn by one thread at a time but not always the same thread, and
// created or destroyed on a thread other than the one that drew last. Each test compares bytes
// with the same frames drawn on one thread.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "pixelgym/render/mesh_data.h"
#include "pixelgym/render/renderer.h"
#include "tests/render/box_and_ball_scene.h"
#include "tests/worker_thread.h"

namespace pixelgym::render {
namespace {

using Image = std::vector<std::uint8_t>;
using pixelgym::testing::WorkerThread;

constexpr int kSize = 32;

Scene scene_at(float offset) { return testing::box_and_ball_scene(offset); }

Camera camera() {
  Camera camera = Camera::look_at({0, -3, 0.5F}, {0, 0, 0.5F});
  camera.width = kSize;
  camera.height = kSize;
  return camera;
}

Image draw(Renderer& renderer, float offset) {
  Image rgb(kSize * kSize * 3);
  renderer.render(scene_at(offset), camera(), {kSize, kSize, rgb.data()});
  return rgb;
}

// Frame i of a renderer's sequence; renderer r draws offsets different from the others'.
float offset(int renderer, int frame) {
  return 0.1F * static_cast<float>(renderer) + 0.02F * static_cast<float>(frame);
}

// The frames of renderers 0..count-1, each drawn `frames` times on this thread.
std::vector<std::vector<Image>> on_one_thread(int count, int frames) {
  std::vector<std::vector<Image>> images(static_cast<std::size_t>(count));
  for (int r = 0; r < count; ++r) {
    Renderer renderer;
    for (int f = 0; f < frames; ++f)
      images[static_cast<std::size_t>(r)].push_back(draw(renderer, offset(r, f)));
  }
  return images;
}

TEST(RendererThreadsTest, RenderersOnTheirOwnThreadsGiveTheBytesOfOneThread) {
  constexpr int kRenderers = 4;
  constexpr int kFrames = 6;
  const auto expected = on_one_thread(kRenderers, kFrames);
  std::vector<std::vector<Image>> got(kRenderers);
  std::vector<std::thread> threads;
  for (int r = 0; r < kRenderers; ++r) {
    threads.emplace_back([r, &got] {
      Renderer renderer;  // made on the thread that draws with it
      for (int f = 0; f < kFrames; ++f)
        got[static_cast<std::size_t>(r)].push_back(draw(renderer, offset(r, f)));
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(got, expected);
}

TEST(RendererThreadsTest, ARendererMovedBetweenThreadsGivesTheBytesOfOneThread) {
  constexpr int kFrames = 9;
  const auto expected = on_one_thread(2, kFrames);
  // Two renderers made here, drawn by two long-lived threads that swap them every 3 frames, so
  // each thread draws with one context, then the other, while the other thread draws with the
  // first; the last frames are drawn here again.
  Renderer first;
  Renderer second;
  std::vector<std::vector<Image>> got(2);
  WorkerThread a;
  WorkerThread b;
  for (int f = 0; f < kFrames; ++f) {
    if (f >= 6) {
      got[0].push_back(draw(first, offset(0, f)));
      got[1].push_back(draw(second, offset(1, f)));
      continue;
    }
    const bool swapped = (f / 3) % 2 == 1;
    Renderer& on_a = swapped ? second : first;
    Renderer& on_b = swapped ? first : second;
    const int r_a = swapped ? 1 : 0;
    std::future<void> done_a = a.start(
        [&, f, r_a] { got[static_cast<std::size_t>(r_a)].push_back(draw(on_a, offset(r_a, f))); });
    std::future<void> done_b = b.start([&, f, r_a] {
      got[static_cast<std::size_t>(1 - r_a)].push_back(draw(on_b, offset(1 - r_a, f)));
    });
    done_a.get();
    done_b.get();
  }
  EXPECT_EQ(got, expected);
}

TEST(RendererThreadsTest, ARendererDestroyedElsewhereLeavesTheThreadThatDrewWithItUsable) {
  const auto expected = on_one_thread(2, 3);
  WorkerThread worker;
  std::vector<std::vector<Image>> got(2);
  for (int round = 0; round < 3; ++round) {
    for (int r = 0; r < 2; ++r) {
      // Made here, drawn by the worker, destroyed here: the worker outlives the context it drew
      // with last, then draws with a new one.
      auto renderer = std::make_unique<Renderer>();
      std::vector<Image> frames;
      worker.run([&] {
        for (int f = 0; f < 3; ++f) frames.push_back(draw(*renderer, offset(r, f)));
      });
      renderer.reset();
      // Reuse the freed memory, as the rest of a program would.
      std::vector<std::unique_ptr<std::vector<char>>> churn;
      for (int i = 0; i < 64; ++i) churn.push_back(std::make_unique<std::vector<char>>(4096, 'x'));
      if (round == 0)
        got[static_cast<std::size_t>(r)] = frames;
      else
        EXPECT_EQ(frames, expected[static_cast<std::size_t>(r)])
            << "round " << round << ", renderer " << r;
    }
  }
  EXPECT_EQ(got, expected);
}

}  // namespace
}  // namespace pixelgym::render
