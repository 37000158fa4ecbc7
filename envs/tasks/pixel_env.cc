#include "pixelgym/envs/tasks/pixel_env.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "pixelgym/envs/errors.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/suggestions.h"

namespace pixelgym {
namespace {

constexpr int kMinImageSize = 16;
constexpr int kMaxImageSize = 8192;
constexpr int kRenderMsaaSamples = 4;

int read_size(const Params& params, const std::string& key, const std::string& env) {
  const std::int64_t value = params.at(key).as_int();
  if (value < kMinImageSize || value > kMaxImageSize) {
    throw std::invalid_argument(env + ": " + key + " must be in [" + std::to_string(kMinImageSize) +
                                ", " + std::to_string(kMaxImageSize) + "], got " +
                                std::to_string(value));
  }
  return static_cast<int>(value);
}

// "x,y,z" as three finite numbers; throws std::invalid_argument naming `env`, `key` and the text.
Eigen::Vector3f read_point(const std::string& text, const std::string& key,
                           const std::string& env) {
  Eigen::Vector3f point;
  std::size_t start = 0;
  int count = 0;
  bool ok = true;
  while (ok && start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string part = text.substr(start, comma - start);
    char* end = nullptr;
    const double value = std::strtod(part.c_str(), &end);
    ok = !part.empty() && end != part.c_str() && *end == '\0' && std::isfinite(value) && count < 3;
    if (ok) point[count++] = static_cast<float>(value);
    start = comma + 1;
  }
  if (!ok || count != 3) {
    throw std::invalid_argument(env + ": " + key +
                                " must be three numbers \"x,y,z\" (world coordinates, m), got \"" +
                                text + "\"");
  }
  return point;
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "\"" : ", \"") + name + "\"";
  return out;
}

}  // namespace

void StateSlots::set(const char* name, std::initializer_list<double> values) {
  float* out = slot(name, static_cast<std::int64_t>(values.size()));
  for (const double value : values) *out++ = static_cast<float>(value);
}

float* StateSlots::slot(const char* name, std::int64_t size) {
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    if (specs_[i].name != name) continue;
    Array& array = arrays_[i].array();
    if (array.size() != size) {
      throw std::invalid_argument("Task::observe: state \"" + specs_[i].name + "\" has " +
                                  std::to_string(array.size()) + " elements, got " +
                                  std::to_string(size) + " values");
    }
    return array.data<float>();
  }
  std::string names;
  for (const StateSpec& spec : specs_) names += (names.empty() ? "\"" : ", \"") + spec.name + "\"";
  throw std::out_of_range("Task::observe: no state \"" + std::string(name) +
                          "\" (states: " + names + ")");
}

std::vector<ParamSpec> TaskConfig::params() {
  const TaskConfig d;
  std::vector<ParamSpec> specs = {
      {"width", d.width, "observation image width in pixels"},
      {"height", d.height, "observation image height in pixels"},
      {"camera", d.camera, "observation and render() camera (empty: the task's default)"},
      {"obs_mode", d.obs_mode,
       "\"pixels+state\" (Dict), \"pixels\" (Dict of the image), \"rgb\" (the image Box "
       "itself, for CnnPolicy) or \"state\""},
      {"render_width", d.render_width, "render() frame width in pixels"},
      {"render_height", d.render_height, "render() frame height in pixels"},
      {"action_repeat", d.action_repeat, "control steps per env step (rewards are summed)"},
      {"shadows", d.shadows, "draw shadows in observations and render()"},
      {"msaa", d.msaa,
       "anti-aliasing samples per observation pixel: 0 (off), 2, 4, or 8 where the OpenGL "
       "offers it (llvmpipe: at most 4; render() uses 4)"},
      {"render_backend", render::gl_backend_name(d.render_backend),
       "the OpenGL to draw with: auto (PIXELGYM_GL when set, else osmesa where it works, else "
       "egl), osmesa or egl (a GPU's EGL device where one exists, else llvmpipe; "
       "PIXELGYM_EGL_DEVICE picks one)"},
      {"cameras", std::string(),
       "cameras drawn into the observation, comma-separated, each as \"pixels/<name>\" (empty: "
       "`camera` as \"pixels\")"},
      {"camera_pos", std::string(),
       "\"x,y,z\": the position of a camera of your own, named \"custom\" (with camera_lookat)"},
      {"camera_lookat", std::string(), "\"x,y,z\": the point the custom camera looks at"},
      {"camera_fov", d.camera_fov,
       "vertical field of view of every camera, degrees (0: each camera's own)"}};
  const std::vector<ParamSpec> variation = VariationConfig::params();
  specs.insert(specs.end(), variation.begin(), variation.end());
  return specs;
}

std::vector<std::string> TaskConfig::camera_names(
    const std::vector<std::string>& task_cameras) const {
  std::vector<std::string> names = task_cameras;
  if (has_custom_camera) names.emplace_back("custom");
  return names;
}

TaskConfig TaskConfig::from_params(const Params& params, const std::vector<std::string>& cameras,
                                   const std::string& env) {
  TaskConfig c;
  c.width = read_size(params, "width", env);
  c.height = read_size(params, "height", env);
  c.render_width = read_size(params, "render_width", env);
  c.render_height = read_size(params, "render_height", env);
  const std::string pos = params.at("camera_pos").as_string();
  const std::string lookat = params.at("camera_lookat").as_string();
  if (pos.empty() != lookat.empty()) {
    throw std::invalid_argument(env + ": camera_pos and camera_lookat go together, got only " +
                                (pos.empty() ? "camera_lookat" : "camera_pos"));
  }
  if (!pos.empty()) {
    c.has_custom_camera = true;
    c.camera_pos = read_point(pos, "camera_pos", env);
    c.camera_lookat = read_point(lookat, "camera_lookat", env);
    if ((c.camera_pos - c.camera_lookat).norm() < 1e-6F) {
      throw std::invalid_argument(env + ": camera_pos and camera_lookat must differ, both are \"" +
                                  pos + "\"");
    }
  }
  c.camera_fov = params.at("camera_fov").as_float();
  if (!(c.camera_fov >= 0.0 && c.camera_fov < 170.0)) {
    throw std::invalid_argument(env +
                                ": camera_fov must be in [0, 170) degrees (0: each camera's "
                                "own), got " +
                                Param(c.camera_fov).to_string());
  }
  const std::vector<std::string> known = c.camera_names(cameras);
  const auto check_camera = [&](const std::string& name, const std::string& key) {
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      const std::string suggestion = did_you_mean(name, known);
      throw std::invalid_argument(
          env + ": unknown camera \"" + name + "\"" + (key == "camera" ? "" : " in " + key) +
          "; cameras: " + quoted_list(known) + (suggestion.empty() ? "" : "; " + suggestion));
    }
  };
  c.camera = params.at("camera").as_string();
  if (c.camera.empty() && c.has_custom_camera) c.camera = "custom";
  if (!c.camera.empty()) check_camera(c.camera, "camera");
  const std::string listed = params.at("cameras").as_string();
  for (std::size_t start = 0; !listed.empty() && start <= listed.size();) {
    const std::size_t comma = std::min(listed.find(',', start), listed.size());
    const std::string name = listed.substr(start, comma - start);
    check_camera(name, "cameras");
    if (std::find(c.cameras.begin(), c.cameras.end(), name) != c.cameras.end()) {
      throw std::invalid_argument(env + ": camera \"" + name + "\" is listed twice in cameras");
    }
    c.cameras.push_back(name);
    start = comma + 1;
  }
  c.obs_mode = params.at("obs_mode").as_string();
  if (c.obs_mode != "pixels+state" && c.obs_mode != "pixels" && c.obs_mode != "rgb" &&
      c.obs_mode != "state") {
    const std::string suggestion =
        did_you_mean(c.obs_mode, {"pixels+state", "pixels", "rgb", "state"});
    throw std::invalid_argument(env +
                                ": obs_mode must be \"pixels+state\", \"pixels\", \"rgb\" or "
                                "\"state\", got \"" +
                                c.obs_mode + "\"" + (suggestion.empty() ? "" : "; " + suggestion));
  }
  const std::int64_t repeat = params.at("action_repeat").as_int();
  if (repeat < 1 || repeat > 1000) {
    throw std::invalid_argument(env + ": action_repeat must be in [1, 1000], got " +
                                std::to_string(repeat));
  }
  c.action_repeat = static_cast<int>(repeat);
  c.shadows = params.at("shadows").as_bool();
  const std::int64_t msaa = params.at("msaa").as_int();
  if (msaa != 0 && msaa != 2 && msaa != 4 && msaa != 8) {
    throw std::invalid_argument(env + ": msaa must be 0, 2, 4 or 8, got " + std::to_string(msaa));
  }
  c.msaa = static_cast<int>(msaa);
  c.render_backend =
      render::parse_gl_backend(params.at("render_backend").as_string(), env + ": render_backend");
  if (!c.cameras.empty() && (c.obs_mode == "rgb" || c.obs_mode == "state")) {
    throw std::invalid_argument(env + ": cameras gives a Dict of images, which obs_mode \"" +
                                c.obs_mode +
                                "\" has no place for (use \"pixels\" or "
                                "\"pixels+state\")");
  }
  c.variation = VariationConfig::from_params(params, env);
  return c;
}

EnvDescription PixelEnv::describe(const Task& task, const TaskConfig& config) {
  EnvDescription description;
  description.cameras = config.camera_names(task.camera_names());
  const auto image = std::make_shared<spaces::Box>(
      0.0, 255.0, Shape{config.height, config.width, 3}, DType::kUInt8);
  spaces::Dict::Entries entries;
  if (config.has_pixels() && config.cameras.empty()) entries.emplace_back("pixels", image);
  for (const std::string& name : config.cameras) entries.emplace_back("pixels/" + name, image);
  if (config.has_state()) {
    const double inf = std::numeric_limits<double>::infinity();
    for (const StateSpec& spec : task.state_specs()) {
      entries.emplace_back(spec.name,
                           std::make_shared<spaces::Box>(-inf, inf, spec.shape, DType::kFloat32));
    }
  }
  description.observation_space =
      config.image_only() ? SpacePtr(image) : std::make_shared<spaces::Dict>(std::move(entries));
  description.action_space = task.action_space();
  // The episode ends after the task's control steps, counted in env steps of action_repeat.
  description.max_episode_steps =
      (task.episode_length() + config.action_repeat - 1) / config.action_repeat;
  description.metadata.render_fps = 1.0 / (task.control_timestep_s() * config.action_repeat);
  description.metadata.render_shape = Shape{config.render_height, config.render_width, 3};
  return description;
}

PixelRenderResources::PixelRenderResources(int mesa_copy, bool share_context)
    : mesa_copy_(mesa_copy), share_context_(share_context) {
  if (mesa_copy < 0) {
    throw std::invalid_argument("PixelRenderResources: mesa_copy must be >= 0, got " +
                                std::to_string(mesa_copy));
  }
}

PixelRenderResources::~PixelRenderResources() = default;

bool PixelRenderResources::context_created() const {
  for (const auto& group : groups_) {
    if (group != nullptr && group->created()) return true;
  }
  return false;
}

std::unique_ptr<render::Renderer> PixelRenderResources::make_renderer(render::GlBackend backend) {
  if (!share_context_) return std::make_unique<render::Renderer>(backend, mesa_copy_);
  std::unique_ptr<render::ContextGroup>& group = groups_[static_cast<std::size_t>(backend)];
  if (group == nullptr) group = std::make_unique<render::ContextGroup>(mesa_copy_, backend);
  return std::make_unique<render::Renderer>(*group);
}

PixelEnv::PixelEnv(std::unique_ptr<Task> task, TaskConfig config, std::string name,
                   std::shared_ptr<RenderResources> render)
    : task_(std::move(task)), config_(std::move(config)), name_(std::move(name)) {
  if (task_ == nullptr) throw std::invalid_argument("PixelEnv: task is null");
  if (render != nullptr) {
    render_resources_ = std::dynamic_pointer_cast<PixelRenderResources>(render);
    if (render_resources_ == nullptr) {
      throw std::invalid_argument(name_ +
                                  ": the render resources given are not PixelRenderResources");
    }
  }
  EnvDescription description = describe(*task_, config_);
  camera_ = config_.camera.empty() ? description.cameras.at(0) : config_.camera;
  observation_space_ = std::move(description.observation_space);
  action_space_ = std::move(description.action_space);
  metadata_ = std::move(description.metadata);
  if (config_.has_state()) state_specs_ = task_->state_specs();
  const engine::WorldConfig world_config = task_->world_config();
  substeps_ = std::max(
      1, static_cast<int>(std::lround(task_->control_timestep_s() / world_config.timestep_s)));
  world_ = std::make_unique<engine::World>(world_config);
  task_->build(*world_);
  scene_ = std::make_unique<WorldScene>(*world_);
  scene_->scene().shadows = config_.shadows;
  if (config_.variation.active()) {
    variation_ = std::make_unique<VisualVariation>(config_.variation, scene_->scene());
  }
  if (config_.has_pixels()) {
    // More samples than this OpenGL offers would fail at the first reset: refuse them now, with
    // what it offers (llvmpipe: 0, 2 and 4; a GPU through EGL: 8 too).
    render::Renderer& drawing = renderer();
    if (config_.msaa > drawing.max_samples()) {
      std::string offered = "0";
      for (int samples = 2; samples <= std::min(drawing.max_samples(), 8); samples *= 2) {
        offered += ", " + std::to_string(samples);
      }
      throw std::invalid_argument(name_ + ": msaa=" + std::to_string(config_.msaa) +
                                  " is more than this OpenGL offers (" + drawing.description() +
                                  "): it takes msaa " + offered);
    }
  }
}

PixelEnv::~PixelEnv() = default;

render::Renderer& PixelEnv::renderer() {
  if (renderer_ == nullptr) {
    renderer_ = render_resources_ != nullptr
                    ? render_resources_->make_renderer(config_.render_backend)
                    : std::make_unique<render::Renderer>(config_.render_backend);
  }
  return *renderer_;
}

void PixelEnv::do_reset(std::optional<std::uint64_t> seed, const Options& options,
                        ResetResult& out) {
  // Options set the visual variation's kwargs from this reset on, over the env's own: checked
  // against them (names and types), and read as make() reads them, before anything changes.
  std::optional<VariationConfig> changed;
  std::unique_ptr<VisualVariation> next;
  if (!options.empty()) {
    std::vector<ParamSpec> current = VariationConfig::params();
    for (ParamSpec& spec : current) spec.default_value = config_.variation.settings.at(spec.name);
    changed = VariationConfig::from_params(
        resolve_params(current, options,
                       name() + ": reset options (the visual variation's kwargs)"),
        name());
    if (changed->active()) {
      next = variation_ != nullptr ? variation_->with_config(*changed)
                                   : std::make_unique<VisualVariation>(*changed, scene_->scene());
    }
  }
  VisualVariation* drawing = changed.has_value() ? next.get() : variation_.get();
  if (drawing != nullptr) {
    // Drawn first: an image that cannot be read fails the reset before anything has changed.
    constexpr std::uint64_t kVariationStream = 0x76697375616c5f76ULL;  // "visual_v"
    if (seed.has_value()) {
      variation_rng_.emplace(*seed ^ kVariationStream);
    } else if (!variation_rng_.has_value()) {
      variation_rng_.emplace(rng().state()[0] ^ kVariationStream);  // reads rng(), draws nothing
    }
    variation_sample_ = drawing->sample(scene_->scene().instances.size(), *variation_rng_);
    VisualVariation::apply(variation_sample_, scene_->scene());
    pivot_distance_m_.clear();
  } else if (changed.has_value() && variation_ != nullptr) {
    // Variation turned off: the task's own look again.
    VisualVariation::apply(variation_->base(scene_->scene().instances.size()), scene_->scene());
    variation_sample_ = VariationSample{};
    pivot_distance_m_.clear();
  }
  if (changed.has_value()) {
    config_.variation = std::move(*changed);
    variation_ = std::move(next);
  }
  world_->reset();
  task_->initialize_episode(*world_, rng());
  control_steps_ = 0;
  observe(out.obs);
}

void PixelEnv::do_step(const Value& action, StepResult& out) {
  for (int r = 0; r < config_.action_repeat; ++r) {
    try {
      task_->before_step(action, *world_);
      world_->step(substeps_);
    } catch (const engine::NonFiniteCommand& error) {
      ++control_steps_;
      diverged(error.what());
    } catch (const engine::NonFiniteState& error) {
      ++control_steps_;
      diverged(error.what());
    }
    ++control_steps_;
    const double reward = task_->reward(*world_);
    if (!std::isfinite(reward)) diverged("the reward is " + std::to_string(reward));
    out.reward += reward;
    out.terminated = task_->terminated(*world_);
    if (out.terminated) break;
  }
  observe(out.obs);
  if (!std::isfinite(out.reward)) diverged("the summed reward is " + std::to_string(out.reward));
}

void PixelEnv::diverged(const std::string& what) const {
  throw PhysicsDivergence(name() + ": the simulation diverged at control step " +
                          std::to_string(control_steps_) + " of the episode: " + what +
                          " (an action, force or setting too large to simulate); reset() starts "
                          "a new episode");
}

void PixelEnv::observe(Value& obs) {
  if (config_.image_only()) {
    render_camera_into(camera_, config_.msaa, obs.array());
    return;
  }
  // Entries in observation_space() order: "pixels" first when present, then the state arrays.
  // The scene takes the world's poses once, however many cameras draw it.
  std::vector<Value>& slots = obs.dict().values();
  std::size_t next = 0;
  if (config_.has_pixels()) scene_->update(*world_);
  if (config_.has_pixels() && config_.cameras.empty()) {
    draw_camera_into(camera_, config_.msaa, slots[next++].array());
  }
  for (const std::string& name : config_.cameras) {
    draw_camera_into(name, config_.msaa, slots[next++].array());
  }
  if (config_.has_state()) {
    StateSlots state(state_specs_, slots.data() + next);
    task_->observe(*world_, state);
    // float32 slots: a large but finite double state (1e39) becomes inf here.
    for (std::size_t s = 0; s < state_specs_.size(); ++s) {
      const Array& array = slots[next + s].array();
      const float* values = array.data<float>();
      for (std::int64_t i = 0; i < array.size(); ++i) {
        if (!std::isfinite(values[i])) {
          diverged("observation \"" + state_specs_[s].name + "\"[" + std::to_string(i) + "] is " +
                   std::to_string(values[i]));
        }
      }
    }
  }
}

Array PixelEnv::render_camera(const std::string& camera, int width, int height, int msaa_samples) {
  Array frame(DType::kUInt8, {height, width, 3});
  render_camera_into(camera, msaa_samples, frame);
  return frame;
}

void PixelEnv::render_camera_into(const std::string& camera, int msaa_samples, Array& frame) {
  scene_->update(*world_);
  draw_camera_into(camera, msaa_samples, frame);
}

void PixelEnv::draw_camera_into(const std::string& camera, int msaa_samples, Array& frame) {
  const Shape& shape = frame.shape();
  if (frame.dtype() != DType::kUInt8 || shape.size() != 3 || shape[2] != 3) {
    throw std::invalid_argument(
        name() + ": a frame must be a uint8 (height, width, 3) array, got " +
        std::string(dtype_name(frame.dtype())) + " " + shape_to_string(shape));
  }
  render::Camera view = view_of(camera);
  view.height = static_cast<int>(shape[0]);
  view.width = static_cast<int>(shape[1]);
  view.msaa_samples = msaa_samples;
  renderer().render(scene_->scene(), view, {view.width, view.height, frame.data<std::uint8_t>()});
  ++frames_rendered_;
}

render::Camera PixelEnv::view_of(const std::string& name) {
  render::Camera view;
  float pivot_m = 0.0F;
  if (name == "custom" && config_.has_custom_camera) {
    view = render::Camera::look_at(
        config_.camera_pos, config_.camera_lookat,
        std::abs((config_.camera_lookat - config_.camera_pos).normalized().z()) > 0.999F
            ? Eigen::Vector3f::UnitY()
            : Eigen::Vector3f::UnitZ());
    pivot_m = (config_.camera_lookat - config_.camera_pos).norm();
  } else {
    view = task_->camera(name, *world_);
  }
  if (config_.camera_fov > 0.0) view.fov_y_deg = static_cast<float>(config_.camera_fov);
  if (variation_ == nullptr) return view;
  // The camera turns about what it looks at: the point of its view axis nearest the scene's
  // centre at the episode's first frame from it (the custom camera's look-at point).
  auto [pivot, added] = pivot_distance_m_.try_emplace(name, pivot_m);
  if (added && pivot_m == 0.0F) {
    const Eigen::Vector3f to_centre = scene_->bounds().center() - view.X_world_camera.translation();
    const float along = to_centre.dot(-view.X_world_camera.linear().col(2));
    pivot->second = std::max(along > 0.1F ? along : to_centre.norm(), 0.1F);
  }
  return VisualVariation::apply(variation_sample_, view, pivot->second);
}

Array PixelEnv::do_render() {
  return render_camera(camera_, config_.render_width, config_.render_height, kRenderMsaaSamples);
}

void PixelEnv::do_close() { renderer_.reset(); }

EnvSpec pixel_task_spec(const std::string& id, const std::string& description,
                        std::function<std::unique_ptr<Task>(const Params& kwargs)> make_task,
                        std::vector<ParamSpec> extra_params) {
  EnvSpec spec;
  spec.id = id;
  spec.description = description;
  spec.params = TaskConfig::params();
  spec.params.insert(spec.params.end(), extra_params.begin(), extra_params.end());
  spec.factory = [id, make_task](const Params& kwargs, const MakeOptions& options) {
    std::unique_ptr<Task> task = make_task(kwargs);
    TaskConfig config = TaskConfig::from_params(kwargs, task->camera_names(), id);
    return std::make_unique<PixelEnv>(std::move(task), std::move(config), id, options.render);
  };
  spec.make_render_resources = [](int worker, bool share_contexts) {
    return std::make_shared<PixelRenderResources>(worker, share_contexts);
  };
  spec.describe = [id, make_task](const Params& kwargs) {
    const std::unique_ptr<Task> task = make_task(kwargs);
    return PixelEnv::describe(*task, TaskConfig::from_params(kwargs, task->camera_names(), id));
  };
  // The default time limit: the one describe gives for default kwargs, from the task's episode
  // length alone, so that registering reads no file (UrdfReach-v0's task reads its URDF only
  // when asked for its spaces or world).
  const Params defaults = resolve_params(spec.params, {}, id);
  const std::int64_t repeat = defaults.at("action_repeat").as_int();
  spec.max_episode_steps = (make_task(defaults)->episode_length() + repeat - 1) / repeat;
  return spec;
}

EnvSpec distracting_task_spec(const EnvSpec& base, float floor_opacity) {
  const std::size_t version = base.id.rfind("-v");
  if (version == std::string::npos || !base.factory || !base.describe) {
    throw std::invalid_argument("distracting_task_spec: \"" + base.id +
                                "\" is not a pixel task's spec (Name-vN, made by pixel_task_spec)");
  }
  EnvSpec spec = base;
  spec.id = base.id.substr(0, version) + "-distracting" + base.id.substr(version);
  spec.description = base.description + "; the Distracting Control Suite's variant (" + base.id +
                     " with random body colours, camera and background)";
  const std::map<std::string, Param> defaults = {
      {"variation", 0.2},
      {"vary_textures", 0.0},
      {"vary_light", 0.0},
      {"vary_fov", 0.0},
      {"sky_texture", std::string("noise")},
      {"floor_opacity", static_cast<double>(floor_opacity)}};
  for (ParamSpec& param : spec.params) {
    const auto found = defaults.find(param.name);
    if (found != defaults.end()) param.default_value = found->second;
    if (param.name == "variation") {
      param.doc =
          "the Distracting Control Suite's intensity, 0 to 1: 0.1 easy, 0.2 medium "
          "(default), 0.3 hard (colours shifted by up to it, the camera turned by up to 90 "
          "times it degrees)";
    }
  }
  // The base's factory names the base in its messages: name the variant instead.
  const auto renamed = [from = base.id, to = spec.id](const std::invalid_argument& error) {
    std::string what = error.what();
    if (what.compare(0, from.size(), from) == 0) what.replace(0, from.size(), to);
    return std::invalid_argument(what);
  };
  spec.factory = [factory = base.factory, renamed](const Params& kwargs,
                                                   const MakeOptions& options) {
    try {
      return factory(kwargs, options);
    } catch (const std::invalid_argument& error) {
      throw renamed(error);
    }
  };
  spec.describe = [describe = base.describe, renamed](const Params& kwargs) {
    try {
      return describe(kwargs);
    } catch (const std::invalid_argument& error) {
      throw renamed(error);
    }
  };
  return spec;
}

engine::BodyOptions marker_body(const std::string& name, double radius_m,
                                const Eigen::Vector4d& rgba) {
  engine::BodyOptions marker;
  marker.name = name;
  marker.geometry.type = engine::GeometryType::kSphere;
  marker.geometry.radius_m = radius_m;
  marker.material.rgba = rgba;
  marker.material.has_rgba = true;
  marker.mass_kg = 0.0;
  marker.collides = false;
  return marker;
}

}  // namespace pixelgym
