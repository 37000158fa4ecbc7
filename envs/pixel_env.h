// PixelEnv: the one environment class that runs every pixel task.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/world.h"
#include "envs/env.h"
#include "envs/registry.h"
#include "envs/task.h"
#include "envs/world_scene.h"
#include "render/renderer.h"

namespace pixelgym {

/// Runs a Task: reset rebuilds the world and lets the task set the episode's start; each step
/// repeats `action_repeat` times before_step -> physics steps -> reward, then observes into the
/// caller's buffer (Env::step_into). Observations are {"pixels": (H, W, 3) uint8, <state
/// arrays>: float32} per obs_mode; spaces come from the config and the task alone, before any
/// world exists (`describe`). The renderer (an OpenGL context) is created on first use, so
/// obs_mode="state" never renders. A PixelEnv never truncates on its own: the registry's
/// TimeLimit does, after the task's episode length (Task::episode_length).
class PixelEnv final : public Env {
 public:
  /// `name` is how messages name the env before the registry sets its id.
  PixelEnv(std::unique_ptr<Task> task, TaskConfig config, std::string name);
  ~PixelEnv() override;

  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  const Metadata& metadata() const override { return metadata_; }

  const Task& task() const { return *task_; }
  const TaskConfig& config() const { return config_; }
  /// The simulation, for inspection and scripted controllers (do not add bodies to it).
  const engine::World& world() const { return *world_; }
  /// The render scene of the world, as of the last frame drawn.
  const WorldScene& scene() const { return *scene_; }
  /// Control steps taken in this episode.
  int control_steps() const { return control_steps_; }
  /// Frames drawn so far (observations and render()); stays 0 with obs_mode="state" until
  /// render() is called.
  std::int64_t frames_rendered() const { return frames_rendered_; }

  /// Camera `camera`'s image at any size, as a new (height, width, 3) uint8 array (for tests and
  /// tools).
  Array render_camera(const std::string& camera, int width, int height, int msaa_samples);
  /// The same, drawn into `frame`: a uint8 (height, width, 3) array the caller owns. Throws
  /// std::invalid_argument for another dtype or shape.
  void render_camera_into(const std::string& camera, int msaa_samples, Array& frame);

  /// The spaces, time limit, cameras and metadata of `task` under `config`, without a world.
  static EnvDescription describe(const Task& task, const TaskConfig& config);

 protected:
  std::string type_name() const override { return name_; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;
  Array do_render() override;
  void do_close() override;

 private:
  void observe(Value& obs);
  render::Renderer& renderer();

  std::unique_ptr<Task> task_;
  TaskConfig config_;
  std::string name_;
  std::string camera_;
  SpacePtr observation_space_;
  SpacePtr action_space_;
  Metadata metadata_;
  std::vector<StateSpec> state_specs_;  // the task's, kept so that observe() allocates nothing
  int substeps_ = 1;
  std::unique_ptr<engine::World> world_;
  std::unique_ptr<WorldScene> scene_;
  std::unique_ptr<render::Renderer> renderer_;
  int control_steps_ = 0;
  std::int64_t frames_rendered_ = 0;
};

/// The registry entry of a pixel task: the shared TaskConfig keys plus `extra_params`; the
/// factory builds the task with `make_task(kwargs)` and runs it in a PixelEnv; `describe` and
/// the default max_episode_steps come from the task and config without building a world.
EnvSpec pixel_task_spec(const std::string& id, const std::string& description,
                        std::function<std::unique_ptr<Task>(const Params& kwargs)> make_task,
                        std::vector<ParamSpec> extra_params = {});

/// A sphere that is drawn but never touched (a target or goal marker), static.
engine::BodyOptions marker_body(const std::string& name, double radius_m,
                                const Eigen::Vector4d& rgba);

}  // namespace pixelgym
