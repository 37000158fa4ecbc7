// OSMesa and EGL on llvmpipe are two front ends of the same Mesa rasterizer: every pixel task,
// from each of its cameras, draws the same bytes with either (observations and render() frames),
// so goldens and determinism hold whichever backend a machine has.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/render/context.h"
#include "tests/envs/env_ids.h"

namespace pixelgym {
namespace {

bool draws(const std::string& id) {
  const auto& params = default_registry().spec(id)->params;
  return std::any_of(params.begin(), params.end(),
                     [](const ParamSpec& param) { return param.name == "render_backend"; });
}

// "" when equal, else how many bytes differ and by how much at most.
std::string difference(const Array& a, const Array& b) {
  if (a.shape() != b.shape()) return "shapes differ";
  const auto* pa = a.data<std::uint8_t>();
  const auto* pb = b.data<std::uint8_t>();
  std::int64_t differing = 0;
  int largest = 0;
  for (std::int64_t i = 0; i < a.size(); ++i) {
    const int delta = std::abs(static_cast<int>(pa[i]) - static_cast<int>(pb[i]));
    if (delta != 0) ++differing;
    largest = std::max(largest, delta);
  }
  if (differing == 0) return "";
  return std::to_string(differing) + " of " + std::to_string(a.size()) +
         " bytes differ, by up to " + std::to_string(largest);
}

class RenderBackendsTest : public ::testing::TestWithParam<std::string> {};

TEST_P(RenderBackendsTest, EglAndOsMesaDrawTheSameBytesFromEveryCamera) {
  const std::string id = GetParam();
  if (!draws(id)) GTEST_SKIP() << id << " draws nothing";
  if (!render::gl_backend_built(render::GlBackend::kOSMesa)) {
    GTEST_SKIP() << "built without OSMesa";
  }
  for (const std::string& camera : describe(id).cameras) {
    const Params kwargs = {{"camera", camera}, {"obs_mode", "pixels"}, {"width", 64},
                           {"height", 64},     {"render_width", 96},   {"render_height", 96}};
    Params osmesa_kwargs = kwargs;
    osmesa_kwargs.insert_or_assign("render_backend", Param("osmesa"));
    Params egl_kwargs = kwargs;
    egl_kwargs.insert_or_assign("render_backend", Param("egl"));
    std::unique_ptr<Env> osmesa = make(id, osmesa_kwargs);
    std::unique_ptr<Env> egl = make(id, egl_kwargs);
    Value osmesa_obs = osmesa->reset(11).obs;
    Value egl_obs = egl->reset(11).obs;
    Rng actions(2);
    for (int t = 0; t < 12; ++t) {
      ASSERT_EQ(
          difference(osmesa_obs.dict().at("pixels").array(), egl_obs.dict().at("pixels").array()),
          "")
          << id << ", camera " << camera << ", observation " << t;
      const Value action = osmesa->action_space().sample(actions);
      osmesa_obs = osmesa->step(action).obs;
      egl_obs = egl->step(action).obs;
    }
    ASSERT_EQ(difference(osmesa->render(), egl->render()), "")
        << id << ", camera " << camera << ", render()";
  }
}

INSTANTIATE_TEST_SUITE_P(AllEnvs, RenderBackendsTest, ::testing::ValuesIn(registered_ids()),
                         testing::env_id_test_name);

}  // namespace
}  // namespace pixelgym
