// Visual variation, cameras and the distracting variants: each factor changes the frames with the
// seed and nothing else (states, rewards and flags as without it; segmentation and depth as
// without it), the same seed gives the same bytes on 1 and 2 threads, and bad settings are errors
// that name them.
#include "pixelgym/envs/tasks/visual_variation.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/render/image_io.h"
#include "pixelgym/render/renderer.h"

namespace pixelgym {
namespace {

constexpr const char* kTask = "CartPoleSwingup-v1";

PixelEnv& pixel_env(Env& env) { return dynamic_cast<PixelEnv&>(env.unwrapped()); }

Params small(Params kwargs = {}) {
  kwargs.emplace("width", 48);
  kwargs.emplace("height", 48);
  return kwargs;
}

// The same actions for every env: seeded uniform forces.
std::vector<Value> actions(int count) {
  Rng rng(7);
  std::vector<Value> out;
  for (int i = 0; i < count; ++i) {
    Array action(DType::kFloat32, {1});
    action.data<float>()[0] = static_cast<float>(rng.uniform(-1.0, 1.0));
    out.emplace_back(std::move(action));
  }
  return out;
}

const Array& pixels(const Value& obs) { return obs.dict().at("pixels").array(); }

bool same_state(const Value& a, const Value& b) {
  return a.dict().at("joint_pos").array().equals(b.dict().at("joint_pos").array()) &&
         a.dict().at("joint_vel").array().equals(b.dict().at("joint_vel").array());
}

// One factor at 0.5 and the rest at 0, or a texture source: the kwargs that turn it on.
struct Factor {
  std::string name;
  Params kwargs;
};

void PrintTo(const Factor& factor, std::ostream* out) { *out << factor.name; }

class VariationFactorTest : public ::testing::TestWithParam<Factor> {};

TEST_P(VariationFactorTest, FramesChangeWithTheSeedWhileStatesRewardsAndFlagsDoNot) {
  const std::unique_ptr<Env> plain = make(kTask, small());
  const std::unique_ptr<Env> varied = make(kTask, small(GetParam().kwargs));
  const std::vector<Value> steps = actions(15);
  std::set<std::vector<std::uint8_t>> differences;  // varied minus plain, first frame, per seed
  for (const std::uint64_t seed : {1, 2, 3}) {
    const ResetResult a = plain->reset(seed);
    const ResetResult b = varied->reset(seed);
    ASSERT_TRUE(same_state(a.obs, b.obs)) << "seed " << seed;
    EXPECT_FALSE(pixels(a.obs).equals(pixels(b.obs))) << "seed " << seed << ": nothing varied";
    std::vector<std::uint8_t> difference(pixels(a.obs).data<std::uint8_t>(),
                                         pixels(a.obs).data<std::uint8_t>() + 48 * 48 * 3);
    for (std::size_t i = 0; i < difference.size(); ++i) {
      difference[i] =
          static_cast<std::uint8_t>(difference[i] - pixels(b.obs).data<std::uint8_t>()[i]);
    }
    differences.insert(difference);
    for (const Value& action : steps) {
      const StepResult x = plain->step(action);
      const StepResult y = varied->step(action);
      ASSERT_TRUE(same_state(x.obs, y.obs)) << "seed " << seed;
      ASSERT_EQ(x.reward, y.reward) << "seed " << seed;
      ASSERT_EQ(x.terminated, y.terminated);
      ASSERT_EQ(x.truncated, y.truncated);
    }
  }
  EXPECT_EQ(differences.size(), 3U) << "the variation is not drawn from the seed";
}

TEST_P(VariationFactorTest, TheSameSeedGivesTheSameBytesOnOneAndTwoThreads) {
  std::vector<std::vector<Array>> runs;
  for (const int threads : {1, 2}) {
    vector::VectorOptions options;
    options.mode = vector::VectorMode::kAsync;
    options.num_threads = threads;
    const std::unique_ptr<vector::VectorEnv> env =
        vector::make_vec(kTask, 2, small(GetParam().kwargs), nullptr, options);
    std::vector<Array> frames{pixels(env->reset(4).obs).clone()};
    for (int i = 0; i < 3; ++i)
      frames.push_back(pixels(env->step(env->action_space().zeros()).obs).clone());
    runs.push_back(std::move(frames));
  }
  for (std::size_t i = 0; i < runs[0].size(); ++i) {
    EXPECT_TRUE(runs[0][i].equals(runs[1][i])) << "frame " << i;
  }
  // A new env with the same seed draws the same variation.
  const std::unique_ptr<Env> one = make(kTask, small(GetParam().kwargs));
  const std::unique_ptr<Env> two = make(kTask, small(GetParam().kwargs));
  EXPECT_TRUE(pixels(one->reset(9).obs).equals(pixels(two->reset(9).obs)));
}

TEST_P(VariationFactorTest, SegmentationAndDepthAreAsWithoutIt) {
  const std::unique_ptr<Env> plain = make(kTask, small());
  const std::unique_ptr<Env> varied = make(kTask, small(GetParam().kwargs));
  render::Renderer renderer;
  for (const std::uint64_t seed : {1, 2}) {
    plain->reset(seed);
    varied->reset(seed);
    PixelEnv& a = pixel_env(*plain);
    PixelEnv& b = pixel_env(*varied);
    render::Camera camera = a.task().camera("fixed", a.world());
    camera.width = 48;
    camera.height = 48;
    std::vector<std::int32_t> ids_a(48 * 48), ids_b(48 * 48);
    std::vector<float> depth_a(48 * 48), depth_b(48 * 48);
    render::RenderTargets targets{48, 48, nullptr, depth_a.data(), ids_a.data()};
    renderer.render(a.scene().scene(), camera, targets);
    targets.depth = depth_b.data();
    targets.segmentation = ids_b.data();
    renderer.render(b.scene().scene(), camera, targets);
    EXPECT_EQ(ids_a, ids_b) << "seed " << seed;
    // Depth too, the floor's included wherever the light moves its shadows (the floor under
    // them is drawn again, with another polygon offset, which the depth image does not show).
    for (std::size_t i = 0; i < depth_a.size(); ++i) {
      ASSERT_EQ(depth_a[i], depth_b[i]) << "seed " << seed << " pixel " << i;
    }
    EXPECT_NE(std::set<std::int32_t>(ids_b.begin(), ids_b.end()).size(), 1U);
  }
}

INSTANTIATE_TEST_SUITE_P(EachFactor, VariationFactorTest,
                         ::testing::Values(Factor{"colors", {{"vary_colors", 0.5}}},
                                           Factor{"textures", {{"vary_textures", 0.5}}},
                                           Factor{"light", {{"vary_light", 0.5}}},
                                           Factor{"camera", {{"vary_camera", 0.5}}},
                                           Factor{"fov", {{"vary_fov", 0.5}}},
                                           Factor{"noise_sky", {{"sky_texture", "noise"}}},
                                           Factor{"noise_floor", {{"floor_texture", "noise"}}},
                                           Factor{"all", {{"variation", 0.3}}}),
                         [](const ::testing::TestParamInfo<Factor>& factor) {
                           return factor.param.name;
                         });

// A factor left at -1 follows `variation`; one set explicitly keeps its own level.
TEST(VariationConfigTest, EachFactorFollowsTheLevelUnlessSetItself) {
  const std::unique_ptr<Env> env = make(kTask, small({{"variation", 0.3}, {"vary_camera", 0.0}}));
  const VariationConfig& config = pixel_env(*env).config().variation;
  EXPECT_EQ(config.colors, 0.3);
  EXPECT_EQ(config.textures, 0.3);
  EXPECT_EQ(config.light, 0.3);
  EXPECT_EQ(config.fov, 0.3);
  EXPECT_EQ(config.camera, 0.0);
  env->reset(1);
  const VariationSample& sample = pixel_env(*env).variation();
  EXPECT_EQ(sample.camera_azimuth, 0.0F);
  EXPECT_EQ(sample.camera_zoom, 1.0F);
  for (const Eigen::Vector3f& offset : sample.color_offsets) {
    EXPECT_LE(offset.cwiseAbs().maxCoeff(), 0.3F);
  }
}

namespace fs = std::filesystem;

// A new empty folder under the system's temporary one.
fs::path fresh_folder(const std::string& name) {
  const fs::path folder = fs::temp_directory_path() / ("pixelgym_variation_" + name);
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

// A `side` x `side` PNG of one colour at `path`.
void write_solid_png(const fs::path& path, int side, std::uint8_t r, std::uint8_t g,
                     std::uint8_t b) {
  render::Image image;
  image.width = side;
  image.height = side;
  for (int p = 0; p < side * side; ++p) image.pixels.insert(image.pixels.end(), {r, g, b});
  render::write_png(path.string(), image.view());
}

bool ends_with(const std::string& text, const std::string& tail) {
  return text.size() >= tail.size() &&
         text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

std::string error_of(const std::string& id, const Params& kwargs) {
  try {
    make(id, kwargs)->reset(0);
  } catch (const std::exception& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(VariationErrorsTest, BadSettingsAreErrorsThatNameThem) {
  const fs::path folder = fresh_folder("errors");
  fs::create_directories(folder / "empty");
  std::ofstream(folder / "notes.txt") << "not an image";

  // Levels are printed as given ("got 1.5", not "got 1.500000").
  EXPECT_TRUE(
      ends_with(error_of(kTask, {{"variation", 1.5}}), ": variation must be in [0, 1], got 1.5"))
      << error_of(kTask, {{"variation", 1.5}});
  EXPECT_TRUE(ends_with(error_of(kTask, {{"camera_fov", 172.5}}), "got 172.5"))
      << error_of(kTask, {{"camera_fov", 172.5}});
  EXPECT_NE(error_of(kTask, {{"vary_camera", -0.5}}).find("vary_camera must be in [0, 1]"),
            std::string::npos);
  EXPECT_NE(error_of(kTask, {{"floor_opacity", 2.0}}).find("floor_opacity must be in [0, 1]"),
            std::string::npos);
  const std::string missing = (folder / "missing").string();
  EXPECT_NE(error_of(kTask, {{"sky_texture", missing}}).find("sky_texture: no folder \"" + missing),
            std::string::npos);
  const std::string file = (folder / "notes.txt").string();
  EXPECT_NE(error_of(kTask, {{"floor_texture", file}}).find("\"" + file + "\" is not a folder"),
            std::string::npos);
  EXPECT_NE(error_of(kTask, {{"sky_texture", (folder / "empty").string()}})
                .find("holds no .png, .jpg or .jpeg image"),
            std::string::npos);
  EXPECT_NE(error_of(kTask, {{"camera", "nowhere"}}).find("unknown camera \"nowhere\""),
            std::string::npos);
  EXPECT_NE(error_of(kTask, {{"cameras", "fixed,nowhere"}})
                .find("unknown camera \"nowhere\" in cameras; cameras: \"fixed\""),
            std::string::npos);
  EXPECT_NE(error_of(kTask, {{"cameras", "fixed,fixed"}}).find("listed twice"), std::string::npos);
  EXPECT_NE(error_of(kTask, {{"cameras", "fixed"}, {"obs_mode", "rgb"}}).find("obs_mode \"rgb\""),
            std::string::npos);
  EXPECT_NE(error_of(kTask, {{"camera_pos", "1,2"}, {"camera_lookat", "0,0,1"}})
                .find("camera_pos must be three numbers \"x,y,z\""),
            std::string::npos);
  EXPECT_NE(error_of(kTask, {{"camera_pos", "1,2,3"}}).find("go together, got only camera_pos"),
            std::string::npos);
  EXPECT_NE(error_of("CartPoleSwingup-distracting-v1", {{"variation", 7}})
                .find("CartPoleSwingup-distracting-v1: variation must be in [0, 1], got 7"),
            std::string::npos);
  EXPECT_TRUE(ends_with(error_of(kTask, {{"vary_camera", 0.25}, {"vary_fov", 1.75}}),
                        "vary_fov must be in [0, 1] (or -1 to follow variation), got 1.75"))
      << error_of(kTask, {{"vary_fov", 1.75}});
  fs::remove_all(folder);
}

// An image that cannot be read fails the reset that picks it, naming the file, and the env keeps
// the look it had: nothing is drawn from a half-read image.
TEST(VariationErrorsTest, AnUnreadableImageFailsTheResetAndTheLookStays) {
  const fs::path folder = fresh_folder("unreadable");
  write_solid_png(folder / "a.png", 8, 200, 200, 200);
  // A PNG cut short: its header says 8 x 8, its data is missing.
  fs::copy_file(folder / "a.png", folder / "b.png");
  fs::resize_file(folder / "b.png", 40);
  const std::unique_ptr<Env> env =
      make(kTask, small({{"sky_texture", folder.string()}, {"variation", 0.0}}));
  int failures = 0;
  int successes = 0;
  for (std::uint64_t seed = 0; seed < 12 && (failures == 0 || successes == 0); ++seed) {
    const VariationSample before = pixel_env(*env).variation();
    const render::Sky sky_before = pixel_env(*env).scene().scene().sky;
    try {
      env->reset(seed);
      ++successes;
      ASSERT_NE(pixel_env(*env).variation().sky.image, nullptr);
      EXPECT_EQ(pixel_env(*env).variation().sky.image->image().width, 8);
    } catch (const std::runtime_error& error) {
      ++failures;
      EXPECT_NE(std::string(error.what()).find((folder / "b.png").string()), std::string::npos)
          << error.what();
      EXPECT_EQ(pixel_env(*env).variation().sky.image, before.sky.image);
      EXPECT_EQ(pixel_env(*env).scene().scene().sky.image, sky_before.image);
    }
  }
  EXPECT_GT(failures, 0);
  EXPECT_GT(successes, 0);
  fs::remove_all(folder);
}

// A folder of the user's images is a background: the frames show them.
TEST(VariationTexturesTest, AFolderOfImagesIsDrawnAsTheSky) {
  const fs::path folder = fresh_folder("folder");
  write_solid_png(folder / "red.png", 16, 230, 10, 10);
  const std::unique_ptr<Env> env = make(kTask, small({{"sky_texture", folder.string()},
                                                      {"camera_lookat", "0,0,3"},
                                                      {"camera_pos", "0,-4,3"}}));
  const Array frame = pixels(env->reset(0).obs);
  // The top row sees the sky only: the image's red.
  const std::uint8_t* row = frame.data<std::uint8_t>();
  for (int x = 0; x < 48; ++x) {
    EXPECT_EQ(row[x * 3], 230) << x;
    EXPECT_EQ(row[x * 3 + 1], 10) << x;
  }
  fs::remove_all(folder);
}

// A folder of subfolders is a folder of videos (DAVIS's layout): an episode picks one of the first
// sky_backgrounds of them (images directly in the folder count as one each), then one frame.
TEST(VariationTexturesTest, SubfoldersAreVideosAndSkyBackgroundsTakesTheFirstByName) {
  const fs::path folder = fresh_folder("videos");
  // Backgrounds by name: "a.png" (grey), then the videos "b" (reds), "c" (greens), "d" (blues).
  write_solid_png(folder / "a.png", 8, 90, 90, 90);
  const std::uint8_t shades[3] = {150, 190, 230};
  for (const char* video : {"b", "c", "d"}) fs::create_directories(folder / video);
  for (int frame = 0; frame < 3; ++frame) {
    const std::string name = "0000" + std::to_string(frame) + ".png";
    write_solid_png(folder / "b" / name, 8, shades[frame], 0, 0);
    write_solid_png(folder / "c" / name, 8, 0, shades[frame], 0);
    write_solid_png(folder / "d" / name, 8, 0, 0, shades[frame]);
  }
  fs::create_directories(folder / "e_empty");
  // The colours the sky shows over 96 seeds, at a count of `backgrounds`.
  const auto seen = [&](int backgrounds) {
    std::set<std::array<int, 3>> colors;
    const std::unique_ptr<Env> env =
        make(kTask, small({{"sky_texture", folder.string()}, {"sky_backgrounds", backgrounds}}));
    for (std::uint64_t seed = 0; seed < 96; ++seed) {
      env->reset(seed);
      const std::vector<std::uint8_t>& pixels =
          pixel_env(*env).variation().sky.image->image().pixels;
      colors.insert({pixels[0], pixels[1], pixels[2]});
    }
    return colors;
  };
  const std::set<std::array<int, 3>> two = seen(2);
  std::set<std::array<int, 3>> expected = {{90, 90, 90}};
  for (const std::uint8_t shade : shades) expected.insert({shade, 0, 0});
  EXPECT_EQ(two, expected);
  const std::set<std::array<int, 3>> all = seen(0);
  for (const std::uint8_t shade : shades) {
    expected.insert({0, shade, 0});
    expected.insert({0, 0, shade});
  }
  EXPECT_EQ(all, expected);
  EXPECT_EQ(seen(4), all);
  fs::remove_all(folder);
}

TEST(VariationTexturesTest, SkyBackgroundsLimitsTheNoiseImages) {
  const std::unique_ptr<Env> env =
      make(kTask, small({{"sky_texture", "noise"}, {"sky_backgrounds", 4}}));
  const auto& noise = noise_textures();
  std::set<const render::TextureImage*> seen;
  for (std::uint64_t seed = 0; seed < 48; ++seed) {
    env->reset(seed);
    seen.insert(pixel_env(*env).variation().sky.image.get());
  }
  EXPECT_EQ(seen, (std::set<const render::TextureImage*>{noise[0].get(), noise[1].get(),
                                                         noise[2].get(), noise[3].get()}));
}

TEST(VariationErrorsTest, SkyBackgroundsOutsideTheSkysCountIsAnError) {
  EXPECT_TRUE(ends_with(error_of(kTask, {{"sky_texture", "noise"}, {"sky_backgrounds", 17}}),
                        "sky_backgrounds must be in [0, 16] (0: all of sky_texture \"noise\"'s "
                        "16), got 17"))
      << error_of(kTask, {{"sky_texture", "noise"}, {"sky_backgrounds", 17}});
  EXPECT_NE(error_of(kTask, {{"sky_texture", "noise"}, {"sky_backgrounds", -1}}).find("got -1"),
            std::string::npos);
  EXPECT_NE(error_of(kTask, {{"sky_backgrounds", 4}})
                .find("sky_texture \"gradient\" has none: give \"noise\" or a folder"),
            std::string::npos);
}

// reset()'s options set the variation's kwargs from that reset on (a curriculum, or evaluating
// one policy under several settings without a new env): each reset looks exactly as an env made
// with those kwargs does, turning it off gives the plain task's bytes back, and a bad option
// changes nothing.
TEST(VariationOptionsTest, ResetOptionsSetTheVariationFromThatResetOn) {
  const std::unique_ptr<Env> env = make(kTask, small());
  const std::unique_ptr<Env> plain = make(kTask, small());
  const std::unique_ptr<Env> varied = make(kTask, small({{"variation", 0.3}}));
  const std::unique_ptr<Env> camera = make(kTask, small({{"vary_camera", 0.3}}));
  const auto same_frame = [](const Value& a, const Value& b) {
    return pixels(a).equals(pixels(b)) && same_state(a, b);
  };

  EXPECT_TRUE(same_frame(env->reset(3, {{"variation", 0.3}}).obs, varied->reset(3).obs));
  EXPECT_FALSE(same_frame(env->reset(3, {{"variation", 0.3}}).obs, plain->reset(3).obs));
  // It stays for the resets after (an autoresetting vector env's too).
  EXPECT_TRUE(same_frame(env->reset(4).obs, varied->reset(4).obs));
  EXPECT_TRUE(same_frame(env->reset().obs, varied->reset().obs));
  // Off again: the task's own look, byte for byte.
  EXPECT_TRUE(same_frame(env->reset(5, {{"variation", 0}}).obs, plain->reset(5).obs));
  EXPECT_TRUE(same_frame(env->reset(6, {{"vary_camera", 0.3}}).obs, camera->reset(6).obs));

  const auto refusal = [&](const Options& options) {
    try {
      env->reset(7, options);
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(refusal({{"gravity", 3.0}}).find("reset options (the visual variation's kwargs)"),
            std::string::npos)
      << refusal({{"gravity", 3.0}});
  EXPECT_NE(refusal({{"gravity", 3.0}}).find("vary_camera (float, default 0.3)"), std::string::npos)
      << refusal({{"gravity", 3.0}});
  EXPECT_TRUE(ends_with(refusal({{"variation", 1.5}}), "variation must be in [0, 1], got 1.5"));
  EXPECT_NE(refusal({{"sky_texture", 2}}).find("sky_texture"), std::string::npos);
  // None of them changed anything: the next reset is as before them.
  EXPECT_TRUE(same_frame(env->reset(8).obs, camera->reset(8).obs));
}

TEST(CamerasTest, SeveralNamedCamerasAreImagesOfTheirOwnInTheDict) {
  const std::unique_ptr<Env> env = make(kTask, small({{"cameras", "close,tracking"}}));
  const auto& space = dynamic_cast<const spaces::Dict&>(env->observation_space());
  std::vector<std::string> keys;
  for (const auto& [key, subspace] : space.entries()) keys.push_back(key);
  EXPECT_EQ(keys, (std::vector<std::string>{"pixels/close", "pixels/tracking", "joint_pos",
                                            "joint_vel"}));
  const Value obs = env->reset(3).obs;
  PixelEnv& inner = pixel_env(*env);
  EXPECT_TRUE(
      obs.dict().at("pixels/close").array().equals(inner.render_camera("close", 48, 48, 0)));
  EXPECT_TRUE(
      obs.dict().at("pixels/tracking").array().equals(inner.render_camera("tracking", 48, 48, 0)));
  EXPECT_FALSE(
      obs.dict().at("pixels/close").array().equals(obs.dict().at("pixels/tracking").array()));
  EXPECT_TRUE(env->observation_space().contains(obs));
}

TEST(CamerasTest, ACustomCameraAndAFieldOfViewAreDrawnAsAsked) {
  const std::unique_ptr<Env> env = make(
      kTask, small({{"camera_pos", "1,-3,2"}, {"camera_lookat", "0,0,1"}, {"camera_fov", 30}}));
  const Array frame = pixels(env->reset(2).obs);
  PixelEnv& inner = pixel_env(*env);
  render::Camera camera = render::Camera::look_at({1.0F, -3.0F, 2.0F}, {0.0F, 0.0F, 1.0F});
  camera.fov_y_deg = 30.0F;
  camera.width = 48;
  camera.height = 48;
  std::vector<std::uint8_t> expected(48 * 48 * 3);
  render::Renderer renderer;
  renderer.render(inner.scene().scene(), camera, {48, 48, expected.data()});
  EXPECT_TRUE(std::equal(expected.begin(), expected.end(), frame.data<std::uint8_t>()));
  EXPECT_EQ(inner.config().camera, "custom");
  // The fov applies to the task's cameras too.
  const std::unique_ptr<Env> narrow = make(kTask, small({{"camera_fov", 20}}));
  const std::unique_ptr<Env> plain = make(kTask, small());
  EXPECT_FALSE(pixels(narrow->reset(2).obs).equals(pixels(plain->reset(2).obs)));
}

// The distracting variants: the base task's physics, rewards and flags, with colours, camera and
// background drawn from the seed at the intensity asked.
TEST(DistractingTest, EachVariantIsItsBaseTaskLookingDifferent) {
  for (const auto& [variant, base] : std::vector<std::pair<std::string, std::string>>{
           {"CartPoleSwingup-distracting-v1", "CartPoleSwingup-v1"},
           {"ReacherEasy-distracting-v1", "ReacherEasy-v1"},
           {"CheetahRun-distracting-v0", "CheetahRun-v0"},
           {"FingerSpin-distracting-v0", "FingerSpin-v0"},
           {"BallInCupCatch-distracting-v0", "BallInCupCatch-v0"},
           {"WalkerWalk-distracting-v0", "WalkerWalk-v0"}}) {
    const std::unique_ptr<Env> a = make(base, small());
    const std::unique_ptr<Env> b = make(variant, small());
    const ResetResult x = a->reset(5);
    const ResetResult y = b->reset(5);
    EXPECT_FALSE(pixels(x.obs).equals(pixels(y.obs))) << variant;
    Value action = a->action_space().zeros();
    for (int i = 0; i < 5; ++i) {
      const StepResult p = a->step(action);
      const StepResult q = b->step(action);
      EXPECT_EQ(p.reward, q.reward) << variant;
      for (const std::string& key : p.obs.dict().keys()) {
        if (key != "pixels") {
          EXPECT_TRUE(p.obs.dict().at(key).array().equals(q.obs.dict().at(key).array()))
              << variant << " " << key;
        }
      }
    }
    const VariationConfig& config = pixel_env(*b).config().variation;
    EXPECT_EQ(config.colors, 0.2) << variant;
    EXPECT_EQ(config.camera, 0.2) << variant;
    EXPECT_EQ(config.light, 0.0) << variant;
    EXPECT_EQ(config.sky.kind, TextureSource::Kind::kNoise) << variant;
  }
  // The intensity is a kwarg: at 0 only the background and the see-through floor remain.
  const std::unique_ptr<Env> calm =
      make("CartPoleSwingup-distracting-v1", small({{"variation", 0.0}}));
  calm->reset(1);
  EXPECT_EQ(pixel_env(*calm).variation().camera_zoom, 1.0F);
  EXPECT_EQ(pixel_env(*calm).config().variation.floor_opacity, 0.3F);
}

}  // namespace
}  // namespace pixelgym
