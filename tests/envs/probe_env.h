// ProbeEnv: a small continuous env for protocol tests, with switchable faults for the checker.
#pragma once

#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/spaces/box.h"

namespace pixelgym::testing {

/// One deliberate fault each; the checker test shows every check catches its fault.
enum class Fault {
  kNone,
  kActionSpaceSamplesOutside,  // the action space's samples are not in the space
  kObservationSpaceSamplesOutside,
  kResetObservationWrongDtype,  // reset returns float64 for a float32 space
  kResetIgnoresSeed,            // the start comes from the OS, not the seed
  kUnseededResetReseeds,        // reset() reseeds with a constant instead of continuing
  kNanReward,
  kStepObservationOutside,  // steps leave the observation space
  kNondeterministicStep,    // steps add OS noise
  kAliasedObservation,      // one buffer is returned (and overwritten) every step
  kReplacesBuffer,          // steps put a new array in place of the caller's instead of writing
  kBadRender,               // RGBA frames
  kZeroRenderFps,
  kCloseThrows,
};

/// A Box whose samples may be pushed out of bounds (a space that is not self-consistent).
class OffsetBox final : public Space {
 public:
  OffsetBox(spaces::Box box, double offset) : box_(std::move(box)), offset_(offset) {}
  Value sample(Rng& rng) const override {
    Array array = box_.sample(rng).array();
    for (std::int64_t i = 0; i < array.size(); ++i)
      array.data<float>()[i] += static_cast<float>(offset_);
    return array;
  }
  std::string mismatch(const Value& value) const override { return box_.mismatch(value); }
  std::optional<Shape> shape() const override { return box_.shape(); }
  std::optional<DType> dtype() const override { return box_.dtype(); }
  std::string to_string() const override { return box_.to_string(); }
  bool equals(const Space& other) const override { return box_.equals(other); }

 private:
  spaces::Box box_;
  double offset_;
};

/// x' = x + 0.1 a with a start x0 ~ U(-1, 1); observation (x, t / 100) as float32; reward -|x|;
/// terminated when t reaches `episode_length`.
class ProbeEnv final : public Env {
 public:
  explicit ProbeEnv(Fault fault = Fault::kNone, int episode_length = 20)
      : fault_(fault), episode_length_(episode_length) {
    const spaces::Box action(-1.0, 1.0, {1});
    const spaces::Box observation(-10.0, 10.0, {2});
    action_space_ = fault == Fault::kActionSpaceSamplesOutside
                        ? SpacePtr(std::make_shared<OffsetBox>(action, 5.0))
                        : SpacePtr(std::make_shared<spaces::Box>(action));
    observation_space_ = fault == Fault::kObservationSpaceSamplesOutside
                             ? SpacePtr(std::make_shared<OffsetBox>(observation, 50.0))
                             : SpacePtr(std::make_shared<spaces::Box>(observation));
    metadata_.render_fps = fault == Fault::kZeroRenderFps ? 0.0 : 30.0;
  }

  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  const Metadata& metadata() const override { return metadata_; }

  double x() const { return x_; }
  int t() const { return t_; }
  int close_calls() const { return close_calls_; }

 protected:
  std::string type_name() const override { return "ProbeEnv"; }

  void do_reset(std::optional<std::uint64_t> seed, const Options& /*options*/,
                ResetResult& out) override {
    if (fault_ == Fault::kUnseededResetReseeds && !seed) rng() = Rng(7);
    x_ = fault_ == Fault::kResetIgnoresSeed ? os_uniform() : rng().uniform(-1.0, 1.0);
    t_ = 0;
    observe(out.obs);
    // A broken env may put an array of its own in place of the caller's buffer.
    if (fault_ == Fault::kResetObservationWrongDtype) {
      out.obs = Array::from_vector<double>({2}, {x_, 0.0});
    }
  }

  void do_step(const Value& action, StepResult& out) override {
    x_ += 0.1 * action.array().data<float>()[0];
    if (fault_ == Fault::kNondeterministicStep) x_ += 1e-3 * os_uniform();
    if (fault_ == Fault::kStepObservationOutside && t_ == 2) x_ = 100.0;
    ++t_;
    if (fault_ == Fault::kReplacesBuffer) out.obs = Array(DType::kFloat32, {2});
    observe(out.obs);
    out.reward = fault_ == Fault::kNanReward ? std::nan("") : -std::abs(x_);
    out.terminated = t_ >= episode_length_;
  }

  Array do_render() override {
    Array frame(DType::kUInt8, {8, 8, fault_ == Fault::kBadRender ? 4 : 3});
    frame.data<std::uint8_t>()[0] = static_cast<std::uint8_t>(t_);
    return frame;
  }

  void do_close() override {
    ++close_calls_;
    if (fault_ == Fault::kCloseThrows) throw std::runtime_error("ProbeEnv: close failed");
  }

 private:
  static double os_uniform() {
    std::random_device device;
    return std::uniform_real_distribution<double>(-1.0, 1.0)(device);
  }

  void observe(Value& obs) {
    if (fault_ == Fault::kAliasedObservation) {
      if (shared_obs_.size() != 2) shared_obs_ = Array(DType::kFloat32, {2});
      obs = shared_obs_;  // every step hands out the same memory
    }
    float* out = obs.array().data<float>();
    out[0] = static_cast<float>(x_);
    out[1] = static_cast<float>(t_) / 100.0F;
  }

  Fault fault_;
  int episode_length_;
  SpacePtr observation_space_;
  SpacePtr action_space_;
  Metadata metadata_;
  double x_ = 0.0;
  int t_ = 0;
  int close_calls_ = 0;
  Array shared_obs_;
};

/// A float32 action of shape (1,).
inline Value action(float a) { return Array::from_vector<float>({1}, {a}); }

}  // namespace pixelgym::testing
