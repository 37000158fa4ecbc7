#include "pixelgym/envs/tasks/grid_world.h"

#include <algorithm>
#include <stdexcept>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"

namespace pixelgym {
namespace {

using Rgb = std::array<std::uint8_t, 3>;
constexpr Rgb kFloorColor{236, 236, 230};
constexpr Rgb kLineColor{70, 70, 78};
constexpr Rgb kWallColor{128, 128, 128};
constexpr Rgb kGoalColor{46, 160, 67};
constexpr Rgb kAgentColor{31, 100, 200};
constexpr int kMinImageSize = 16;
constexpr int kMaxImageSize = 8192;

int read_size(const Params& params, const std::string& key) {
  const std::int64_t value = params.at(key).as_int();
  if (value < kMinImageSize || value > kMaxImageSize) {
    throw std::invalid_argument("GridWorld: " + key + " must be in [" +
                                std::to_string(kMinImageSize) + ", " +
                                std::to_string(kMaxImageSize) + "], got " + std::to_string(value));
  }
  return static_cast<int>(value);
}

// Fills pixels [y0, y1) x [x0, x1) of an (H, W, 3) image.
void fill_rect(Array& image, int y0, int y1, int x0, int x1, Rgb color) {
  const auto width = static_cast<int>(image.shape()[1]);
  std::uint8_t* pixels = image.data<std::uint8_t>();
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x)
      std::copy(color.begin(), color.end(), pixels + (y * width + x) * 3);
  }
}

}  // namespace

std::vector<ParamSpec> GridWorldConfig::params() {
  const GridWorldConfig defaults;
  return {
      {"render_width", defaults.render_width, "width of render() frames in pixels"},
      {"render_height", defaults.render_height, "height of render() frames in pixels"},
      {"obs_mode", defaults.obs_mode,
       "\"index\" (Discrete(16)), \"pixels\" (Dict with an image) or \"rgb\" (the image Box "
       "itself)"},
      {"width", defaults.width, "observation image width for obs_mode \"pixels\" and \"rgb\""},
      {"height", defaults.height, "observation image height for obs_mode \"pixels\" and \"rgb\""}};
}

GridWorldConfig GridWorldConfig::from_params(const Params& params) {
  GridWorldConfig config;
  config.render_width = read_size(params, "render_width");
  config.render_height = read_size(params, "render_height");
  config.width = read_size(params, "width");
  config.height = read_size(params, "height");
  config.obs_mode = params.at("obs_mode").as_string();
  if (config.obs_mode != "index" && config.obs_mode != "pixels" && config.obs_mode != "rgb") {
    throw std::invalid_argument(
        "GridWorld: obs_mode must be \"index\", \"pixels\" or \"rgb\", got \"" + config.obs_mode +
        "\"");
  }
  return config;
}

namespace {

SpacePtr grid_observation_space(const GridWorldConfig& config) {
  if (config.obs_mode == "index") {
    return std::make_shared<spaces::Discrete>(GridWorld::kSize * GridWorld::kSize);
  }
  const auto image = std::make_shared<spaces::Box>(
      0.0, 255.0, Shape{config.height, config.width, 3}, DType::kUInt8);
  if (config.obs_mode == "rgb") return image;
  return std::make_shared<spaces::Dict>(spaces::Dict::Entries{{"pixels", image}});
}

}  // namespace

GridWorld::GridWorld(GridWorldConfig config)
    : config_(config),
      observation_space_(grid_observation_space(config)),
      action_space_(std::make_shared<spaces::Discrete>(4)) {
  metadata_.render_fps = 4.0;
  metadata_.render_shape = Shape{config.render_height, config.render_width, 3};
}

void GridWorld::do_reset(std::optional<std::uint64_t> /*seed*/, const Options& options,
                         ResetResult& out) {
  if (!options.empty()) {
    throw std::invalid_argument(name() + ": reset() takes no options, got \"" +
                                options.begin()->first + "\"");
  }
  agent_ = kStart;
  observe(out.obs);
}

void GridWorld::do_step(const Value& action, StepResult& out) {
  Cell next = agent_;
  switch (static_cast<std::int64_t>(action.array().element_as_double(0))) {
    case kLeft:
      next.col -= 1;
      break;
    case kDown:
      next.row += 1;
      break;
    case kRight:
      next.col += 1;
      break;
    case kUp:
      next.row -= 1;
      break;
    default:
      break;  // unreachable: the action was checked against Discrete(4)
  }
  const bool on_grid = next.row >= 0 && next.row < kSize && next.col >= 0 && next.col < kSize;
  if (on_grid && !(next == kWall)) agent_ = next;

  observe(out.obs);
  out.terminated = agent_ == kGoal;
  out.reward = out.terminated ? kGoalReward : kStepReward;
}

void GridWorld::observe(Value& obs) const {
  if (config_.obs_mode == "pixels") {
    draw(obs.dict().values()[0].array());
  } else if (config_.obs_mode == "rgb") {
    draw(obs.array());
  } else {
    *obs.array().data<std::int64_t>() = agent_.row * kSize + agent_.col;
  }
}

Array GridWorld::do_render() {
  Array image(DType::kUInt8, {config_.render_height, config_.render_width, 3});
  draw(image);
  return image;
}

void GridWorld::draw(Array& image) const {
  const auto height = static_cast<int>(image.shape()[0]);
  const auto width = static_cast<int>(image.shape()[1]);
  fill_rect(image, 0, height, 0, width, kLineColor);
  const int line = std::max(1, std::min(width, height) / 96);
  for (int row = 0; row < kSize; ++row) {
    for (int col = 0; col < kSize; ++col) {
      // Cell bounds inside a border of `line` pixels; the background showing between cells
      // and around the border draws lines 2 * line thick everywhere.
      const int y0 = line + row * (height - 2 * line) / kSize + line;
      const int y1 = line + (row + 1) * (height - 2 * line) / kSize - line;
      const int x0 = line + col * (width - 2 * line) / kSize + line;
      const int x1 = line + (col + 1) * (width - 2 * line) / kSize - line;
      const Cell cell{row, col};
      const Rgb color = cell == kWall ? kWallColor : cell == kGoal ? kGoalColor : kFloorColor;
      fill_rect(image, y0, y1, x0, x1, color);
      if (cell == agent_) {
        // The agent: a disc filling most of its cell.
        const double cy = (y0 + y1) / 2.0;
        const double cx = (x0 + x1) / 2.0;
        const double radius = 0.36 * std::min(y1 - y0, x1 - x0);
        std::uint8_t* pixels = image.data<std::uint8_t>();
        for (int y = y0; y < y1; ++y) {
          for (int x = x0; x < x1; ++x) {
            const double dy = y + 0.5 - cy;
            const double dx = x + 0.5 - cx;
            if (dy * dy + dx * dx <= radius * radius) {
              std::copy(kAgentColor.begin(), kAgentColor.end(), pixels + (y * width + x) * 3);
            }
          }
        }
      }
    }
  }
}

EnvSpec GridWorld::spec_v0() {
  EnvSpec spec;
  spec.id = "GridWorld-v0";
  spec.description = "4x4 grid: reach the green goal, avoid the wall; Discrete(4) moves";
  spec.params = GridWorldConfig::params();
  spec.max_episode_steps = kMaxEpisodeSteps;
  spec.factory = [](const Params& kwargs, const MakeOptions& /*options: draws on the CPU*/) {
    return std::make_unique<GridWorld>(GridWorldConfig::from_params(kwargs));
  };
  spec.describe = [](const Params& kwargs) {
    // Building a GridWorld is cheap (no world, no GL): its spaces are the description.
    const GridWorld env(GridWorldConfig::from_params(kwargs));
    EnvDescription description;
    description.observation_space = env.observation_space_;
    description.action_space = env.action_space_;
    description.metadata = env.metadata_;
    description.max_episode_steps = kMaxEpisodeSteps;
    return description;
  };
  return spec;
}

}  // namespace pixelgym
