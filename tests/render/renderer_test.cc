#include "pixelgym/render/renderer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <thread>

namespace pixelgym::render {
namespace {

using ::testing::HasSubstr;

constexpr int kSize = 64;

struct Pixel {
  int r, g, b;
};

Pixel at(const std::vector<std::uint8_t>& rgb, int width, int row, int col) {
  const std::size_t i = (static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                         static_cast<std::size_t>(col)) *
                        3;
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

void expect_pixel(const Pixel& actual, int r, int g, int b, const std::string& where) {
  EXPECT_NEAR(actual.r, r, 1) << where;
  EXPECT_NEAR(actual.g, g, 1) << where;
  EXPECT_NEAR(actual.b, b, 1) << where;
}

// Lighting that shows base colours as they are: full ambient, no direct light, no highlights.
Scene flat_scene() {
  Scene scene;
  scene.light.color.setZero();
  scene.light.ambient.setOnes();
  scene.shadows = false;
  scene.floor.enabled = false;
  scene.sky.horizon = scene.sky.zenith = Eigen::Vector3f(0.2F, 0.4F, 0.6F);
  return scene;
}

Instance box(const Eigen::Vector3f& centre, const Eigen::Vector3f& size,
             const Eigen::Vector4f& color, int id = 0) {
  Instance instance;
  instance.mesh = make_box_mesh();
  instance.scale = size;
  instance.X_world_instance.translation() = centre;
  instance.material.base_color = color;
  instance.material.specular = 0.0F;
  instance.segmentation_id = id;
  return instance;
}

Camera front_camera(int size = kSize) {
  Camera camera = Camera::look_at({0, -3, 0.5F}, {0, 0, 0.5F});
  camera.width = size;
  camera.height = size;
  return camera;
}

TEST(RendererTest, KnownColourBoxAtTheCentreAndBackgroundAtTheCorners) {
  Renderer renderer;
  Scene scene = flat_scene();
  scene.instances.push_back(box({0, 0, 0.5F}, {0.5F, 0.5F, 0.5F}, {0.8F, 0.25F, 0.5F, 1.0F}));
  std::vector<std::uint8_t> rgb(kSize * kSize * 3);
  renderer.render(scene, front_camera(), {kSize, kSize, rgb.data()});
  expect_pixel(at(rgb, kSize, kSize / 2, kSize / 2), 204, 64, 128, "centre");
  for (const auto& [row, col] : std::vector<std::pair<int, int>>{
           {0, 0}, {0, kSize - 1}, {kSize - 1, 0}, {kSize - 1, kSize - 1}}) {
    expect_pixel(at(rgb, kSize, row, col), 51, 102, 153, "corner");
  }
}

TEST(RendererTest, RowZeroIsTheTopOfTheImage) {
  Renderer renderer;
  Scene scene = flat_scene();
  scene.instances.push_back(box({0, 0, 1.2F}, {0.4F, 0.4F, 0.4F}, {1, 0, 0, 1}));   // high: red
  scene.instances.push_back(box({0, 0, -0.2F}, {0.4F, 0.4F, 0.4F}, {0, 1, 0, 1}));  // low: green
  std::vector<std::uint8_t> rgb(kSize * kSize * 3);
  renderer.render(scene, front_camera(), {kSize, kSize, rgb.data()});
  bool red_above_green = false;
  for (int row = 0; row < kSize / 2; ++row) {
    if (at(rgb, kSize, row, kSize / 2).r > 200) red_above_green = true;
  }
  EXPECT_TRUE(red_above_green) << "the high box is not in the top half";
  expect_pixel(at(rgb, kSize, kSize * 3 / 4, kSize / 2), 0, 255, 0, "low box in the bottom half");
}

TEST(RendererTest, DepthOfAPlaneAtAKnownDistanceWithinOneMillimetre) {
  Renderer renderer;
  Scene scene = flat_scene();
  // A wall whose front face is 2 m in front of the camera, square to its view.
  scene.instances.push_back(box({0, 4.0F, 0.5F}, {20, 10, 20}, {1, 1, 1, 1}));  // face at y = -1
  std::vector<float> depth(kSize * kSize);
  Camera camera = front_camera();
  renderer.render(scene, camera, {kSize, kSize, nullptr, depth.data()});
  for (int p = 0; p < kSize * kSize; ++p)
    ASSERT_NEAR(depth[static_cast<std::size_t>(p)], 2.0F, 1e-3F) << p;
  // Where nothing is drawn, depth is the far plane.
  Scene empty = flat_scene();
  renderer.render(empty, camera, {kSize, kSize, nullptr, depth.data()});
  EXPECT_EQ(depth[0], camera.far_m);
}

// The floor is drawn pushed back in depth (so that what rests on it wins the depth test), which
// must not show in the depth image: each floor pixel's depth is the plane's along the pixel's
// centre ray, worked out here from the camera alone, at grazing angles too.
TEST(RendererTest, FloorDepthIsThePlanesOwnEvenAtGrazingAngles) {
  Renderer renderer;
  Scene scene = flat_scene();
  scene.floor.enabled = true;
  scene.floor.height_m = 0.1F;
  // A box resting on the floor, in the middle of the view.
  scene.instances.push_back(box({0, 0, 0.35F}, {0.5F, 0.5F, 0.5F}, {1, 0, 0, 1}, 5));
  for (const Eigen::Vector3f& eye : {Eigen::Vector3f(0, -6, 0.45F), Eigen::Vector3f(2, -3, 2.5F)}) {
    Camera camera = Camera::look_at(eye, {0, 0, 0.3F});
    camera.width = kSize;
    camera.height = kSize;
    std::vector<float> depth(kSize * kSize);
    std::vector<std::int32_t> ids(kSize * kSize);
    renderer.render(scene, camera, {kSize, kSize, nullptr, depth.data(), ids.data()});
    const float tan_half = std::tan(camera.fov_y_deg * 3.14159265F / 360.0F);
    int floor_pixels = 0;
    for (int row = 0; row < kSize; ++row) {
      for (int col = 0; col < kSize; ++col) {
        // The ray through the pixel's centre in the camera's frame (it looks along -z, y up,
        // rows top first), scaled to eye depth 1, then in the world.
        const Eigen::Vector3f ray((2.0F * col + 1.0F - kSize) / kSize * tan_half,
                                  (kSize - 2.0F * row - 1.0F) / kSize * tan_half, -1.0F);
        const Eigen::Vector3f world = camera.X_world_camera.linear() * ray;
        const auto p = static_cast<std::size_t>(row * kSize + col);
        if (ids[p] != -1) continue;  // the box or the sky
        ASSERT_LT(world.z(), 0.0F);
        const float plane = (scene.floor.height_m - eye.z()) / world.z();
        const float seen = depth[p];
        ++floor_pixels;
        ASSERT_NEAR(seen, plane, 1e-3F + 1e-4F * plane)
            << "row " << row << ", column " << col << ", camera at " << eye.transpose();
      }
    }
    EXPECT_GT(floor_pixels, kSize * kSize / 4) << eye.transpose();
    // The box is still in front: its middle is drawn, nearer than its centre.
    const auto middle = static_cast<std::size_t>(kSize / 2 * kSize + kSize / 2);
    EXPECT_EQ(ids[middle], 5) << eye.transpose();
    EXPECT_LT(depth[middle], (eye - Eigen::Vector3f(0, 0, 0.35F)).norm()) << eye.transpose();
  }
}

TEST(RendererTest, SegmentationIdsAreExact) {
  Renderer renderer;
  Scene scene = flat_scene();
  scene.floor.enabled = true;
  scene.instances.push_back(box({-0.5F, 0, 0.5F}, {0.4F, 0.4F, 0.4F}, {1, 0, 0, 1}, 5));
  scene.instances.push_back(box({0.5F, 0, 0.5F}, {0.4F, 0.4F, 0.4F}, {0, 0, 1, 1}, 9));
  std::vector<std::int32_t> ids(kSize * kSize);
  std::vector<std::uint8_t> rgb(kSize * kSize * 3);
  renderer.render(scene, front_camera(), {kSize, kSize, rgb.data(), nullptr, ids.data()});
  const auto id_at = [&](int row, int col) {
    return ids[static_cast<std::size_t>(row * kSize + col)];
  };
  EXPECT_EQ(id_at(kSize / 2, kSize / 2 - 11), 5);
  EXPECT_EQ(id_at(kSize / 2, kSize / 2 + 11), 9);
  EXPECT_EQ(id_at(0, 0), 0);           // sky
  EXPECT_EQ(id_at(kSize - 1, 0), -1);  // floor
  for (std::int32_t id : ids) ASSERT_TRUE(id == 0 || id == -1 || id == 5 || id == 9) << id;
  // Every red pixel is id 5, every blue one id 9.
  for (int p = 0; p < kSize * kSize; ++p) {
    const Pixel px{rgb[static_cast<std::size_t>(p) * 3], rgb[static_cast<std::size_t>(p) * 3 + 1],
                   rgb[static_cast<std::size_t>(p) * 3 + 2]};
    if (px.r > 250 && px.g < 5 && px.b < 5) {
      ASSERT_EQ(ids[static_cast<std::size_t>(p)], 5);
    }
    if (px.b > 250 && px.r < 5 && px.g < 5) {
      ASSERT_EQ(ids[static_cast<std::size_t>(p)], 9);
    }
  }
}

TEST(RendererTest, ShadowsDarkenTheFloorUnderAnObject) {
  Renderer renderer;
  Scene scene;
  scene.light.direction = {0, 0, -1};  // straight down
  scene.instances.push_back(box({0, 0, 0.6F}, {0.5F, 0.5F, 0.1F}, {0.8F, 0.8F, 0.8F, 1}));
  Camera camera = Camera::look_at({0.01F, -2.5F, 2.5F}, {0, 0, 0});
  camera.width = camera.height = kSize;
  std::vector<std::uint8_t> with(kSize * kSize * 3);
  std::vector<std::uint8_t> without(kSize * kSize * 3);
  renderer.render(scene, camera, {kSize, kSize, with.data()});
  scene.shadows = false;
  renderer.render(scene, camera, {kSize, kSize, without.data()});
  // The floor at the origin is below the slab; it is hidden from the camera by nothing but the
  // slab's shadow. Find a floor pixel that changed and one that did not.
  int darker = 0;
  int unchanged = 0;
  for (std::size_t i = 0; i < with.size(); i += 3) {
    const int delta = int{without[i]} - int{with[i]};
    if (delta > 20) ++darker;
    if (delta == 0) ++unchanged;
  }
  EXPECT_GT(darker, 50) << "no shadow on the floor";
  EXPECT_GT(unchanged, kSize * kSize / 2) << "shadows darkened more than the shadow";
}

// Faces turned away are culled only for closed meshes: an open one (a single sheet, here facing
// away from both the camera and the light) is still drawn and still casts its shadow.
TEST(RendererTest, OpenMeshesAreDrawnAndShadowedFromBehind) {
  auto sheet = std::make_shared<MeshData>();
  sheet->positions = {{-0.3F, -0.3F, 0}, {0.3F, -0.3F, 0}, {0.3F, 0.3F, 0}, {-0.3F, 0.3F, 0}};
  sheet->normals.assign(4, Eigen::Vector3f(0, 0, -1));
  sheet->indices = {0, 2, 1, 0, 3, 2};  // clockwise seen from above: it faces down
  ASSERT_FALSE(is_closed_surface(*sheet));
  Renderer renderer;
  Scene scene;
  scene.light.direction = {0, 0, -1};  // straight down, onto the sheet's back
  Instance instance;
  instance.mesh = sheet;
  instance.X_world_instance.translation() = Eigen::Vector3f(0, 0, 0.6F);
  instance.material.base_color = {0.9F, 0.1F, 0.1F, 1};
  scene.instances.push_back(instance);
  Camera camera = Camera::look_at({0.01F, -0.5F, 3.0F}, {0, 0, 0});
  camera.width = camera.height = kSize;
  std::vector<std::uint8_t> with(kSize * kSize * 3);
  std::vector<std::uint8_t> without(kSize * kSize * 3);
  renderer.render(scene, camera, {kSize, kSize, with.data()});
  const Pixel centre = at(with, kSize, kSize / 2, kSize / 2);
  EXPECT_GT(centre.r, 2 * centre.g) << "the sheet is not drawn from behind";
  scene.shadows = false;
  renderer.render(scene, camera, {kSize, kSize, without.data()});
  int darker = 0;
  for (std::size_t i = 0; i < with.size(); i += 3) {
    if (int{without[i]} - int{with[i]} > 20) ++darker;
  }
  EXPECT_GT(darker, 20) << "the sheet casts no shadow from behind";
}

// A closed mesh mirrored by a negative scale is wound inside out; it must not be culled as if it
// were not. A mirrored box is the same box.
TEST(RendererTest, MirroredClosedMeshesLookTheSame) {
  Renderer renderer;
  Scene scene;
  scene.instances.push_back(box({0, 0, 0.5F}, {0.6F, 0.4F, 0.5F}, {0.2F, 0.7F, 0.3F, 1}));
  std::vector<std::uint8_t> plain(kSize * kSize * 3);
  std::vector<std::uint8_t> mirrored(kSize * kSize * 3);
  const Camera camera = Camera::look_at({1.5F, -2.5F, 1.8F}, {0, 0, 0.4F});
  Camera sized = camera;
  sized.width = sized.height = kSize;
  renderer.render(scene, sized, {kSize, kSize, plain.data()});
  scene.instances[0].scale.x() = -scene.instances[0].scale.x();
  renderer.render(scene, sized, {kSize, kSize, mirrored.data()});
  int differing = 0;
  for (std::size_t i = 0; i < plain.size(); ++i) {
    if (std::abs(int{plain[i]} - int{mirrored[i]}) > 8) ++differing;
  }
  EXPECT_LT(differing, 10);
}

TEST(RendererTest, TexturesModulateTheBaseColour) {
  Renderer renderer;
  Scene scene = flat_scene();
  Instance textured = box({0, 0, 0.5F}, {1.5F, 0.1F, 1.5F}, {1, 1, 1, 1});
  textured.material.texture_path =
      std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/checker.png";
  scene.instances.push_back(textured);
  std::vector<std::uint8_t> rgb(kSize * kSize * 3);
  renderer.render(scene, front_camera(), {kSize, kSize, rgb.data()});
  // The 8x8 texture's two grays (60 and 200) both appear on the face (texel centres are exact;
  // linear filtering blends between them).
  bool dark = false;
  bool light = false;
  for (std::size_t i = 0; i < rgb.size(); i += 3) {
    dark = dark || std::abs(int{rgb[i]} - 60) <= 1;
    light = light || std::abs(int{rgb[i]} - 200) <= 1;
  }
  EXPECT_TRUE(dark && light);
  scene.instances[0].material.texture_path = "/nonexistent/texture.png";
  try {
    renderer.render(scene, front_camera(), {kSize, kSize, rgb.data()});
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("/nonexistent/texture.png"));
  }
}

Scene busy_scene(float offset) {
  Scene scene;
  scene.instances.push_back(box({offset, 0, 0.3F}, {0.4F, 0.4F, 0.6F}, {0.8F, 0.3F, 0.2F, 1}, 1));
  Instance ball;
  ball.mesh = make_sphere_mesh();
  ball.scale = Eigen::Vector3f::Constant(0.25F);
  ball.X_world_instance.translation() = Eigen::Vector3f(0.6F - offset, 0.4F, 0.25F);
  ball.material.base_color = {0.2F, 0.5F, 0.9F, 1};
  scene.instances.push_back(ball);
  return scene;
}

TEST(RendererTest, SameSceneTwiceGivesIdenticalBytes) {
  Renderer renderer;
  const Scene scene = busy_scene(0.0F);
  Camera camera = front_camera(96);
  std::vector<std::uint8_t> a(96 * 96 * 3);
  std::vector<std::uint8_t> b(96 * 96 * 3);
  renderer.render(scene, camera, {96, 96, a.data()});
  renderer.render(busy_scene(0.3F), camera, {96, 96, b.data()});  // something else in between
  renderer.render(scene, camera, {96, 96, b.data()});
  EXPECT_EQ(a, b);
  Renderer other;  // a fresh renderer's first frame matches too
  other.render(scene, camera, {96, 96, b.data()});
  EXPECT_EQ(a, b);
}

TEST(RendererTest, TwoThreadsGiveTheBytesOfOneThread) {
  const Scene first = busy_scene(0.0F);
  const Scene second = busy_scene(0.4F);
  Camera camera = front_camera(84);
  const std::size_t bytes = 84 * 84 * 3;
  std::vector<std::uint8_t> seq_first(bytes), seq_second(bytes), par_first(bytes),
      par_second(bytes);
  {
    Renderer renderer;
    renderer.render(first, camera, {84, 84, seq_first.data()});
    renderer.render(second, camera, {84, 84, seq_second.data()});
  }
  const auto draw = [&camera](const Scene& scene, std::vector<std::uint8_t>& out) {
    Renderer renderer;
    for (int i = 0; i < 20; ++i) renderer.render(scene, camera, {84, 84, out.data()});
  };
  std::thread a(draw, std::cref(first), std::ref(par_first));
  std::thread b(draw, std::cref(second), std::ref(par_second));
  a.join();
  b.join();
  EXPECT_EQ(par_first, seq_first);
  EXPECT_EQ(par_second, seq_second);
  EXPECT_NE(seq_first, seq_second);
}

TEST(RendererTest, MultisamplingSmoothsEdgesOnly) {
  Renderer renderer;
  Scene scene = flat_scene();
  Instance ball;
  ball.mesh = make_sphere_mesh();
  ball.scale = Eigen::Vector3f::Constant(0.4F);
  ball.X_world_instance.translation() = Eigen::Vector3f(0, 0, 0.5F);
  ball.material.base_color = {0.8F, 0.25F, 0.5F, 1.0F};
  ball.material.specular = 0.0F;
  scene.instances.push_back(ball);
  Camera camera = front_camera();
  std::vector<std::uint8_t> plain(kSize * kSize * 3);
  std::vector<std::uint8_t> smooth(kSize * kSize * 3);
  renderer.render(scene, camera, {kSize, kSize, plain.data()});
  camera.msaa_samples = 4;
  renderer.render(scene, camera, {kSize, kSize, smooth.data()});
  expect_pixel(at(smooth, kSize, kSize / 2, kSize / 2), 204, 64, 128, "centre with MSAA");
  // Without MSAA every pixel is the ball's or the sky's colour; with it the rim blends the two.
  const auto blended = [](const std::vector<std::uint8_t>& rgb) {
    int count = 0;
    for (std::size_t i = 0; i < rgb.size(); i += 3) {
      if (std::abs(int{rgb[i]} - 204) > 1 && std::abs(int{rgb[i]} - 51) > 1) ++count;
    }
    return count;
  };
  EXPECT_EQ(blended(plain), 0);
  EXPECT_GT(blended(smooth), 20);
  // Every sample count the GL offers is drawn (and smooths the rim); every larger one is refused
  // naming the GL's limit. (llvmpipe offers 4: 2 and 4 draw, 8 is refused.)
  // The renderer binds its context only while it draws; a context of our own asks the same GL.
  const int max_samples = Context().max_samples();
  ASSERT_GE(max_samples, 2);
  for (int samples : {2, 4, 8}) {
    camera.msaa_samples = samples;
    if (samples <= max_samples) {
      std::fill(smooth.begin(), smooth.end(), std::uint8_t{0});
      renderer.render(scene, camera, {kSize, kSize, smooth.data()});
      EXPECT_GT(blended(smooth), 20) << samples << " samples";
    } else {
      try {
        renderer.render(scene, camera, {kSize, kSize, smooth.data()});
        FAIL() << samples << " samples drawn, but the GL offers at most " << max_samples;
      } catch (const std::invalid_argument& error) {
        EXPECT_THAT(error.what(), HasSubstr("at most " + std::to_string(max_samples)));
      }
    }
  }
}

TEST(RendererTest, BadInputIsRejected) {
  Renderer renderer;
  Scene scene = flat_scene();
  std::vector<std::uint8_t> rgb(kSize * kSize * 3);
  Camera camera = front_camera();
  camera.width = 0;
  EXPECT_THROW(renderer.render(scene, camera, {kSize, kSize, rgb.data()}), std::invalid_argument);
  camera = front_camera();
  camera.far_m = camera.near_m;
  EXPECT_THROW(renderer.render(scene, camera, {kSize, kSize, rgb.data()}), std::invalid_argument);
  scene.instances.push_back(Instance{});
  try {
    renderer.render(scene, front_camera(), {kSize, kSize, rgb.data()});
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("instance 0 has no mesh"));
  }
}

// The targets' size must be the camera's, on either axis: a buffer sized for another image would
// be overrun or left partly unwritten.
TEST(RendererTest, TargetsOfAnotherSizeAreRejected) {
  Renderer renderer;
  const Scene scene = flat_scene();
  std::vector<std::uint8_t> rgb(kSize * kSize * 3);
  const Camera camera = front_camera();
  for (const auto& [width, height] : std::vector<std::pair<int, int>>{
           {kSize - 1, kSize}, {kSize, kSize - 1}, {kSize, kSize / 2}, {0, 0}}) {
    try {
      renderer.render(scene, camera, {width, height, rgb.data()});
      FAIL() << "no error for targets of " << width << "x" << height;
    } catch (const std::invalid_argument& error) {
      EXPECT_THAT(error.what(), HasSubstr(std::to_string(width) + "x" + std::to_string(height)));
      EXPECT_THAT(error.what(), HasSubstr("64x64"));
    }
  }
  EXPECT_NO_THROW(renderer.render(scene, camera, {kSize, kSize, rgb.data()}));
}

TEST(RendererTest, DescribesItsBackend) {
  Renderer renderer;
  EXPECT_THAT(renderer.description(), HasSubstr("Core Profile"));
}

}  // namespace
}  // namespace pixelgym::render
