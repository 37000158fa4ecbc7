// PixelEnv: the one environment class that runs every pixel task.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/engine/world.h"
#include "pixelgym/envs/env.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/render_resources.h"
#include "pixelgym/envs/tasks/task.h"
#include "pixelgym/envs/tasks/world_scene.h"
#include "pixelgym/render/renderer.h"

namespace pixelgym {

class PixelRenderResources;

/// Runs a Task: reset rebuilds the world and lets the task set the episode's start; each step
/// repeats `action_repeat` times before_step -> physics steps -> reward, then observes into the
/// caller's buffer (Env::step_into). Observations are {"pixels": (H, W, 3) uint8, <state
/// arrays>: float32} per obs_mode; spaces come from the config and the task alone, before any
/// world exists (`describe`). The renderer draws with the PixelRenderResources it is given (null:
/// a GL context of its own); it is built in the constructor when observations hold pixels, and
/// on the first render() call otherwise, so obs_mode="state" never creates a GL context unless
/// asked to render. A PixelEnv never truncates on its own: the registry's TimeLimit does, after
/// the task's episode length (Task::episode_length). reset()'s options are visual variation
/// kwargs (VariationConfig::params: variation, vary_*, floor_texture, sky_texture,
/// sky_backgrounds, floor_opacity), which replace the env's from that reset on; any other key, a
/// wrong type or a bad value is std::invalid_argument, and the env is as it was. A step whose
/// command, state, observation or reward goes non-finite throws PhysicsDivergence.
class PixelEnv final : public Env {
 public:
  /// Builds the world (Task::build) and, when observations hold pixels, the renderer. `config`
  /// is taken as given (TaskConfig::from_params checks kwargs). `name` is how messages name the
  /// env before the registry sets its id. Throws std::invalid_argument for a null task, when
  /// `render` is not null and not PixelRenderResources, or when observations hold pixels and
  /// config.msaa is more than the renderer's OpenGL offers (naming the counts it offers);
  /// std::runtime_error when the GL context cannot be created, and what the task's build throws.
  PixelEnv(std::unique_ptr<Task> task, TaskConfig config, std::string name,
           std::shared_ptr<RenderResources> render = nullptr);
  ~PixelEnv() override;

  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  const Metadata& metadata() const override { return metadata_; }

  /// The task it runs.
  const Task& task() const { return *task_; }
  /// The config it was made with.
  const TaskConfig& config() const { return config_; }
  /// The simulation, for inspection and scripted controllers (do not add bodies to it).
  const engine::World& world() const { return *world_; }
  /// The render scene of world(), as of the last observation or render() (for tests and tools).
  const WorldScene& scene() const { return *scene_; }
  /// The render resources it draws with, as given at construction; null: a context of its own.
  const PixelRenderResources* render_resources() const { return render_resources_.get(); }
  /// This episode's visual variation (all zero when the config varies nothing).
  const VariationSample& variation() const { return variation_sample_; }
  /// Control steps taken in this episode.
  int control_steps() const { return control_steps_; }
  /// Frames drawn so far (observations and render()); stays 0 with obs_mode="state" until
  /// render() is called.
  std::int64_t frames_rendered() const { return frames_rendered_; }

  /// Camera `camera`'s image of the world as it is now, at any size and MSAA sample count
  /// (0, 2, 4 or 8), as a new (height, width, 3) uint8 array (for tests and tools), with this
  /// episode's variation. Counts in frames_rendered(); creates the renderer if there is none yet.
  /// `camera` goes to Task::camera unchecked (the built-in tasks draw an unknown name as one of
  /// their cameras) unless it is "custom" and the config has a custom camera. Throws
  /// std::invalid_argument for an invalid size or sample count (render::Camera::validate).
  Array render_camera(const std::string& camera, int width, int height, int msaa_samples);
  /// The same, drawn into `frame`: a uint8 (height, width, 3) array the caller owns. Throws
  /// std::invalid_argument for another dtype or shape, and as render_camera.
  void render_camera_into(const std::string& camera, int msaa_samples, Array& frame);

  /// The spaces, time limit, cameras and metadata of `task` under `config`, without a world: the
  /// observation Dict ("pixels" a uint8 Box [0, 255] of (height, width, 3), or one such
  /// "pixels/<name>" per camera of config.cameras, then each state array a float32 Box
  /// (-inf, inf)), max_episode_steps = ceil(episode_length / action_repeat),
  /// render_fps = 1 / (control_timestep_s * action_repeat) and render_shape from render_width and
  /// render_height.
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
  // render_camera_into without updating the scene first: it draws the poses of the last update.
  void draw_camera_into(const std::string& camera, int msaa_samples, Array& frame);
  // Camera `name` for the world as it is now: the task's or the custom one, with camera_fov and
  // this episode's camera variation.
  render::Camera view_of(const std::string& name);
  // Throws PhysicsDivergence naming the env, the control step and `what` went non-finite.
  [[noreturn]] void diverged(const std::string& what) const;
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
  std::shared_ptr<PixelRenderResources> render_resources_;  // null: a context of its own
  std::unique_ptr<render::Renderer> renderer_;
  int control_steps_ = 0;
  std::int64_t frames_rendered_ = 0;
  // Visual variation: drawn at reset from a generator of its own (seeded from the reset seed),
  // so that the physics' generator, rng(), draws the same numbers with it on or off.
  std::unique_ptr<VisualVariation> variation_;  // null: config_.variation varies nothing
  VariationSample variation_sample_;
  std::optional<Rng> variation_rng_;
  std::map<std::string, float> pivot_distance_m_;  // per camera, this episode's
};

/// What the pixel envs that one thread steps share to draw (RenderResources, made by make_vec
/// through EnvSpec::make_render_resources): one GL context group (render::ContextGroup) per
/// render_backend the envs ask for, in copy `mesa_copy` of Mesa, or, without sharing, only the copy
/// (each env's context of its own in it). Frames are byte-identical whatever is shared. The envs
/// given one must be stepped by one thread at a time (render::ContextGroup).
class PixelRenderResources final : public RenderResources {
 public:
  /// Throws std::invalid_argument for mesa_copy < 0.
  PixelRenderResources(int mesa_copy, bool share_context);
  ~PixelRenderResources() override;

  /// The copy of Mesa asked for (see render::MesaCopy).
  int mesa_copy() const { return mesa_copy_; }
  /// Whether the renderers it makes share one GL context (one per backend).
  bool shares_context() const { return share_context_; }
  /// Whether a renderer made with these resources has created a shared GL context yet.
  bool context_created() const;
  /// A renderer for one env drawing with `backend`: with that backend's shared context when
  /// shared, else with one of its own in the copy. Throws as render::Renderer's constructors.
  std::unique_ptr<render::Renderer> make_renderer(render::GlBackend backend);

 private:
  int mesa_copy_;
  bool share_context_;
  std::array<std::unique_ptr<render::ContextGroup>, 3> groups_;  // by GlBackend asked for
};

/// The registry entry of a pixel task: the shared TaskConfig keys plus `extra_params`; the
/// factory builds the task with `make_task(kwargs)` and runs it in a PixelEnv drawing with the
/// MakeOptions' render resources (make_render_resources makes PixelRenderResources); `describe` and
/// the default max_episode_steps come from the task and config without building a world. Calls
/// `make_task` once, with the default kwargs, for the task's episode length, and throws what it
/// throws.
EnvSpec pixel_task_spec(const std::string& id, const std::string& description,
                        std::function<std::unique_ptr<Task>(const Params& kwargs)> make_task,
                        std::vector<ParamSpec> extra_params = {});

/// The Distracting Control Suite's variant of the pixel task `base` (made by pixel_task_spec):
/// id "<Name>-distracting-v<N>" for base "<Name>-v<N>", the same task and kwargs with other
/// defaults: variation 0.2 (the suite's "medium"; 0.1 easy, 0.3 hard) for body colours and the
/// camera only, a procedural background (sky_texture "noise", or a folder of the user's) and the
/// floor at `floor_opacity` (the suite's ground-plane alpha for the domain).
EnvSpec distracting_task_spec(const EnvSpec& base, float floor_opacity);

/// A sphere that is drawn but never touched (a target or goal marker), static.
engine::BodyOptions marker_body(const std::string& name, double radius_m,
                                const Eigen::Vector4d& rgba);

}  // namespace pixelgym
