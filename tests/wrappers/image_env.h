// ImageEnv: a small env with an observation space of the test's choosing, for image wrapper tests.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"

namespace pixelgym::testing {

/// Every observation fills each array of the space with generator noise: uint8 elements uniform
/// in [0, 255], float ones uniform in [-1, 1] (so the space's bounds must allow those). The
/// action is a float32 (1,) Box and episodes end after `episode_length` steps. Set `next` to
/// write a given observation instead (copied into the caller's buffer).
class ImageEnv final : public Env {
 public:
  explicit ImageEnv(SpacePtr observation_space, int episode_length = 10)
      : observation_space_(std::move(observation_space)), episode_length_(episode_length) {
    metadata_.render_fps = 30.0;
  }

  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return action_space_; }
  const Metadata& metadata() const override { return metadata_; }

  /// When it holds a value, the next observations are copies of it.
  std::optional<Value> next;

 protected:
  std::string type_name() const override { return "ImageEnv"; }

  void do_reset(std::optional<std::uint64_t> /*seed*/, const Options& /*options*/,
                ResetResult& out) override {
    t_ = 0;
    observe(out.obs);
  }

  void do_step(const Value& /*action*/, StepResult& out) override {
    ++t_;
    observe(out.obs);
    out.reward = 0.0;
    out.terminated = t_ >= episode_length_;
  }

  Array do_render() override { return Array(DType::kUInt8, {8, 8, 3}); }

 private:
  void observe(Value& obs) {
    if (next) {
      copy(*next, obs);
    } else {
      fill(obs);
    }
  }

  static void copy(const Value& from, Value& to) {
    if (from.is_array()) {
      to.array().copy_from(from.array());
      return;
    }
    for (std::size_t i = 0; i < from.dict().size(); ++i) {
      copy(from.dict().values()[i], to.dict().values()[i]);
    }
  }

  void fill(Value& obs) {
    if (obs.is_dict()) {
      for (Value& entry : obs.dict().values()) fill(entry);
      return;
    }
    Array& array = obs.array();
    for (std::int64_t i = 0; i < array.size(); ++i) {
      if (array.dtype() == DType::kUInt8) {
        array.data<std::uint8_t>()[i] = static_cast<std::uint8_t>(rng().uniform(0.0, 256.0));
      } else {
        array.data<float>()[i] = static_cast<float>(rng().uniform(-1.0, 1.0));
      }
    }
  }

  SpacePtr observation_space_;
  spaces::Box action_space_{-1.0, 1.0, {1}};
  Metadata metadata_;
  int episode_length_;
  int t_ = 0;
};

/// A uint8 (H, W, C) Box with bounds [0, 255].
inline SpacePtr image_box(std::int64_t height, std::int64_t width, std::int64_t channels) {
  return std::make_shared<spaces::Box>(0.0, 255.0, Shape{height, width, channels}, DType::kUInt8);
}

/// Dict{"pixels": (H, W, C) uint8, "state": float32 (4,), "depth": (H, W, 1) uint8,
/// "velocity": float32 (2, 2)}: an image, state entries around it and a second image key.
inline SpacePtr pixels_and_state(std::int64_t height, std::int64_t width, std::int64_t channels) {
  return std::make_shared<spaces::Dict>(spaces::Dict::Entries{
      {"state", std::make_shared<spaces::Box>(-1.0, 1.0, Shape{4})},
      {"pixels", image_box(height, width, channels)},
      {"depth", image_box(height, width, 1)},
      {"velocity", std::make_shared<spaces::Box>(-1.0, 1.0, Shape{2, 2})},
  });
}

}  // namespace pixelgym::testing
