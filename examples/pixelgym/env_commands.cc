// pixelgym list | info | check | snapshot | rollout | bench
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "envs/checker.h"
#include "envs/registry.h"
#include "examples/pixelgym/cli.h"

namespace pixelgym::cli {
namespace {

std::string join(const std::vector<std::string>& items) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return text;
}

int run_list() {
  for (const std::string& id : registered_ids()) {
    std::cout << std::left << std::setw(28) << id << " " << default_registry().spec(id)->description
              << "\n";
  }
  return 0;
}

int run_info(const std::string& id, const std::vector<std::string>& sets) {
  const auto spec = default_registry().spec(id);
  std::unique_ptr<Env> env = make_env(id, sets);
  std::cout << id << ": " << spec->description << "\n"
            << "observation_space: " << env->observation_space().to_string() << "\n"
            << "action_space:      " << env->action_space().to_string() << "\n"
            << "render_modes:      " << join(env->metadata().render_modes) << "\n"
            << "render_fps:        " << env->metadata().render_fps << "\n"
            << "max_episode_steps: "
            << (spec->max_episode_steps ? std::to_string(*spec->max_episode_steps) : "none") << "\n"
            << "config (--set key=value):\n";
  for (const ParamSpec& param : spec->params) {
    std::cout << "  " << std::left << std::setw(18) << param.name << std::setw(8)
              << param_type_name(param.type()) << "default " << std::setw(10)
              << param.default_value.to_string() << param.doc << "\n";
  }
  std::cout << "  " << std::left << std::setw(18) << "max_episode_steps" << std::setw(8) << "int"
            << "default " << std::setw(10)
            << (spec->max_episode_steps ? std::to_string(*spec->max_episode_steps) : "0")
            << "steps before TimeLimit truncates; 0 for no limit\n";
  env->close();
  return 0;
}

int run_check(const std::string& id, std::uint64_t seed, int steps,
              const std::vector<std::string>& sets) {
  std::unique_ptr<Env> env = make_env(id, sets);
  const CheckReport report = check_env(*env, {seed, steps});
  for (const CheckResult& result : report.results) {
    std::cout << (result.passed ? "ok    " : "FAIL  ") << result.name;
    if (!result.passed) std::cout << ": " << result.reason;
    std::cout << "\n";
  }
  const std::size_t failed = report.failures().size();
  if (failed == 0) {
    std::cout << id << ": all " << report.results.size() << " checks passed\n";
    return 0;
  }
  std::cout << id << ": " << failed << " of " << report.results.size() << " checks failed\n";
  return kExitFailure;
}

int run_snapshot(const std::string& id, std::uint64_t seed, int steps, const std::string& out,
                 bool observation, const std::vector<std::string>& sets) {
  std::unique_ptr<Env> env = make_env(id, sets);
  Value obs = env->reset(seed).obs;
  Rng action_rng(seed);
  for (int t = 0; t < steps; ++t) {
    const StepResult step = env->step(env->action_space().sample(action_rng));
    obs = step.obs;
    if (step.terminated || step.truncated) obs = env->reset().obs;
  }
  Array frame;
  if (observation) {
    if (!obs.is_dict() || !obs.dict().contains("pixels")) {
      throw std::invalid_argument(
          id + ": --observation needs an observation with \"pixels\" (try --set obs_mode=pixels)");
    }
    frame = obs.dict().at("pixels").array();
  } else {
    frame = env->render();
  }
  write_frame_png(out, frame);
  std::cout << "wrote " << out << " (" << frame.shape()[1] << "x" << frame.shape()[0] << " "
            << (observation ? "observation" : "render()") << ", " << id << ", seed " << seed << ", "
            << steps << " steps)\n";
  env->close();
  return 0;
}

int run_rollout(const std::string& id, std::uint64_t seed, int episodes,
                const std::string& snapshot, const std::vector<std::string>& sets) {
  std::unique_ptr<Env> env = make_env(id, sets);
  Rng action_rng(seed);
  double total = 0.0;
  for (int episode = 0; episode < episodes; ++episode) {
    // The first reset seeds the env; later ones continue its generator.
    env->reset(episode == 0 ? std::optional<std::uint64_t>(seed) : std::nullopt);
    double episode_return = 0.0;
    int length = 0;
    StepResult step;
    do {
      step = env->step(env->action_space().sample(action_rng));
      episode_return += step.reward;
      ++length;
    } while (!step.terminated && !step.truncated);
    total += episode_return;
    std::cout << "episode " << episode << ": return=" << episode_return << " length=" << length
              << (step.terminated ? " terminated" : " truncated") << "\n";
    if (!snapshot.empty() && episode == episodes - 1) write_frame_png(snapshot, env->render());
  }
  std::cout << "mean_return=" << total / episodes << " episodes=" << episodes << "\n";
  if (!snapshot.empty()) std::cout << "wrote " << snapshot << "\n";
  env->close();
  return 0;
}

int run_bench(const std::string& id, std::uint64_t seed, int steps,
              const std::vector<std::string>& sets) {
  std::unique_ptr<Env> env = make_env(id, sets);
  Rng action_rng(seed);
  env->reset(seed);
  // Warm up (shader compilation, caches) outside the timed loop.
  for (int t = 0; t < 20; ++t) {
    const StepResult step = env->step(env->action_space().sample(action_rng));
    if (step.terminated || step.truncated) env->reset();
  }
  int episodes = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int t = 0; t < steps; ++t) {
    const StepResult step = env->step(env->action_space().sample(action_rng));
    if (step.terminated || step.truncated) {
      env->reset();
      ++episodes;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << id << ": " << steps << " steps (" << episodes << " resets) in " << seconds
            << " s, one thread\n";
  std::cout << "steps_per_s=" << static_cast<long>(std::lround(steps / seconds)) << "\n";
  env->close();
  return 0;
}

}  // namespace

std::vector<Command> add_env_commands(CLI::App& app) {
  // Options live in shared state owned by the returned callbacks. Each subcommand's `--steps` has
  // its own variable: CLI11 writes a default into the variable when the option is declared, so
  // a shared one would take the last subcommand's default.
  struct Options {
    std::string id;
    std::uint64_t seed = 0;
    int check_steps = 0;
    int snapshot_steps = 0;
    int bench_steps = 0;
    int episodes = 5;
    std::string out;
    bool observation = false;
    std::vector<std::string> sets;
  };
  auto options = std::make_shared<Options>();
  std::vector<Command> commands;

  CLI::App* list =
      app.add_subcommand("list", "List the registered env ids, one per line with a description");
  commands.push_back({list, [] { return run_list(); }});

  CLI::App* info = app.add_subcommand(
      "info", "Show an env's spaces, metadata and config keys (types, defaults)");
  info->add_option("id", options->id, "Env id, e.g. GridWorld-v0")->required();
  add_set_option(*info, options->sets);
  commands.push_back({info, [options] { return run_info(options->id, options->sets); }});

  CLI::App* check = app.add_subcommand(
      "check",
      "Run the env checker; exit 0 when every check passes, 1 otherwise (failures printed)");
  check->add_option("id", options->id, "Env id, e.g. GridWorld-v0")->required();
  check->add_option("--seed", options->seed, "Seed for resets and random actions")
      ->capture_default_str();
  check->add_option("--steps", options->check_steps, "Random steps per checked trajectory")
      ->default_val(100)
      ->check(CLI::PositiveNumber);
  add_set_option(*check, options->sets);
  commands.push_back({check, [options] {
                        return run_check(options->id, options->seed, options->check_steps,
                                         options->sets);
                      }});

  CLI::App* snapshot = app.add_subcommand("snapshot",
                                          "Reset with a seed, take K seeded random actions, write "
                                          "render() (or the observation) as a PNG");
  snapshot->add_option("id", options->id, "Env id, e.g. GridWorld-v0")->required();
  snapshot->add_option("--seed", options->seed, "Seed for the reset and the random actions")
      ->required();
  snapshot->add_option("--out", options->out, "PNG file to write (folders are created)")
      ->required();
  snapshot
      ->add_option("--steps", options->snapshot_steps, "Random actions before the frame is taken")
      ->default_val(0)
      ->check(CLI::NonNegativeNumber);
  snapshot->add_flag(
      "--observation", options->observation,
      "Write the observation's \"pixels\" (what the agent sees) instead of render()");
  add_set_option(*snapshot, options->sets);
  commands.push_back({snapshot, [options] {
                        return run_snapshot(options->id, options->seed, options->snapshot_steps,
                                            options->out, options->observation, options->sets);
                      }});

  CLI::App* rollout = app.add_subcommand(
      "rollout", "Run a uniform random policy for some episodes and print each return");
  rollout->add_option("id", options->id, "Env id, e.g. GridWorld-v0")->required();
  rollout->add_option("--seed", options->seed, "Seed for the first reset and the random actions")
      ->capture_default_str();
  rollout->add_option("--episodes", options->episodes, "Episodes to run")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  rollout->add_option("--snapshot", options->out,
                      "Write the last episode's final frame to this PNG");
  add_set_option(*rollout, options->sets);
  commands.push_back({rollout, [options] {
                        return run_rollout(options->id, options->seed, options->episodes,
                                           options->out, options->sets);
                      }});
  CLI::App* bench = app.add_subcommand(
      "bench",
      "Step an env with seeded random actions (resetting when done) and print steps_per_s= for "
      "physics + "
      "render + observation, one thread (--set obs_mode=state for physics alone)");
  bench->add_option("id", options->id, "Env id, e.g. CartPoleSwingup-v0")->required();
  bench->add_option("--steps", options->bench_steps, "Steps to time")
      ->default_val(2000)
      ->check(CLI::PositiveNumber);
  bench->add_option("--seed", options->seed, "Seed for the reset and the random actions")
      ->capture_default_str();
  add_set_option(*bench, options->sets);
  commands.push_back({bench, [options] {
                        return run_bench(options->id, options->seed, options->bench_steps,
                                         options->sets);
                      }});
  return commands;
}

}  // namespace pixelgym::cli
