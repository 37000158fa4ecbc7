// ScriptedEnv: a small env whose spaces, rewards, episode end and frames a test chooses, and which
// remembers what it was given and what it returned (for the action, reward, statistics and
// observation wrapper tests).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/spaces/box.h"

namespace pixelgym::testing {

/// Observations fill each array with noise: uint8 uniform in [0, 255], int32 / int64 uniform in
/// [-5, 5], floats `offset + scale * U(-1, 1)`. Rewards cycle through `rewards` (1 by default).
/// The episode ends after `episode_length` steps, by truncation when `truncate`, else by
/// termination. render() returns a zero frame of metadata.render_shape whose first byte is the
/// step count (meta.render_shape, metadata()'s, is the tests' to change).
class ScriptedEnv final : public Env {
 public:
  ScriptedEnv(SpacePtr observation_space, SpacePtr action_space, int episode_length = 10,
              bool truncate = false)
      : observation_space_(std::move(observation_space)),
        action_space_(std::move(action_space)),
        episode_length_(episode_length),
        truncate_(truncate) {
    meta.render_fps = 30.0;
    meta.render_shape = Shape{6, 8, 3};
  }

  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  const Metadata& metadata() const override { return meta; }

  Metadata meta;  // what metadata() returns
  double offset = 0.0;
  double scale = 1.0;
  std::vector<double> rewards{1.0};
  /// When true, every observation and action is cloned into `observations` / `actions`.
  bool record = true;
  std::vector<Value> observations;
  std::vector<Value> actions;
  int t = 0;

 protected:
  std::string type_name() const override { return "ScriptedEnv"; }

  void do_reset(std::optional<std::uint64_t> /*seed*/, const Options& /*options*/,
                ResetResult& out) override {
    t = 0;
    fill(out.obs);
    if (record) observations.push_back(out.obs.clone());
  }

  void do_step(const Value& action, StepResult& out) override {
    if (record) actions.push_back(action.clone());
    out.reward = rewards[static_cast<std::size_t>(t) % rewards.size()];
    ++t;
    fill(out.obs);
    if (record) observations.push_back(out.obs.clone());
    const bool end = t >= episode_length_;
    out.terminated = end && !truncate_;
    out.truncated = end && truncate_;
  }

  Array do_render() override {
    Array frame(DType::kUInt8, meta.render_shape.value_or(Shape{4, 4, 3}));
    frame.data<std::uint8_t>()[0] = static_cast<std::uint8_t>(t);
    return frame;
  }

 private:
  void fill(Value& obs) {
    if (obs.is_dict()) {
      for (Value& entry : obs.dict().values()) fill(entry);
      return;
    }
    Array& array = obs.array();
    for (std::int64_t i = 0; i < array.size(); ++i) {
      switch (array.dtype()) {
        case DType::kUInt8:
          array.data<std::uint8_t>()[i] = static_cast<std::uint8_t>(rng().integer(0, 255));
          break;
        case DType::kInt32:
          array.data<std::int32_t>()[i] = static_cast<std::int32_t>(rng().integer(-5, 5));
          break;
        case DType::kInt64:
          array.data<std::int64_t>()[i] = rng().integer(-5, 5);
          break;
        case DType::kFloat32:
          array.data<float>()[i] = static_cast<float>(offset + scale * rng().uniform(-1.0, 1.0));
          break;
        case DType::kFloat64:
          array.data<double>()[i] = offset + scale * rng().uniform(-1.0, 1.0);
          break;
        case DType::kBool:
          break;
      }
    }
  }

  SpacePtr observation_space_;
  SpacePtr action_space_;
  int episode_length_;
  bool truncate_;
};

/// A float32 Box with the same bounds for every element.
inline SpacePtr box(double low, double high, Shape shape, DType dtype = DType::kFloat32) {
  return std::make_shared<spaces::Box>(low, high, std::move(shape), dtype);
}

}  // namespace pixelgym::testing
