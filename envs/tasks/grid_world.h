// GridWorld-v0: the 4x4 gridworld every RL course starts from.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/registry.h"

namespace pixelgym {

/// Settings of GridWorld (its `make` kwargs).
struct GridWorldConfig {
  /// Size of `render()` frames in pixels, each in [16, 8192].
  int render_width = 256;
  int render_height = 256;
  /// "index": Discrete(16), the agent's cell; "pixels": Dict{"pixels": (height, width, 3) uint8};
  /// "rgb": that image itself, a bare (height, width, 3) uint8 Box.
  std::string obs_mode = "index";
  /// Observation image size for obs_mode "pixels" and "rgb", each in [16, 8192].
  int width = 84;
  int height = 84;

  /// The kwargs above with their defaults and docs.
  static std::vector<ParamSpec> params();
  /// Reads resolved kwargs. Throws std::invalid_argument for a size outside [16, 8192] or an
  /// unknown obs_mode.
  static GridWorldConfig from_params(const Params& params);
};

/// A 4x4 grid. The agent (blue) starts in the top-left cell; the goal (green) is the
/// bottom-right cell; one wall cell (gray) at row 1, column 1 blocks movement.
///
/// - Actions: Discrete(4), in Gymnasium FrozenLake's order: 0 left, 1 down, 2 right, 3 up. A
///   move into the wall or off the grid leaves the agent where it is.
/// - Observation: Discrete(16), the agent's cell as row * 4 + column; with obs_mode="pixels",
///   Dict{"pixels": (height, width, 3) uint8}, the grid as render() draws it; with
///   obs_mode="rgb", that image as a bare Box.
/// - Reward: +1.0 on the step that reaches the goal, which terminates the episode; -0.04 on
///   every other step.
/// - The registered spec truncates after 50 steps (TimeLimit).
/// The start is fixed, so the generator is not used; seeding still works as for every env.
/// reset() takes no options (std::invalid_argument names the first one given).
class GridWorld final : public Env {
 public:
  /// Rows and columns of the grid.
  static constexpr int kSize = 4;
  /// The actions, as the Discrete(4) action space numbers them.
  enum Action : std::int64_t { kLeft = 0, kDown = 1, kRight = 2, kUp = 3 };
  /// A cell of the grid: row 0 is the top, column 0 the left.
  struct Cell {
    int row;
    int col;
    friend bool operator==(Cell a, Cell b) { return a.row == b.row && a.col == b.col; }
  };
  /// Where the agent starts, the goal and the wall.
  static constexpr Cell kStart{0, 0};
  static constexpr Cell kGoal{3, 3};
  static constexpr Cell kWall{1, 1};
  /// The reward of a step that does not reach the goal, and of the one that does.
  static constexpr double kStepReward = -0.04;
  static constexpr double kGoalReward = 1.0;
  /// The registered spec's time limit, in steps.
  static constexpr std::int64_t kMaxEpisodeSteps = 50;

  /// An env with `config` as given: it is not checked (GridWorldConfig::from_params checks
  /// kwargs), and any obs_mode but "pixels" gives the index observation.
  explicit GridWorld(GridWorldConfig config = {});

  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  const Metadata& metadata() const override { return metadata_; }

  /// Where the agent is now.
  Cell agent() const { return agent_; }

  /// The registry entry for GridWorld-v0.
  static EnvSpec spec_v0();

 protected:
  std::string type_name() const override { return "GridWorld"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;
  Array do_render() override;

 private:
  void observe(Value& obs) const;
  /// Draws the grid into an (H, W, 3) uint8 image.
  void draw(Array& image) const;

  GridWorldConfig config_;
  SpacePtr observation_space_;
  SpacePtr action_space_;
  Metadata metadata_;
  Cell agent_ = kStart;
};

}  // namespace pixelgym
