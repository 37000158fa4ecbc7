// pixelgym list | info | check | snapshot | rollout | bench
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "examples/pixelgym/cli.h"
#include "pixelgym/envs/checker.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rollout.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/suggestions.h"
#include "pixelgym/envs/vector/async_vector_env.h"
#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/envs/vector/process_vector_env.h"
#include "pixelgym/render/context.h"
#include "pixelgym/testing/snapshot.h"
#include "pixelgym/wrappers/wrapper_spec.h"

namespace pixelgym::cli {
namespace {

std::string join(const std::vector<std::string>& items) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return text;
}

// Rows printed as left-aligned columns as wide as their widest cell, two spaces apart; the last
// column is not padded.
void print_table(std::ostream& out, const std::vector<std::vector<std::string>>& rows,
                 const std::string& indent) {
  std::vector<std::size_t> widths;
  for (const auto& row : rows) {
    widths.resize(std::max(widths.size(), row.size()));
    for (std::size_t i = 0; i < row.size(); ++i) widths[i] = std::max(widths[i], row[i].size());
  }
  for (const auto& row : rows) {
    std::string line = indent;
    for (std::size_t i = 0; i < row.size(); ++i) {
      line += row[i];
      if (i + 1 < row.size()) line += std::string(widths[i] - row[i].size() + 2, ' ');
    }
    out << line << "\n";
  }
}

// What list and wrappers take: nothing.
struct NoArguments {};

// --- list ---

void declare_list(CLI::App& list, NoArguments& /*args*/) {
  list.description("List the registered env ids, one per line with a description");
}

int run_list(const NoArguments& /*args*/) {
  std::vector<std::vector<std::string>> rows;
  for (const std::string& id : registered_ids()) {
    rows.push_back({id, default_registry().spec(id)->description});
  }
  print_table(std::cout, rows, "");
  return 0;
}

// --- wrappers ---

void declare_wrappers(CLI::App& command, NoArguments& /*args*/) {
  command.description("List the wrappers that --wrap accepts, with their arguments and defaults");
  command.footer(
      "A spec is NAME or NAME=ARGS; ARGS are comma-separated, each a value (taken by the "
      "parameters in the order shown) or param=value. Examples: --wrap resize=64x64 --wrap "
      "grayscale --wrap time_limit=500");
}

int run_wrappers(const NoArguments& /*args*/) {
  std::vector<std::vector<std::string>> rows;
  for (const wrappers::WrapperSpecHelp& help : wrappers::wrapper_spec_help()) {
    std::string summary = help.summary;
    if (!help.aliases.empty()) summary += " (also: " + join_names(help.aliases) + ")";
    rows.push_back({help.usage, summary});
  }
  print_table(std::cout, rows, "");
  return 0;
}

// --- info ---

struct InfoArguments : EnvArguments {};

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// A Box's valid range: "[low, high]" when every element shares it, else each element's.
std::string box_range(const spaces::Box& box) {
  const auto& low = box.low();
  const auto& high = box.high();
  const bool uniform =
      std::all_of(low.begin(), low.end(), [&](double v) { return v == low[0]; }) &&
      std::all_of(high.begin(), high.end(), [&](double v) { return v == high[0]; });
  if (uniform && !low.empty()) return "[" + number(low[0]) + ", " + number(high[0]) + "]";
  std::string text;
  for (std::size_t i = 0; i < low.size(); ++i) {
    text += (i == 0 ? "" : ", ") + std::string("[") + number(low[i]) + ", " + number(high[i]) + "]";
  }
  return "per element " + text;
}

// One row per observation key (one for the whole observation when it is not a Dict): the key,
// dtype, shape and valid range.
std::vector<std::vector<std::string>> observation_rows(const Space& space) {
  const auto row = [](const std::string& key, const Space& sub) {
    std::string range = sub.to_string();
    if (const auto* box = dynamic_cast<const spaces::Box*>(&sub)) range = box_range(*box);
    if (const auto* discrete = dynamic_cast<const spaces::Discrete*>(&sub)) {
      range = "{" + std::to_string(discrete->start()) + ", ..., " +
              std::to_string(discrete->start() + discrete->n() - 1) + "}";
    }
    return std::vector<std::string>{key, sub.dtype() ? dtype_name(*sub.dtype()) : "",
                                    sub.shape() ? shape_to_string(*sub.shape()) : "", range};
  };
  std::vector<std::vector<std::string>> rows = {{"key", "dtype", "shape", "valid range"}};
  if (const auto* dict = dynamic_cast<const spaces::Dict*>(&space)) {
    for (const auto& [key, sub] : dict->entries()) rows.push_back(row(key, *sub));
  } else {
    rows.push_back(row("(all)", space));
  }
  return rows;
}

// The OpenGL a pixel env of these --set kwargs would draw with: its backend and GL_RENDERER,
// from a context made for the purpose; or "none" and why, when no backend works here (info
// still answers everything else).
std::string renderer_line(const std::vector<std::string>& sets) {
  std::string requested = "auto";
  for (const std::string& set : sets) {
    if (set.rfind("render_backend=", 0) == 0) requested = set.substr(15);
  }
  try {
    render::Context context(render::parse_gl_backend(requested, "render_backend"));
    return render::gl_backend_name(context.backend()) + " (" + context.description() +
           "; render_backend=" + requested + ")";
  } catch (const std::exception& error) {
    return "none works here (render_backend=" + requested + "): " + error.what();
  }
}

// From the spec and Registry::describe: no env or Bullet world is built (a GL context only to
// name the renderer of a pixel env).
int run_info(const InfoArguments& args) {
  const EnvDescription description = describe_env(args.id, args.sets, args.wraps);
  // The time limit the kwargs give, before a time_limit wrapper.
  const std::optional<std::int64_t> kwarg_limit =
      describe_env(args.id, args.sets).max_episode_steps;
  const auto spec = default_registry().spec(args.id);
  const auto limit = [](const std::optional<std::int64_t>& steps) {
    return steps ? std::to_string(*steps) : std::string("none");
  };
  std::string cameras = "none";
  if (!description.cameras.empty()) {
    cameras = description.cameras[0] + " (default)";
    for (std::size_t i = 1; i < description.cameras.size(); ++i) {
      cameras += ", " + description.cameras[i];
    }
  }
  std::cout << args.id << ": " << spec->description << "\n";
  for (const std::string& wrap : args.wraps) std::cout << "wrapped:           " << wrap << "\n";
  std::cout << "observation_space: " << description.observation_space->to_string() << "\n";
  print_table(std::cout, observation_rows(*description.observation_space), "  ");
  std::cout << "action_space:      " << description.action_space->to_string() << "\n"
            << "cameras:           " << cameras << "\n"
            << "render_modes:      " << join(description.metadata.render_modes) << "\n"
            << "render_fps:        " << description.metadata.render_fps << "\n"
            << "max_episode_steps: " << limit(description.max_episode_steps) << "\n";
  const bool draws =
      std::any_of(spec->params.begin(), spec->params.end(),
                  [](const ParamSpec& param) { return param.name == "render_backend"; });
  if (draws) std::cout << "renderer:          " << renderer_line(args.sets) << "\n";
  std::cout << "config (--set key=value):\n";
  std::vector<std::vector<std::string>> rows = {{"key", "type", "default", "description"}};
  for (const ParamSpec& param : spec->params) {
    rows.push_back(
        {param.name, param_type_name(param.type()), param.default_value.to_string(), param.doc});
  }
  // Its default follows the other kwargs (a pixel task's action_repeat), as describe gives it.
  rows.push_back({"max_episode_steps", "int", kwarg_limit ? std::to_string(*kwarg_limit) : "0",
                  "steps before TimeLimit truncates; 0 for no limit"});
  print_table(std::cout, rows, "  ");
  return 0;
}

void declare_info(CLI::App& info, InfoArguments& args) {
  info.description(
      "Show an env's spaces (under the --wrap wrappers, if any), metadata and config keys "
      "(types, defaults), without making the env");
  add_id_argument(info, args.id, "GridWorld-v0");
  add_env_options(info, args);
}

// --- check ---

struct CheckArguments : EnvArguments {
  std::uint64_t seed = 0;
  int steps = 100;
};

int run_check(const CheckArguments& args) {
  std::unique_ptr<Env> env = make_env(args.id, args.sets, args.wraps);
  const CheckReport report = check_env(*env, {args.seed, args.steps});
  for (const CheckResult& result : report.results) {
    std::cout << (result.passed ? "ok    " : "FAIL  ") << result.name;
    if (!result.passed) std::cout << ": " << result.reason;
    std::cout << "\n";
  }
  const std::size_t failed = report.failures().size();
  if (failed == 0) {
    std::cout << args.id << ": all " << report.results.size() << " checks passed\n";
    return 0;
  }
  std::cout << args.id << ": " << failed << " of " << report.results.size() << " checks failed\n";
  return kExitFailure;
}

void declare_check(CLI::App& check, CheckArguments& args) {
  check.description(
      "Run the env checker; exit 0 when every check passes, 1 otherwise (failures printed)");
  add_id_argument(check, args.id, "GridWorld-v0");
  add_seed_option(check, args.seed, "Seed for resets and random actions");
  add_checked_option(check, "--steps", args.steps, "Random steps per checked trajectory",
                     integer_in(1));
  add_env_options(check, args);
}

// --- snapshot ---

struct SnapshotArguments : EnvArguments {
  std::uint64_t seed = 0;
  int steps = 0;
  std::string out;
  std::string compare;
  bool observation = false;
};

// The observation's image as an (H, W, 3) picture: the "pixels" entry of a Dict observation (its
// "pixels/<camera>" entries side by side, the first leftmost), or a bare uint8 observation. A gray
// image ((H, W) or (H, W, 1)) becomes grey RGB; planes on a leading axis ((k, H, W): stacked gray
// frames or channel-first planes; (k, H, W, C): stacked frames) are laid side by side, the first
// leftmost. Throws UsageError for anything else.
Array observation_picture(const std::string& id, const Value& obs) {
  // Several cameras ("pixels/<name>" entries, kwarg cameras): their pictures side by side.
  if (obs.is_dict() && !obs.dict().contains("pixels")) {
    std::vector<Array> pictures;
    for (const std::string& key : obs.dict().keys()) {
      if (key.rfind("pixels/", 0) == 0)
        pictures.push_back(observation_picture(id, obs.dict().at(key)));
    }
    if (!pictures.empty()) {
      const std::int64_t height = pictures[0].shape()[0];
      std::int64_t width = 0;
      for (const Array& picture : pictures) width += picture.shape()[1];
      Array row(DType::kUInt8, {height, width, 3});
      std::int64_t left = 0;
      for (const Array& picture : pictures) {
        const std::int64_t w = picture.shape()[1];
        for (std::int64_t y = 0; y < height; ++y) {
          std::copy_n(picture.data<std::uint8_t>() + y * w * 3, w * 3,
                      row.data<std::uint8_t>() + (y * width + left) * 3);
        }
        left += w;
      }
      return row;
    }
  }
  const Array* image = nullptr;
  if (obs.is_dict() && obs.dict().contains("pixels") && obs.dict().at("pixels").is_array()) {
    image = &obs.dict().at("pixels").array();
  } else if (obs.is_array()) {
    image = &obs.array();
  }
  if (image == nullptr || image->dtype() != DType::kUInt8 || image->ndim() < 2 ||
      image->ndim() > 4) {
    throw UsageError(id +
                     ": --observation needs a uint8 image observation or a \"pixels\" entry "
                     "(try --set obs_mode=pixels), got " +
                     obs.to_string());
  }
  const Shape& shape = image->shape();
  const std::size_t rank = shape.size();
  const bool has_channels = rank >= 3 && (shape[rank - 1] == 1 || shape[rank - 1] == 3);
  // Planes side by side: (planes, height, width, channels).
  const std::int64_t planes = rank == 4 || (rank == 3 && !has_channels) ? shape[0] : 1;
  const std::int64_t height = shape[planes > 1 || rank == 4 ? 1 : 0];
  const std::int64_t width = shape[planes > 1 || rank == 4 ? 2 : 1];
  const std::int64_t channels = rank == 4 || (rank == 3 && has_channels) ? shape[rank - 1] : 1;
  if (rank == 4 && !has_channels) {
    throw UsageError(id + ": --observation cannot show an image of shape " +
                     shape_to_string(shape) + " (the last axis must be 1 or 3 channels)");
  }
  Array picture(DType::kUInt8, {height, width * planes, 3});
  const std::uint8_t* from = image->data<std::uint8_t>();
  std::uint8_t* to = picture.data<std::uint8_t>();
  for (std::int64_t p = 0; p < planes; ++p) {
    for (std::int64_t y = 0; y < height; ++y) {
      for (std::int64_t x = 0; x < width; ++x) {
        const std::uint8_t* pixel = from + ((p * height + y) * width + x) * channels;
        std::uint8_t* out = to + (y * width * planes + p * width + x) * 3;
        for (int c = 0; c < 3; ++c) out[c] = pixel[channels == 3 ? c : 0];
      }
    }
  }
  return picture;
}

// `snapshot --compare GOLDEN`: the frame against the golden under the default tolerance of
// testing/snapshot.h; 0 on a match, 1 with the figures and the diff image's path otherwise.
int compare_snapshot(const SnapshotArguments& args, const Array& frame,
                     const std::string& description) {
  const testing::SnapshotResult result = testing::compare_to_golden(frame, args.compare);
  if (result.status == testing::SnapshotResult::Status::kUpdated) {
    std::cout << result.message() << " (PIXELGYM_UPDATE_GOLDENS=1; " << description << ")\n";
    return 0;
  }
  if (result.matched()) {
    std::cout << "match: " << result.message() << " (" << description << ")\n";
    return 0;
  }
  std::cerr << "mismatch: " << result.message() << " (" << description << ")\n";
  return kExitFailure;
}

int run_snapshot(const SnapshotArguments& args) {
  if (args.out.empty() && args.compare.empty()) {
    throw UsageError(
        "snapshot: give --out FILE.png (write the frame), --compare GOLDEN.png "
        "(compare it with a golden), or both");
  }
  std::unique_ptr<Env> env = make_env(args.id, args.sets, args.wraps);
  RandomRollout random(*env, args.seed);
  for (int t = 0; t < args.steps; ++t) random.step();
  Array frame;
  if (args.observation) {
    frame = observation_picture(args.id, random.observation());
  } else {
    frame = env->render();
  }
  std::ostringstream description;
  description << frame.shape()[1] << "x" << frame.shape()[0] << " "
              << (args.observation ? "observation" : "render()") << ", " << args.id << ", seed "
              << args.seed << ", " << args.steps << " steps";
  if (!args.out.empty()) {
    write_frame_png(args.out, frame);  // throws naming the path and the OS error
    std::cout << "wrote " << args.out << " (" << description.str() << ")\n";
  }
  const int status = args.compare.empty() ? 0 : compare_snapshot(args, frame, description.str());
  env->close();
  return status;
}

void declare_snapshot(CLI::App& snapshot, SnapshotArguments& args) {
  snapshot.description(
      "Reset with a seed, take K seeded random actions, write render() (or the observation) as a "
      "PNG, or compare it with a golden PNG");
  add_id_argument(snapshot, args.id, "GridWorld-v0");
  add_seed_option(snapshot, args.seed, "Seed for the reset and the random actions");
  snapshot.add_option("--out", args.out, "PNG file to write (folders are created; PNG only)")
      ->check(png_path());
  snapshot
      .add_option("--compare", args.compare,
                  "Golden PNG to compare the frame with (the default tolerance of "
                  "testing/snapshot.h): exit 0 on a match, 1 with the figures and a diff image "
                  "(in $PIXELGYM_SNAPSHOT_OUTPUT_DIR, else ./snapshot_output) otherwise; "
                  "PIXELGYM_UPDATE_GOLDENS=1 writes the golden instead")
      ->check(png_path());
  add_checked_option(snapshot, "--steps", args.steps, "Random actions before the frame is taken",
                     integer_in(0));
  snapshot.add_flag(
      "--observation", args.observation,
      "Take the observation's \"pixels\" (what the agent sees, after any --wrap) instead of "
      "render(); gray images as grey, stacked frames side by side, oldest leftmost, and the "
      "images of several cameras (--set cameras=a,b) side by side");
  add_env_options(snapshot, args);
}

// --- rollout ---

struct RolloutArguments : EnvArguments {
  std::uint64_t seed = 0;
  int episodes = 5;
  std::string snapshot;
};

int run_rollout(const RolloutArguments& args) {
  std::unique_ptr<Env> env = make_env(args.id, args.sets, args.wraps);
  RandomRollout random(*env, args.seed);
  double total = 0.0;
  for (int episode = 0; episode < args.episodes; ++episode) {
    // The last episode is not reset, so that the snapshot is its final frame.
    const EpisodeSummary& summary = random.finish_episode(episode + 1 < args.episodes);
    total += summary.episode_return;
    std::cout << "episode " << episode << ": return=" << summary.episode_return
              << " length=" << summary.length << (summary.terminated ? " terminated" : " truncated")
              << "\n";
  }
  if (!args.snapshot.empty()) write_frame_png(args.snapshot, env->render());
  std::cout << "mean_return=" << total / args.episodes << " episodes=" << args.episodes << "\n";
  if (!args.snapshot.empty()) std::cout << "wrote " << args.snapshot << "\n";
  env->close();
  return 0;
}

void declare_rollout(CLI::App& rollout, RolloutArguments& args) {
  rollout.description("Run a uniform random policy for some episodes and print each return");
  add_id_argument(rollout, args.id, "GridWorld-v0");
  add_seed_option(rollout, args.seed, "Seed for the first reset and the random actions");
  add_checked_option(rollout, "--episodes", args.episodes, "Episodes to run", integer_in(1));
  rollout
      .add_option("--snapshot", args.snapshot,
                  "Write the last episode's final frame to this PNG (PNG only)")
      ->check(png_path());
  add_env_options(rollout, args);
}

// --- bench ---

struct BenchArguments : EnvArguments {
  std::uint64_t seed = 0;
  int steps = 2000;
  int num_envs = 0;  // 0: one Env in a loop; else a vector env
  int threads = 0;   // with num_envs: 0 for SyncVectorEnv, else AsyncVectorEnv's worker threads
  bool threads_given = false;
  int workers = 0;  // with num_envs: ProcessVectorEnv's worker processes (0: none)
  bool workers_given = false;
};

// `num_envs` envs in a vector env, stepped with seeded random actions (a pool of batches drawn
// before timing) until `steps` env steps are done; autoreset NextStep.
int run_vector_bench(const BenchArguments& args) {
  vector::VectorOptions options{
      args.threads == 0 ? vector::VectorMode::kSync : vector::VectorMode::kAsync, args.threads,
      vector::AutoresetMode::kNextStep};
  if (args.workers_given) {
    options.mode = vector::VectorMode::kProcess;
    options.num_workers = args.workers;
  }
  const std::unique_ptr<vector::VectorEnv> env =
      vector::make_vec(args.id, args.num_envs, parse_sets(args.id, args.sets),
                       wrappers::wrapping(args.wraps), options);
  Rng rng(args.seed);
  std::vector<Value> actions;
  for (int k = 0; k < 64; ++k) actions.push_back(env->action_space().sample(rng));
  env->reset(args.seed);
  for (int t = 0; t < 20; ++t) env->step(actions[static_cast<std::size_t>(t) % actions.size()]);
  const int batches = (args.steps + args.num_envs - 1) / args.num_envs;
  std::int64_t resets = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int t = 0; t < batches; ++t) {
    const vector::VectorStepResult& result =
        env->step(actions[static_cast<std::size_t>(t) % actions.size()]);
    for (int i = 0; i < args.num_envs; ++i) {
      resets += result.terminated.data<bool>()[i] || result.truncated.data<bool>()[i] ? 1 : 0;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::int64_t env_steps = static_cast<std::int64_t>(batches) * args.num_envs;
  std::string runner = "SyncVectorEnv, one thread";
  if (const auto* pool = dynamic_cast<const vector::AsyncVectorEnv*>(env.get())) {
    runner = "AsyncVectorEnv, " + std::to_string(pool->num_threads()) + " threads";
  } else if (const auto* workers = dynamic_cast<const vector::ProcessVectorEnv*>(env.get())) {
    runner = "ProcessVectorEnv, " + std::to_string(workers->num_workers()) + " worker processes";
  }
  std::cout << args.id << ": " << env_steps << " env steps (" << batches << " batches of "
            << args.num_envs << " envs, " << resets << " resets) in " << seconds << " s, " << runner
            << "\n";
  std::cout << "steps_per_s=" << static_cast<long>(std::lround(env_steps / seconds)) << "\n";
  env->close();
  return 0;
}

int run_bench(const BenchArguments& args) {
  if (args.threads_given && args.workers_given) {
    throw UsageError("bench --threads " + std::to_string(args.threads) + " --workers " +
                     std::to_string(args.workers) +
                     ": a vector env runs on threads or on worker processes; give one of them");
  }
  if (args.num_envs > 0) return run_vector_bench(args);
  if (args.threads_given || args.workers_given) {
    throw UsageError(std::string("bench ") + (args.threads_given ? "--threads " : "--workers ") +
                     std::to_string(args.threads_given ? args.threads : args.workers) +
                     ": threads and workers step a vector env; give --num-envs N with it");
  }
  std::unique_ptr<Env> env = make_env(args.id, args.sets, args.wraps);
  RandomRollout random(*env, args.seed);
  // Warm up (shader compilation, caches) outside the timed loop.
  for (int t = 0; t < 20; ++t) random.step();
  const std::int64_t episodes_before = random.episodes();
  const auto start = std::chrono::steady_clock::now();
  for (int t = 0; t < args.steps; ++t) random.step();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << args.id << ": " << args.steps << " steps (" << random.episodes() - episodes_before
            << " resets) in " << seconds << " s, one thread\n";
  std::cout << "steps_per_s=" << static_cast<long>(std::lround(args.steps / seconds)) << "\n";
  env->close();
  return 0;
}

void declare_bench(CLI::App& bench, BenchArguments& args) {
  bench.description(
      "Step an env with seeded random actions (resetting when done) and print steps_per_s= for "
      "physics + render + observation, one env on this thread, or with --num-envs N a vector env "
      "of N (--threads T threads, or --workers W processes); --set obs_mode=state for physics "
      "alone");
  add_id_argument(bench, args.id, "CartPoleSwingup-v1");
  add_checked_option(bench, "--steps", args.steps, "Steps to time", integer_in(1));
  add_seed_option(bench, args.seed, "Seed for the reset and the random actions");
  bench
      .add_option("--num-envs", args.num_envs,
                  "Step N envs as one vector env (make_vec) and count steps_per_s= over all of "
                  "them; --steps is then the total of env steps")
      ->check(integer_in(1));
  add_checked_option(bench, "--threads", args.threads,
                     "With --num-envs: 0 for SyncVectorEnv (a loop on this thread), T for an "
                     "AsyncVectorEnv on T threads, this one included (clamped to N); refused "
                     "without --num-envs",
                     integer_in(0))
      ->each([&args](const std::string&) { args.threads_given = true; });
  add_checked_option(bench, "--workers", args.workers,
                     "With --num-envs: a ProcessVectorEnv of W worker processes (0: one per "
                     "core; clamped to N), each stepping its block of envs and writing into "
                     "shared memory; refused without --num-envs or with --threads",
                     integer_in(0))
      ->each([&args](const std::string&) { args.workers_given = true; });
  add_env_options(bench, args);
}

}  // namespace

std::vector<Command> add_env_commands(CLI::App& app) {
  return {add_command(app, "list", declare_list, run_list),
          add_command(app, "wrappers", declare_wrappers, run_wrappers),
          add_command(app, "info", declare_info, run_info),
          add_command(app, "check", declare_check, run_check),
          add_command(app, "snapshot", declare_snapshot, run_snapshot),
          add_command(app, "rollout", declare_rollout, run_rollout),
          add_command(app, "bench", declare_bench, run_bench)};
}

}  // namespace pixelgym::cli
