// Task: what one pixel task is — its world, cameras, actions, observations, reward, termination.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/engine/world.h"
#include "pixelgym/envs/params.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/envs/tasks/visual_variation.h"
#include "pixelgym/envs/value.h"
#include "pixelgym/render/camera.h"
#include "pixelgym/render/context.h"

namespace pixelgym {

/// The settings every pixel task shares (`make` kwargs and `--set` keys).
struct TaskConfig {
  /// Observation image size in pixels.
  int width = 84;
  int height = 84;
  /// One of the task's camera names (or "custom"); empty for its default (the first), or
  /// "custom" when camera_pos is given.
  std::string camera;
  /// Cameras drawn into the observation, each as its own "pixels/<name>" image in the Dict (in
  /// place of "pixels"); empty for the one `camera` as "pixels".
  std::vector<std::string> cameras;
  /// A camera of the user's, named "custom": at `camera_pos` looking at `camera_lookat` (world
  /// coordinates, m) with +z up in the image, fixed in the world.
  bool has_custom_camera = false;
  Eigen::Vector3f camera_pos = Eigen::Vector3f::Zero();
  Eigen::Vector3f camera_lookat = Eigen::Vector3f::Zero();
  /// Vertical field of view of every camera drawn, degrees; 0 for each camera's own (the custom
  /// camera's: 45).
  double camera_fov = 0.0;
  /// "pixels+state": Dict of "pixels" and the state arrays; "pixels": Dict of "pixels" alone;
  /// "rgb": the (height, width, 3) uint8 image itself, a bare Box (ALE's obs_type="rgb", what
  /// SB3's CnnPolicy and Gymnasium's image wrappers take); "state": only the state arrays (no
  /// rendering at all).
  std::string obs_mode = "pixels+state";
  /// Size of `render()` frames (anti-aliased), separate from the observation.
  int render_width = 256;
  int render_height = 256;
  /// Control steps per env step; rewards are summed over them.
  int action_repeat = 1;
  /// Whether observations and render() frames draw shadows.
  bool shadows = true;
  /// Multisample anti-aliasing of observation images: 0 (off), 2, 4 or 8 samples per pixel.
  /// Without it a part thinner than a pixel (the cart-pole's pole at 64x64) covers a pixel only
  /// where it crosses the pixel's centre, so it shows up broken into pieces that come and go as
  /// it moves; with it such a part is a continuous fainter line. Off by default in the v0 ids,
  /// whose observations stay as they were (render() frames always use 4).
  int msaa = 0;
  /// The OpenGL the env draws with (render::GlBackend): auto (PIXELGYM_GL when set, else OSMesa
  /// where it works, else EGL), osmesa or egl. On llvmpipe both draw the same bytes.
  render::GlBackend render_backend = render::GlBackend::kAuto;
  /// Visual variation drawn at each reset (none by default).
  VariationConfig variation;

  /// Whether observations hold the image (obs_mode is not "state").
  bool has_pixels() const { return obs_mode != "state"; }
  /// Whether observations hold the state arrays (obs_mode is "pixels+state" or "state").
  bool has_state() const { return obs_mode == "pixels+state" || obs_mode == "state"; }
  /// Whether the observation is the image itself, a bare Box (obs_mode "rgb").
  bool image_only() const { return obs_mode == "rgb"; }

  /// The keys above with their defaults and docs (VariationConfig::params for the variation).
  static std::vector<ParamSpec> params();
  /// The cameras an env of `task` under this config draws: the task's, then "custom" if given.
  std::vector<std::string> camera_names(const std::vector<std::string>& task_cameras) const;
  /// Reads resolved kwargs; `cameras` are the task's camera names. Throws std::invalid_argument,
  /// naming `env` and the key, for a size outside [16, 8192], an unknown obs_mode or camera (in
  /// `camera` or `cameras`, or a repeated one), `cameras` with obs_mode "rgb" or "state",
  /// camera_pos or camera_lookat that is not three numbers "x,y,z" or given without the other,
  /// the two equal, camera_fov outside [0, 170), action_repeat outside [1, 1000], msaa other than
  /// 0, 2, 4 or 8, a render_backend other than auto, egl or osmesa, and what
  /// VariationConfig::from_params refuses.
  static TaskConfig from_params(const Params& params, const std::vector<std::string>& cameras,
                                const std::string& env);
};

/// A named float32 state array of the observation.
struct StateSpec {
  /// The observation key.
  std::string name;
  /// The array's shape.
  Shape shape;
};

/// Where Task::observe writes: the float32 state arrays of one observation, in memory the caller
/// owns (slots of the observation PixelEnv writes into). Writing allocates nothing.
class StateSlots {
 public:
  /// `arrays[i]` is the slot of `specs[i]`: a float32 array of its shape. Both must outlive this.
  StateSlots(const std::vector<StateSpec>& specs, Value* arrays) : specs_(specs), arrays_(arrays) {}

  /// Writes `values` (any Eigen vector or expression, converted to float32) into the slot
  /// named `name`. Throws std::out_of_range for a name not in the task's state_specs() and
  /// std::invalid_argument when the sizes differ.
  template <typename Derived>
  void set(const char* name, const Eigen::MatrixBase<Derived>& values) {
    float* out = slot(name, static_cast<std::int64_t>(values.size()));
    for (Eigen::Index i = 0; i < values.size(); ++i) out[i] = static_cast<float>(values(i));
  }
  /// The same for values listed in place: `state.set("joint_pos", {angle})`.
  void set(const char* name, std::initializer_list<double> values);

 private:
  float* slot(const char* name, std::int64_t size);

  const std::vector<StateSpec>& specs_;
  Value* arrays_;
};

/// One task, written like dm_control's suite files: how its world is built, named quantities,
/// then initialize_episode / before_step / observe / reward / terminated. PixelEnv runs it.
/// Everything that fixes the spaces (action_space, state_specs, camera_names) is known without a
/// world.
class Task {
 public:
  virtual ~Task() = default;

  /// Camera names; the first is the default for observations and render().
  virtual std::vector<std::string> camera_names() const = 0;
  /// The actions before_step accepts.
  virtual SpacePtr action_space() const = 0;
  /// The state arrays, in observation order.
  virtual std::vector<StateSpec> state_specs() const = 0;
  /// Seconds of simulated time per control step. PixelEnv runs
  /// round(control_timestep_s / world_config().timestep_s) physics steps (at least 1) per control
  /// step.
  virtual double control_timestep_s() const = 0;
  /// The settings of the world PixelEnv builds for the task (physics timestep, gravity, ground).
  virtual engine::WorldConfig world_config() const = 0;
  /// Control steps per episode: the registry's TimeLimit truncates after
  /// ceil(episode_length / action_repeat) env steps unless `make` is given max_episode_steps.
  virtual int episode_length() const { return 1000; }

  /// Adds the robots and bodies.
  virtual void build(engine::World& world) = 0;
  /// Camera `name` for the world's current state (tracking cameras follow a body). The image
  /// size is set by the caller.
  virtual render::Camera camera(const std::string& name, const engine::World& world) const = 0;

  /// Sets the start of an episode in a freshly reset world, drawing from `rng`.
  virtual void initialize_episode(engine::World& world, Rng& rng) = 0;
  /// Applies an action already known to be in action_space().
  virtual void before_step(const Value& action, engine::World& world) = 0;
  /// Writes every state array of state_specs() into its slot.
  virtual void observe(const engine::World& world, StateSlots& state) const = 0;
  /// This control step's reward, in [0, 1].
  virtual double reward(const engine::World& world) const = 0;
  /// Whether the episode ends at this control step (the goal reached, a fall); PixelEnv stops
  /// the action repeat there. Never, by default.
  virtual bool terminated(const engine::World& /*world*/) const { return false; }
};

}  // namespace pixelgym
