// Private copies of Mesa (render::MesaCopy): contexts in the copy selected on their thread, the
// same bytes from every copy, threads drawing with different copies at once (threads that did
// not load the copy included), and the selection rules.
#include "pixelgym/render/mesa_copy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/render/context.h"
#include "pixelgym/render/mesh_data.h"
#include "pixelgym/render/renderer.h"
#include "tests/render/box_and_ball_scene.h"

namespace pixelgym::render {
namespace {

using ::testing::HasSubstr;

constexpr int kSize = 40;

Scene scene_at(float offset) {
  return testing::box_and_ball_scene(offset, /*box_segmentation_id=*/7,
                                     /*ball_segmentation_id=*/9);
}

struct Frame {
  std::vector<std::uint8_t> rgb = std::vector<std::uint8_t>(kSize * kSize * 3);
  std::vector<float> depth = std::vector<float>(kSize * kSize);
  std::vector<std::int32_t> segmentation = std::vector<std::int32_t>(kSize * kSize);
  bool operator==(const Frame& other) const {
    return rgb == other.rgb && depth == other.depth && segmentation == other.segmentation;
  }
};

Frame draw(Renderer& renderer, float offset) {
  Camera camera = Camera::look_at({0, -3, 0.8F}, {0, 0, 0.4F});
  camera.width = kSize;
  camera.height = kSize;
  Frame frame;
  renderer.render(scene_at(offset), camera,
                  {kSize, kSize, frame.rgb.data(), frame.depth.data(), frame.segmentation.data()});
  return frame;
}

// The frames of one renderer made in copy `copy` on this thread.
std::vector<Frame> frames_with_copy(int copy, int count) {
  Renderer renderer(GlBackend::kOSMesa, copy);
  std::vector<Frame> frames;
  for (int f = 0; f < count; ++f) frames.push_back(draw(renderer, 0.05F * static_cast<float>(f)));
  return frames;
}

// Copies are OSMesa's: a build without it (-DPIXELGYM_OSMESA=OFF) has none to test.
class MesaCopyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!gl_backend_built(GlBackend::kOSMesa)) GTEST_SKIP() << "built without OSMesa";
  }
};

TEST_F(MesaCopyTest, AContextIsOfTheCopyItIsGiven) {
  {
    const Context linked;
    EXPECT_EQ(linked.mesa_copy(), 0);
  }
  const Context first(GlBackend::kOSMesa, 1);
  EXPECT_EQ(first.mesa_copy(), 1) << MesaCopy::why_not(1);
  EXPECT_TRUE(MesaCopy::loaded(1));
  {
    const Context second(GlBackend::kOSMesa, 2);
    EXPECT_EQ(second.mesa_copy(), 2) << MesaCopy::why_not(2);
  }
  // A group's renderers draw with contexts of the group's copy.
  ContextGroup group(2);
  EXPECT_EQ(group.mesa_copy(), 2);
  EXPECT_THROW(Context(GlBackend::kOSMesa, -1), std::invalid_argument);
}

TEST_F(MesaCopyTest, EveryCopyDrawsTheSameBytes) {
  const std::vector<Frame> expected = frames_with_copy(0, 3);
  ASSERT_NE(expected[0].rgb, std::vector<std::uint8_t>(kSize * kSize * 3, 0));  // not blank
  for (const int copy : {1, 2, 3}) {
    const std::vector<Frame> got = frames_with_copy(copy, 3);
    for (std::size_t f = 0; f < got.size(); ++f) {
      EXPECT_TRUE(got[f] == expected[f]) << "copy " << copy << ", frame " << f;
    }
  }
}

// Two threads that did not load the copies they draw with (the main thread did) draw at once,
// each with its own copy, and give the bytes of one thread drawing with copy 0.
TEST_F(MesaCopyTest, ThreadsDrawWithDifferentCopiesAtOnce) {
  constexpr int kFrames = 8;
  for (const int copy : {4, 5}) EXPECT_EQ(MesaCopy::resolve(copy), copy) << MesaCopy::why_not(copy);
  const std::vector<Frame> expected = frames_with_copy(0, kFrames);
  std::vector<std::vector<Frame>> got(2);
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t) {
    threads.emplace_back(
        [t, &got] { got[static_cast<std::size_t>(t)] = frames_with_copy(4 + t, kFrames); });
  }
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < 2; ++t) {
    ASSERT_EQ(got[static_cast<std::size_t>(t)].size(), expected.size());
    for (std::size_t f = 0; f < expected.size(); ++f) {
      EXPECT_TRUE(got[static_cast<std::size_t>(t)][f] == expected[f])
          << "thread " << t << ", frame " << f;
    }
  }
}

// A renderer made on one thread in a copy and drawn and destroyed on others (as a vector env's
// worker 0 envs move between the caller and worker thread 0).
TEST_F(MesaCopyTest, ARendererOfACopyMovesBetweenThreads) {
  const std::vector<Frame> expected = frames_with_copy(0, 2);
  auto renderer = std::make_unique<Renderer>(GlBackend::kOSMesa, 6);
  Frame first;
  std::thread([&] { first = draw(*renderer, 0.0F); }).join();
  EXPECT_TRUE(first == expected[0]);
  EXPECT_TRUE(draw(*renderer, 0.05F) == expected[1]);
  std::thread([&] { renderer.reset(); }).join();
}

TEST_F(MesaCopyTest, CopyNumbersWrapAtTheLimitAndTheLimitIsChecked) {
  ASSERT_EQ(std::getenv("PIXELGYM_MESA_COPIES"), nullptr) << "the test sets it itself";
  EXPECT_EQ(MesaCopy::max_copies(), 8);
  EXPECT_EQ(MesaCopy::resolve(9), 1);
  setenv("PIXELGYM_MESA_COPIES", "3", 1);
  EXPECT_EQ(MesaCopy::max_copies(), 3);
  EXPECT_EQ(MesaCopy::resolve(4), 1);
  EXPECT_EQ(Context(GlBackend::kOSMesa, 5).mesa_copy(), 2);
  setenv("PIXELGYM_MESA_COPIES", "1", 1);  // no private copies
  EXPECT_EQ(Context(GlBackend::kOSMesa, 1).mesa_copy(), 0);
  for (const char* bad : {"0", "17", "two", "2x", "-1"}) {
    setenv("PIXELGYM_MESA_COPIES", bad, 1);
    try {
      MesaCopy::max_copies();
      ADD_FAILURE() << "no error for " << bad;
    } catch (const std::invalid_argument& error) {
      EXPECT_THAT(error.what(),
                  HasSubstr("PIXELGYM_MESA_COPIES must be a whole number from 1 to 16"));
      EXPECT_THAT(error.what(), HasSubstr(std::string("got \"") + bad + "\""));
    }
    EXPECT_THROW(Context(GlBackend::kOSMesa, 1), std::invalid_argument) << bad;
  }
  unsetenv("PIXELGYM_MESA_COPIES");
  EXPECT_THROW(MesaCopy::resolve(-1), std::invalid_argument);
  EXPECT_EQ(MesaCopy::why_not(1), "");
}

}  // namespace
}  // namespace pixelgym::render
