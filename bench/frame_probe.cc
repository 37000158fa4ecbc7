// Do an env's frames carry its task? Renders frames under random actions with the ground truth
// read from the simulation, trains a small CNN on them (supervised, 1 torch thread) and prints its
// error on frames of held-out episodes beside the error of predicting the training mean.
//
// usage: frame_probe --env ID[,ID...] [--size 64] [--msaa 0] [--grey] [--frames 20000]
//                    [--stride 5] [--episode-steps 200] [--updates 1500] [--train-seconds 600]
//                    [--seed 0]
//                    [--camera NAME] [--png PATH]
//
//   cart-pole ids: the network predicts (sin, cos) of the pole angle and the cart position;
//                  printed: angle error in degrees (median, 90th percentile) and cart error in m.
//   reacher ids:   it predicts the fingertip-to-target vector (the state's to_target), the
//                  fingertip and the target positions; printed: each error in m (median, p90)
//                  and the to_target error as a fraction of the target radius.
//
// Several ids (comma-separated) alternate by episode. Each episode resets with a fresh seed and
// takes `episode-steps` random control steps, keeping one frame every `stride` control steps (the
// env runs with action_repeat = stride, so only kept frames are drawn). Episodes are split 80/20
// into training and held-out frames, so no held-out frame is a neighbour of a training one.
// --png writes the first 16 held-out frames, 4x enlarged, so a person can look at them.
// docs/experiments/frame-probe.md has the commands and results.
#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/tasks/cartpole.h"
#include "pixelgym/envs/tasks/pixel_env.h"
#include "pixelgym/envs/tasks/reacher.h"
#include "pixelgym/render/image_io.h"

namespace {

using pixelgym::Env;
using pixelgym::PixelEnv;

constexpr double kPi = 3.14159265358979323846;

struct Options {
  std::vector<std::string> envs;
  int size = 64;
  int msaa = 0;
  bool grey = false;
  int frames = 20000;
  int stride = 5;
  int episode_steps = 200;
  int updates = 1500;
  double train_seconds = 600.0;
  std::uint64_t seed = 0;
  std::string camera;
  std::string png;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument("frame_probe: " + flag + " needs a value");
      return argv[++i];
    };
    if (flag == "--env") {
      std::stringstream list(value());
      for (std::string id; std::getline(list, id, ',');) o.envs.push_back(id);
    } else if (flag == "--size") {
      o.size = std::stoi(value());
    } else if (flag == "--msaa") {
      o.msaa = std::stoi(value());
    } else if (flag == "--grey") {
      o.grey = true;
    } else if (flag == "--frames") {
      o.frames = std::stoi(value());
    } else if (flag == "--stride") {
      o.stride = std::stoi(value());
    } else if (flag == "--episode-steps") {
      o.episode_steps = std::stoi(value());
    } else if (flag == "--updates") {
      o.updates = std::stoi(value());
    } else if (flag == "--train-seconds") {
      o.train_seconds = std::stod(value());
    } else if (flag == "--seed") {
      o.seed = std::stoull(value());
    } else if (flag == "--camera") {
      o.camera = value();
    } else if (flag == "--png") {
      o.png = value();
    } else {
      throw std::invalid_argument("frame_probe: unknown flag " + flag);
    }
  }
  if (o.envs.empty()) throw std::invalid_argument("frame_probe: --env ID is required");
  return o;
}

// What the network predicts for one kind of task, read from the simulation.
enum class Kind { kCartPole, kReacher };

Kind kind_of(const Env& env) {
  const auto& task = static_cast<const PixelEnv&>(const_cast<Env&>(env).unwrapped()).task();
  if (dynamic_cast<const pixelgym::CartPoleTask*>(&task) != nullptr) return Kind::kCartPole;
  if (dynamic_cast<const pixelgym::ReacherTask*>(&task) != nullptr) return Kind::kReacher;
  throw std::invalid_argument("frame_probe: only cart-pole and reacher ids are probed");
}

// cart-pole: sin, cos of the pole angle, cart position. reacher: to_target (2), fingertip (2),
// target (2), all in the ground plane, m.
std::vector<float> truth(Env& env, Kind kind) {
  auto& pixel_env = static_cast<PixelEnv&>(env.unwrapped());
  const auto& world = pixel_env.world();
  if (kind == Kind::kCartPole) {
    const auto& task = static_cast<const pixelgym::CartPoleTask&>(pixel_env.task());
    const double angle = task.pole_angle(world);
    return {static_cast<float>(std::sin(angle)), static_cast<float>(std::cos(angle)),
            static_cast<float>(task.cart_position(world))};
  }
  const auto& task = static_cast<const pixelgym::ReacherTask&>(pixel_env.task());
  const Eigen::Vector3d tip = task.fingertip(world);
  const Eigen::Vector3d target = task.target(world);
  return {static_cast<float>(target.x() - tip.x()),
          static_cast<float>(target.y() - tip.y()),
          static_cast<float>(tip.x()),
          static_cast<float>(tip.y()),
          static_cast<float>(target.x()),
          static_cast<float>(target.y())};
}

struct Dataset {
  torch::Tensor frames;   // (N, C, H, W) uint8
  torch::Tensor targets;  // (N, K) float32
  torch::Tensor episode;  // (N,) int64
  double target_radius_m = 0.0;
};

Dataset collect(const Options& o, Kind& kind, double& seconds) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::unique_ptr<Env>> envs;
  for (const std::string& id : o.envs) {
    pixelgym::Params kwargs{
        {"width", o.size},      {"height", o.size},          {"msaa", o.msaa},
        {"obs_mode", "pixels"}, {"action_repeat", o.stride}, {"max_episode_steps", 0}};
    if (!o.camera.empty()) kwargs.insert_or_assign("camera", pixelgym::Param(o.camera));
    envs.push_back(pixelgym::make(id, kwargs));
  }
  kind = kind_of(*envs.front());
  for (const auto& env : envs) {
    if (kind_of(*env) != kind) throw std::invalid_argument("frame_probe: mix of task kinds");
  }
  const int channels = o.grey ? 1 : 3;
  const int per_episode = std::max(1, o.episode_steps / o.stride);
  Dataset data;
  data.frames = torch::empty({o.frames, channels, o.size, o.size}, torch::kUInt8);
  data.targets = torch::empty({o.frames, kind == Kind::kCartPole ? 3 : 6}, torch::kFloat32);
  data.episode = torch::empty({o.frames}, torch::kInt64);
  auto frames = data.frames.accessor<std::uint8_t, 4>();
  auto targets = data.targets.accessor<float, 2>();
  pixelgym::Rng rng(o.seed);
  int n = 0;
  for (std::int64_t episode = 0; n < o.frames; ++episode) {
    Env& env = *envs[static_cast<std::size_t>(episode) % envs.size()];
    pixelgym::Value obs = env.reset(o.seed * 1000003 + static_cast<std::uint64_t>(episode)).obs;
    for (int k = 0; k < per_episode && n < o.frames; ++k) {
      obs = env.step(env.action_space().sample(rng)).obs;
      const pixelgym::Array& pixels = obs.dict().at("pixels").array();
      const std::uint8_t* rgb = pixels.data<std::uint8_t>();
      for (int y = 0; y < o.size; ++y) {
        for (int x = 0; x < o.size; ++x) {
          const std::uint8_t* p = rgb + (static_cast<std::ptrdiff_t>(y) * o.size + x) * 3;
          if (o.grey) {
            // ITU-R BT.601 luma, as OpenCV's RGB2GRAY (the grayscale wrapper) weighs it.
            frames[n][0][y][x] =
                static_cast<std::uint8_t>(std::lround(0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]));
          } else {
            for (int c = 0; c < 3; ++c) frames[n][c][y][x] = p[c];
          }
        }
      }
      const std::vector<float> t = truth(env, kind);
      for (std::size_t j = 0; j < t.size(); ++j) targets[n][static_cast<std::int64_t>(j)] = t[j];
      data.episode[n] = episode;
      ++n;
    }
  }
  if (kind == Kind::kReacher) {
    // The reward's bound: the target radius (-v0) or target + finger radius (-v1).
    auto& pixel_env = static_cast<PixelEnv&>(envs.front()->unwrapped());
    data.target_radius_m =
        static_cast<const pixelgym::ReacherTask&>(pixel_env.task()).reward_radius_m();
  }
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return data;
}

struct Net : torch::nn::Module {
  Net(int channels, int size, int outputs) {
    conv1 = register_module("conv1",
                            torch::nn::Conv2d(torch::nn::Conv2dOptions(channels, 32, 3).stride(2)));
    conv2 =
        register_module("conv2", torch::nn::Conv2d(torch::nn::Conv2dOptions(32, 32, 3).stride(2)));
    conv3 = register_module("conv3", torch::nn::Conv2d(torch::nn::Conv2dOptions(32, 32, 3)));
    conv4 =
        register_module("conv4", torch::nn::Conv2d(torch::nn::Conv2dOptions(32, 32, 3).stride(2)));
    const torch::Tensor probe = features(torch::zeros({1, channels, size, size}));
    fc1 = register_module("fc1", torch::nn::Linear(probe.size(1), 256));
    fc2 = register_module("fc2", torch::nn::Linear(256, outputs));
  }
  torch::Tensor features(torch::Tensor x) {
    x = torch::relu(conv1->forward(x));
    x = torch::relu(conv2->forward(x));
    x = torch::relu(conv3->forward(x));
    x = torch::relu(conv4->forward(x));
    return x.flatten(1);
  }
  torch::Tensor forward(torch::Tensor x) {
    return fc2->forward(torch::relu(fc1->forward(features(x))));
  }
  torch::nn::Conv2d conv1{nullptr}, conv2{nullptr}, conv3{nullptr}, conv4{nullptr};
  torch::nn::Linear fc1{nullptr}, fc2{nullptr};
};

torch::Tensor to_input(const torch::Tensor& frames) {
  return frames.to(torch::kFloat32).div(255.0).sub(0.5);
}

double percentile(torch::Tensor values, double q) {
  return values.flatten().to(torch::kFloat64).quantile(q).item<double>();
}

void write_sheet(const std::string& path, const torch::Tensor& frames) {
  const int count = static_cast<int>(std::min<std::int64_t>(16, frames.size(0)));
  const int c = static_cast<int>(frames.size(1));
  const int s = static_cast<int>(frames.size(2));
  constexpr int kScale = 4;
  const int cols = 8;
  const int rows = (count + cols - 1) / cols;
  const int w = cols * s * kScale;
  const int h = rows * s * kScale;
  std::vector<std::uint8_t> sheet(static_cast<std::size_t>(w) * h * 3, 0);
  auto f = frames.accessor<std::uint8_t, 4>();
  for (int i = 0; i < count; ++i) {
    for (int y = 0; y < s * kScale; ++y) {
      for (int x = 0; x < s * kScale; ++x) {
        const int px = (i % cols) * s * kScale + x;
        const int py = (i / cols) * s * kScale + y;
        for (int ch = 0; ch < 3; ++ch) {
          sheet[(static_cast<std::size_t>(py) * w + px) * 3 + ch] =
              f[i][c == 1 ? 0 : ch][y / kScale][x / kScale];
        }
      }
    }
  }
  pixelgym::render::write_png(path, {sheet.data(), h, w, 3});
}

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  torch::set_num_threads(1);
  torch::manual_seed(static_cast<std::uint64_t>(o.seed));

  Kind kind = Kind::kCartPole;
  double collect_seconds = 0.0;
  Dataset data = collect(o, kind, collect_seconds);
  const std::int64_t episodes = data.episode.max().item<std::int64_t>() + 1;
  const torch::Tensor is_test = data.episode >= (episodes * 4) / 5;
  const torch::Tensor train_idx = torch::nonzero(~is_test).flatten();
  const torch::Tensor test_idx = torch::nonzero(is_test).flatten();
  const torch::Tensor train_x = data.frames.index_select(0, train_idx);
  const torch::Tensor test_x = data.frames.index_select(0, test_idx);
  const torch::Tensor train_y = data.targets.index_select(0, train_idx);
  const torch::Tensor test_y = data.targets.index_select(0, test_idx);
  if (!o.png.empty()) write_sheet(o.png, test_x);

  // Targets standardized with the training set's mean and std; the mean is the baseline.
  const torch::Tensor mean = train_y.mean(0);
  const torch::Tensor std = train_y.std(0).clamp_min(1e-6);
  const torch::Tensor train_z = (train_y - mean) / std;

  Net net(static_cast<int>(train_x.size(1)), o.size, static_cast<int>(train_y.size(1)));
  torch::optim::Adam optimizer(net.parameters(), torch::optim::AdamOptions(1e-3));
  const std::int64_t batch = 64;
  const std::int64_t n_train = train_x.size(0);
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::int64_t updates = 0;
  double epochs = 0.0;
  // `updates` Adam steps of 64 frames (fewer if --train-seconds runs out first); the learning
  // rate falls from 1e-3 to 1e-4 on a cosine over whichever budget is nearer its end.
  const auto running = [&] { return updates < o.updates && elapsed() < o.train_seconds; };
  while (running()) {
    const torch::Tensor order = torch::randperm(n_train, torch::kInt64);
    for (std::int64_t b = 0; b + batch <= n_train && running(); b += batch) {
      const double progress =
          std::min(1.0, std::max(elapsed() / o.train_seconds,
                                 static_cast<double>(updates) / static_cast<double>(o.updates)));
      const double lr = 1e-4 + 0.5 * (1e-3 - 1e-4) * (1.0 + std::cos(kPi * progress));
      for (auto& group : optimizer.param_groups()) {
        static_cast<torch::optim::AdamOptions&>(group.options()).lr(lr);
      }
      const torch::Tensor idx = order.slice(0, b, b + batch);
      const torch::Tensor loss = torch::mse_loss(
          net.forward(to_input(train_x.index_select(0, idx))), train_z.index_select(0, idx));
      optimizer.zero_grad();
      loss.backward();
      optimizer.step();
      ++updates;
      epochs += static_cast<double>(batch) / static_cast<double>(n_train);
    }
  }
  const double train_seconds = elapsed();

  torch::NoGradGuard no_grad;
  net.eval();
  std::vector<torch::Tensor> chunks;
  for (std::int64_t b = 0; b < test_x.size(0); b += 256) {
    chunks.push_back(net.forward(to_input(test_x.slice(0, b, b + 256))));
  }
  const torch::Tensor predicted = torch::cat(chunks) * std + mean;
  const torch::Tensor baseline = mean.unsqueeze(0).expand_as(test_y);

  std::printf(
      "env=%s size=%d msaa=%d colour=%s camera=%s frames=%d train=%lld test=%lld "
      "collect_s=%.0f train_s=%.0f updates=%lld epochs=%.1f\n",
      [&] {
        std::string ids;
        for (const auto& id : o.envs) ids += (ids.empty() ? "" : ",") + id;
        return ids;
      }()
          .c_str(),
      o.size, o.msaa, o.grey ? "grey" : "rgb", o.camera.empty() ? "default" : o.camera.c_str(),
      o.frames, static_cast<long long>(train_x.size(0)), static_cast<long long>(test_x.size(0)),
      collect_seconds, train_seconds, static_cast<long long>(updates), epochs);
  for (const auto& [name, p] : {std::pair<const char*, torch::Tensor>{"cnn", predicted},
                                std::pair<const char*, torch::Tensor>{"mean", baseline}}) {
    if (kind == Kind::kCartPole) {
      const torch::Tensor true_angle = torch::atan2(test_y.select(1, 0), test_y.select(1, 1));
      const torch::Tensor angle = torch::atan2(p.select(1, 0), p.select(1, 1));
      const torch::Tensor d = torch::remainder(angle - true_angle + kPi, 2 * kPi) - kPi;
      const torch::Tensor deg = d.abs() * (180.0 / kPi);
      const torch::Tensor cart = (p.select(1, 2) - test_y.select(1, 2)).abs();
      // The same split by where the pole points: above the hinge (|angle| <= 90 degrees, against
      // the sky) or below it (against the floor, where swing-up starts).
      const torch::Tensor upper = true_angle.abs() <= kPi / 2;
      const torch::Tensor deg_upper = deg.masked_select(upper);
      const torch::Tensor deg_lower = deg.masked_select(~upper);
      std::printf(
          "  %-4s angle_err_deg median=%.2f p90=%.2f  cart_err_m median=%.4f p90=%.4f  "
          "pole_up(%lld frames) angle_err_deg median=%.2f p90=%.2f  pole_down(%lld frames) "
          "angle_err_deg median=%.2f p90=%.2f\n",
          name, percentile(deg, 0.5), percentile(deg, 0.9), percentile(cart, 0.5),
          percentile(cart, 0.9), static_cast<long long>(deg_upper.numel()),
          percentile(deg_upper, 0.5), percentile(deg_upper, 0.9),
          static_cast<long long>(deg_lower.numel()), percentile(deg_lower, 0.5),
          percentile(deg_lower, 0.9));
    } else {
      const auto err = [&](int j) {
        return (p.slice(1, j, j + 2) - test_y.slice(1, j, j + 2)).norm(2, 1);
      };
      const torch::Tensor to_target = err(0);
      const torch::Tensor tip = err(2);
      const torch::Tensor target = err(4);
      const double r = data.target_radius_m;
      std::printf(
          "  %-4s to_target_err_m median=%.4f p90=%.4f (in reward radii %.3f: median=%.2f "
          "p90=%.2f, within=%.1f%%)  fingertip_err_m median=%.4f p90=%.4f  target_err_m "
          "median=%.4f p90=%.4f\n",
          name, percentile(to_target, 0.5), percentile(to_target, 0.9), r,
          percentile(to_target, 0.5) / r, percentile(to_target, 0.9) / r,
          100.0 * (to_target < r).to(torch::kFloat64).mean().item<double>(), percentile(tip, 0.5),
          percentile(tip, 0.9), percentile(target, 0.5), percentile(target, 0.9));
    }
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "frame_probe: %s\n", e.what());
  return 1;
}
