#include "pixelgym/envs/checker.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

#include "pixelgym/envs/rollout.h"

namespace pixelgym {
namespace {

// A failed check: thrown inside a check to stop it with a reason.
struct CheckFailure {
  std::string reason;
};

void expect(bool condition, const std::string& reason) {
  if (!condition) throw CheckFailure{reason};
}

void expect_in_space(const Space& space, const Value& value, const std::string& what) {
  const std::string reason = space.mismatch(value);
  expect(reason.empty(),
         what + " " + value.to_string() + " is not in " + space.to_string() + ": " + reason);
}

// One step of a recorded trajectory.
struct Transition {
  Value obs;
  double reward;
  bool terminated;
  bool truncated;
};

// RandomRollout over `num_steps` steps, every transition recorded: the reset's observation, each
// step's, and the new episode's first after an episode ends.
std::vector<Transition> rollout(Env& env, std::uint64_t seed, int num_steps) {
  std::vector<Transition> trajectory;
  RandomRollout random(env, seed);
  trajectory.push_back({random.observation(), 0.0, false, false});
  for (int t = 0; t < num_steps; ++t) {
    const StepResult& step = random.step();
    trajectory.push_back({step.obs, step.reward, step.terminated, step.truncated});
    if (random.episode_ended()) trajectory.push_back({random.observation(), 0.0, false, false});
  }
  return trajectory;
}

void check_space_samples(const Space& space) {
  Rng rng(12345);
  constexpr int kSamples = 16;
  expect(!space.to_string().empty(), "to_string() is empty");
  for (int i = 0; i < kSamples; ++i) {
    const Value sample = space.sample(rng);
    const std::string reason = space.mismatch(sample);
    expect(reason.empty(), "sample " + std::to_string(i) + " " + sample.to_string() +
                               " is not in its own space " + space.to_string() + ": " + reason);
  }
}

}  // namespace

bool CheckReport::passed() const {
  return std::all_of(results.begin(), results.end(), [](const CheckResult& r) { return r.passed; });
}

std::vector<CheckResult> CheckReport::failures() const {
  std::vector<CheckResult> failed;
  std::copy_if(results.begin(), results.end(), std::back_inserter(failed),
               [](const CheckResult& r) { return !r.passed; });
  return failed;
}

CheckReport check_env(Env& env, const CheckOptions& options) {
  CheckReport report;
  const std::uint64_t seed = options.seed;
  const auto run = [&](const std::string& name, const std::function<void()>& check) {
    CheckResult result{name, true, ""};
    try {
      check();
    } catch (const CheckFailure& failure) {
      result = {name, false, failure.reason};
    } catch (const std::exception& error) {
      result = {name, false, std::string("threw: ") + error.what()};
    }
    report.results.push_back(result);
  };

  run("observation_space", [&] { check_space_samples(env.observation_space()); });
  run("action_space", [&] { check_space_samples(env.action_space()); });

  run("reset", [&] {
    expect_in_space(env.observation_space(), env.reset(seed).obs, "reset(seed) observation");
  });

  run("reset_seed", [&] {
    const Value first = env.reset(seed).obs;
    const Value second = env.reset(seed).obs;
    expect(first.equals(second), "reset(seed=" + std::to_string(seed) + ") twice gave " +
                                     first.to_string() + " then " + second.to_string());
  });

  run("reset_unseeded", [&] {
    const Value seeded = env.reset(seed).obs;
    const Value next = env.reset().obs;
    const Value next_again = (env.reset(seed), env.reset().obs);
    expect(next.equals(next_again),
           "reset() after reset(seed) is not repeatable: the generator is not the seeded one");
    const Value other_seeded = env.reset(seed + 1).obs;
    const Value other_next = env.reset().obs;
    // Only envs whose start depends on the seed can show a reseed to a fixed state.
    if (!seeded.equals(other_seeded)) {
      expect(!next.equals(other_next),
             "reset() gave the same observation after reset(seed) with seeds " +
                 std::to_string(seed) + " and " + std::to_string(seed + 1) +
                 ": unseeded resets must continue the generator, not reseed it");
    }
  });

  run("step", [&] {
    std::vector<Transition> trajectory = rollout(env, seed, options.num_steps);
    for (std::size_t i = 0; i < trajectory.size(); ++i) {
      expect_in_space(env.observation_space(), trajectory[i].obs,
                      "observation " + std::to_string(i));
      expect(std::isfinite(trajectory[i].reward), "reward " + std::to_string(trajectory[i].reward) +
                                                      " at transition " + std::to_string(i) +
                                                      " is not finite");
    }
  });

  run("step_determinism", [&] {
    const std::vector<Transition> a = rollout(env, seed, options.num_steps);
    const std::vector<Transition> b = rollout(env, seed, options.num_steps);
    expect(a.size() == b.size(),
           "two runs with seed " + std::to_string(seed) + " had different episode boundaries");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string where = " differ at transition " + std::to_string(i) +
                                " of two runs with seed " + std::to_string(seed) +
                                " and the same actions";
      expect(a[i].obs.equals(b[i].obs), "observations" + where);
      expect(a[i].reward == b[i].reward || (std::isnan(a[i].reward) && std::isnan(b[i].reward)),
             "rewards" + where);
      expect(a[i].terminated == b[i].terminated && a[i].truncated == b[i].truncated,
             "terminated/truncated flags" + where);
    }
  });

  run("observation_aliasing", [&] {
    // Observations may share memory (FrameStackObservation's stacked frames do), but what reset()
    // or step() returned must never change afterwards: keep each with a copy made as it was
    // returned, and compare once the later steps ran.
    std::vector<Value> held;
    std::vector<Value> copies;
    const auto keep = [&](const Value& obs) {
      held.push_back(obs);
      copies.push_back(obs.clone());
    };
    RandomRollout random(env, seed);
    keep(random.observation());
    for (int t = 0; t < std::min(options.num_steps, 10); ++t) {
      keep(random.step().obs);
      if (random.episode_ended()) keep(random.observation());
    }
    for (std::size_t i = 0; i + 1 < held.size(); ++i) {
      expect(held[i].equals(copies[i]),
             "observation " + std::to_string(i) +
                 " changed when later steps ran: the env wrote "
                 "again into memory it had returned (observations may share memory only when it is "
                 "never written again)");
    }
  });

  run("buffer_path", [&] {
    // reset_into / step_into write into the caller's arrays and give what reset / step give.
    const auto same_arrays = [](const std::vector<Array>& a, const std::vector<Array>& b) {
      if (a.size() != b.size()) return false;
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i].raw_data() != b[i].raw_data()) return false;
      }
      return true;
    };
    ResetResult reset;
    reset.obs = env.observation_space().zeros();
    const std::vector<Array> reset_arrays = reset.obs.leaves();
    env.reset_into(reset, seed);
    expect(same_arrays(reset_arrays, reset.obs.leaves()),
           "reset_into() put arrays of its own in the caller's observation instead of writing "
           "into them");
    expect(reset.obs.equals(env.reset(seed).obs),
           "reset_into(seed) and reset(seed) gave different observations");

    Rng actions_rng(seed);
    std::vector<Value> actions;
    for (int i = 0; i < std::min(options.num_steps, 10); ++i) {
      actions.push_back(env.action_space().sample(actions_rng));
    }
    std::vector<StepResult> expected;
    env.reset(seed);
    for (const Value& action : actions) {
      expected.push_back(env.step(action));
      if (expected.back().terminated || expected.back().truncated) break;
    }
    env.reset(seed);
    StepResult step;
    step.obs = env.observation_space().zeros();
    const std::vector<Array> step_arrays = step.obs.leaves();
    for (std::size_t i = 0; i < expected.size(); ++i) {
      env.step_into(actions[i], step);
      const std::string where = " at step " + std::to_string(i);
      expect(same_arrays(step_arrays, step.obs.leaves()),
             "step_into() put arrays of its own in the caller's observation instead of writing "
             "into them" +
                 where);
      expect(step.obs.equals(expected[i].obs),
             "step_into() and step() observations differ" + where);
      expect(step.reward == expected[i].reward ||
                 (std::isnan(step.reward) && std::isnan(expected[i].reward)),
             "step_into() and step() rewards differ" + where);
      expect(step.terminated == expected[i].terminated && step.truncated == expected[i].truncated,
             "step_into() and step() flags differ" + where);
    }
  });

  run("render", [&] {
    env.reset(seed);
    const Array frame = env.render();
    const Shape& shape = frame.shape();
    expect(frame.dtype() == DType::kUInt8 && shape.size() == 3 && shape[2] == 3 && shape[0] > 0 &&
               shape[1] > 0,
           std::string("render() returned ") + dtype_name(frame.dtype()) + " " +
               shape_to_string(shape) + ", expected uint8 (H, W, 3) with H, W > 0");
    const std::optional<Shape>& declared = env.metadata().render_shape;
    expect(!declared || *declared == shape,
           "render() returned a " + shape_to_string(shape) + " frame, metadata().render_shape is " +
               (declared ? shape_to_string(*declared) : std::string()));
  });

  run("metadata", [&] {
    const Metadata& metadata = env.metadata();
    const auto& modes = metadata.render_modes;
    expect(std::find(modes.begin(), modes.end(), "rgb_array") != modes.end(),
           "render_modes does not include \"rgb_array\"");
    std::ostringstream fps;
    fps << metadata.render_fps;
    expect(std::isfinite(metadata.render_fps) && metadata.render_fps > 0,
           "render_fps must be > 0, got " + fps.str());
  });

  run("close", [&] {
    env.close();
    env.close();
  });
  return report;
}

}  // namespace pixelgym
