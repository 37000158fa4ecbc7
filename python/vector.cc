// VectorEnv: make_vec's loop or thread pool from Python, stepped with the GIL released.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/async_vector_env.h"
#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/envs/vector/process_vector_env.h"
#include "pixelgym/wrappers/wrapper_spec.h"
#include "python/bindings.h"
#include "python/convert.h"

namespace pixelgym::python {
namespace {

using vector::AsyncVectorEnv;
using vector::VectorEnv;

vector::VectorMode parse_mode(const std::string& mode) {
  if (mode == "async") return vector::VectorMode::kAsync;
  if (mode == "sync") return vector::VectorMode::kSync;
  if (mode == "process") return vector::VectorMode::kProcess;
  throw std::invalid_argument(
      "make_vec: mode must be \"async\" (the thread pool), \"process\" (worker processes) "
      "or \"sync\" (a loop on the calling thread), got \"" +
      mode + "\"");
}

// A small result array copied out of the vector env's buffer (rewards, flags): callers keep
// these across steps, and copying num_envs numbers costs nothing next to a step.
py::array copy_of(const Array& array) { return to_numpy(array).attr("copy")(); }

// make_vec's vector env as the Python class _core.VectorEnv. The observation batch is returned
// as numpy views of the vector env's buffers (made once: every reset and step writes the same
// arrays); rewards, flags and infos are copies. A mutex keeps two Python threads from calling
// it at once (the second waits).
class VectorHandle {
 public:
  VectorHandle(const std::string& id, int num_envs, const py::dict& kwargs,
               const std::vector<std::string>& wrappers, const std::string& mode, int num_threads,
               const std::string& autoreset_mode, bool share_gl_contexts, int num_workers)
      : id_(id), wrappers_(wrappers) {
    vector::VectorOptions options;
    options.mode = parse_mode(mode);
    options.num_threads = num_threads;
    options.num_workers = num_workers;
    options.autoreset = vector::parse_autoreset_mode(autoreset_mode);
    options.share_gl_contexts = share_gl_contexts;
    kwargs_ = params_from_python(kwargs, id);
    // make_vec checks the id, kwargs and wrappers first, on this thread, without building envs.
    with_kwarg_errors(id, kwargs_, [&] {
      max_episode_steps_ =
          wrappers::describe_wrapped(describe(id, kwargs_), wrappers_).max_episode_steps;
    });
    py::gil_scoped_release release;
    env_ = vector::make_vec(id, num_envs, kwargs_, wrappers::wrapping(wrappers_), options);
  }

  py::tuple reset(const py::object& seed, const py::object& options, const py::object& mask) {
    const std::optional<std::uint64_t> seed_value = seed_from_python(seed, env_->name() + ".reset");
    Options options_value;
    if (!options.is_none()) {
      options_value = params_from_python(options.cast<py::dict>(), env_->name() + ".reset options");
    }
    std::optional<Array> mask_value;
    if (!mask.is_none()) {
      mask_value = array_from_python(mask, env_->name() + ".reset: reset_mask");
    }
    const vector::VectorResetResult* result = nullptr;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      result = mask_value ? &env_->reset(seed_value, options_value, *mask_value)
                          : &env_->reset(seed_value, options_value);
    }
    return py::make_tuple(observations(result->obs), to_python(result->infos, /*copy=*/true));
  }

  py::tuple step(const py::handle& actions) {
    const Value actions_value = convert_actions(actions);
    const vector::VectorStepResult* result = nullptr;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      result = &env_->step(actions_value);
    }
    return step_tuple(*result);
  }

  void step_async(const py::handle& actions) {
    AsyncVectorEnv& async = as_async("step_async");
    const Value actions_value = convert_actions(actions);
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    async.step_async(actions_value);
  }

  py::tuple step_wait() {
    AsyncVectorEnv& async = as_async("step_wait");
    const vector::VectorStepResult* result = nullptr;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      result = &async.step_wait();
    }
    return step_tuple(*result);
  }

  py::tuple render() {
    std::vector<Array> frames;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      frames = env_->render();
    }
    py::tuple out(frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i) out[i] = to_numpy(frames[i]);
    return out;
  }

  void close() {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    env_->close();
  }

  int num_envs() const { return env_->num_envs(); }
  int num_threads() const {
    const auto* async = dynamic_cast<const AsyncVectorEnv*>(env_.get());
    return async != nullptr ? async->num_threads() : 1;
  }
  int num_workers() const {
    const auto* workers = dynamic_cast<const vector::ProcessVectorEnv*>(env_.get());
    return workers != nullptr ? workers->num_workers() : 0;
  }
  std::string autoreset_mode() const { return vector::autoreset_mode_name(env_->autoreset_mode()); }
  std::shared_ptr<Space> space(const Space& space) const {
    return std::shared_ptr<Space>(env_, const_cast<Space*>(&space));
  }
  std::shared_ptr<Space> single_observation_space() const {
    return space(env_->single_observation_space());
  }
  std::shared_ptr<Space> single_action_space() const { return space(env_->single_action_space()); }
  std::shared_ptr<Space> observation_space() const { return space(env_->observation_space()); }
  std::shared_ptr<Space> action_space() const { return space(env_->action_space()); }
  const VectorEnv& env() const { return *env_; }
  const std::string& id() const { return id_; }
  std::string name() const { return env_->name(); }
  std::optional<std::int64_t> max_episode_steps() const { return max_episode_steps_; }
  const std::vector<std::string>& wrappers() const { return wrappers_; }
  bool closed() const { return env_->closed(); }
  bool is_async() const { return dynamic_cast<const AsyncVectorEnv*>(env_.get()) != nullptr; }

 private:
  // Actions as a Value laid out as the batched action space, converted as a single env's are.
  Value convert_actions(const py::handle& actions) const {
    return value_from_python(actions, env_->action_space(), Cast::kSameKind,
                             env_->name() + ".step");
  }

  AsyncVectorEnv& as_async(const char* method) {
    auto* async = dynamic_cast<AsyncVectorEnv*>(env_.get());
    if (async == nullptr) {
      throw py::type_error(env_->name() + "." + method +
                           ": only the thread pool (mode=\"async\") steps asynchronously");
    }
    return *async;
  }

  // The observation batch as numpy views, made once: reset and step write the same arrays. A
  // Dict or Tuple is a new container each call (of the same arrays), so that what a caller does
  // to one does not show in the next.
  py::object observations(const Value& obs) {
    if (observations_.is_none() || obs.leaves().front().raw_data() != observed_data_) {
      observations_ = to_python(obs);
      observed_data_ = obs.leaves().front().raw_data();
    }
    if (py::isinstance<py::dict>(observations_)) return observations_.attr("copy")();
    return observations_;  // an array, or a tuple (immutable)
  }

  py::tuple step_tuple(const vector::VectorStepResult& result) {
    return py::make_tuple(observations(result.obs), copy_of(result.rewards),
                          copy_of(result.terminated), copy_of(result.truncated),
                          to_python(result.infos, /*copy=*/true));
  }

  std::string id_;
  std::vector<std::string> wrappers_;
  Params kwargs_;
  std::optional<std::int64_t> max_episode_steps_;
  std::shared_ptr<VectorEnv> env_;
  std::mutex mutex_;
  py::object observations_ = py::none();
  const void* observed_data_ = nullptr;
};

}  // namespace

void bind_vector(py::module_& module) {
  py::class_<VectorHandle>(module, "VectorEnv",
                           "num_envs pixelgym envs stepped as one (C++): use pixelgym.make_vec.")
      .def(py::init<const std::string&, int, const py::dict&, const std::vector<std::string>&,
                    const std::string&, int, const std::string&, bool, int>(),
           py::arg("id"), py::arg("num_envs"), py::arg("kwargs") = py::dict(),
           py::arg("wrappers") = std::vector<std::string>{}, py::arg("mode") = "async",
           py::arg("num_threads") = 0, py::arg("autoreset_mode") = "NextStep",
           py::arg("share_gl_contexts") = true, py::arg("num_workers") = 0)
      .def("reset", &VectorHandle::reset, py::arg("seed") = py::none(),
           py::arg("options") = py::none(), py::arg("reset_mask") = py::none(),
           "Resets every env (env i with seed + i), or those of reset_mask: (obs, infos).")
      .def("step", &VectorHandle::step, py::arg("actions"),
           "(obs, rewards, terminated, truncated, infos); obs are the vector env's buffers")
      .def("step_async", &VectorHandle::step_async, py::arg("actions"),
           "Starts a step on the thread pool and returns.")
      .def("step_wait", &VectorHandle::step_wait, "The results of the step begun by step_async.")
      .def("render", &VectorHandle::render,
           "Each env's current frame, (H, W, 3) uint8, env 0 first: a tuple of num_envs arrays.")
      .def("close", &VectorHandle::close, "Closes every env; calling it again does nothing.")
      .def_property_readonly("num_envs", &VectorHandle::num_envs)
      .def_property_readonly("num_threads", &VectorHandle::num_threads,
                             "Threads that run envs, the caller's included (1 for mode sync).")
      .def_property_readonly("num_workers", &VectorHandle::num_workers,
                             "Worker processes that run envs (mode process; 0 otherwise).")
      .def_property_readonly("autoreset_mode", &VectorHandle::autoreset_mode,
                             "\"NextStep\", \"SameStep\" or \"Disabled\".")
      .def_property_readonly("single_observation_space", &VectorHandle::single_observation_space)
      .def_property_readonly("single_action_space", &VectorHandle::single_action_space)
      .def_property_readonly("observation_space", &VectorHandle::observation_space,
                             "The batched observation space (a leading num_envs axis).")
      .def_property_readonly("action_space", &VectorHandle::action_space)
      .def_property_readonly("id", &VectorHandle::id)
      .def_property_readonly("name", &VectorHandle::name)
      .def_property_readonly("max_episode_steps", &VectorHandle::max_episode_steps,
                             "The step at which each env truncates; None for no limit.")
      .def_property_readonly("wrappers", &VectorHandle::wrappers,
                             "The --wrap specs applied to every env, innermost first.")
      .def_property_readonly("closed", &VectorHandle::closed)
      .def_property_readonly("is_async", &VectorHandle::is_async)
      .def_property_readonly("metadata", [](const VectorHandle& handle) {
        const auto& metadata = handle.env().metadata();
        py::dict out;
        out["render_modes"] = metadata.render_modes;
        out["render_fps"] = metadata.render_fps;
        out["autoreset_mode"] = vector::autoreset_mode_name(metadata.autoreset_mode);
        return out;
      });
}

}  // namespace pixelgym::python
