// Env: one env from the registry, stepped from Python with the GIL released; ids(), info().
#include "pixelgym/envs/env.h"

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/wrappers/wrapper_spec.h"
#include "python/bindings.h"
#include "python/convert.h"

namespace pixelgym::python {
namespace {

// Whether the first problem resolve_params meets in `kwargs` (it checks them in key order: the
// order of Params, a std::map) is a type mismatch rather than an unknown name.
bool first_kwarg_problem_is_type(const std::string& id, const Params& kwargs) {
  std::shared_ptr<const EnvSpec> spec;
  try {
    spec = default_registry().spec(id);
  } catch (const std::invalid_argument&) {
    return false;  // an unknown id
  }
  for (const auto& [key, value] : kwargs) {
    ParamType declared = ParamType::kInt;  // max_episode_steps, the reserved kwarg
    if (key != "max_episode_steps") {
      const auto found = std::find_if(spec->params.begin(), spec->params.end(),
                                      [&](const ParamSpec& param) { return param.name == key; });
      if (found == spec->params.end()) return false;
      declared = found->type();
    }
    const bool fits = value.type() == declared ||
                      (declared == ParamType::kFloat && value.type() == ParamType::kInt);
    if (!fits) return true;
  }
  return false;
}

py::object param_to_python(const Param& value) {
  switch (value.type()) {
    case ParamType::kBool:
      return py::bool_(value.as_bool());
    case ParamType::kInt:
      return py::int_(value.as_int());
    case ParamType::kFloat:
      return py::float_(value.as_float());
    case ParamType::kString:
      return py::str(value.as_string());
  }
  return py::none();
}

py::dict params_to_python(const Params& params) {
  py::dict out;
  for (const auto& [key, value] : params) out[py::str(key)] = param_to_python(value);
  return out;
}

py::dict metadata_to_python(const Metadata& metadata) {
  py::dict out;
  out["render_modes"] = metadata.render_modes;
  out["render_fps"] = metadata.render_fps;
  out["render_shape"] = metadata.render_shape ? py::cast(*metadata.render_shape) : py::none();
  return out;
}

// A single env's info: arrays copied (an env may reuse its info buffers), 0-d ones as numpy
// scalars, as Gymnasium's envs report numbers.
py::object info_to_python(const Info& info) {
  return to_python(Value(info), /*copy=*/true, /*scalars=*/true);
}

// A single env's observation: views of the arrays the step allocated (zero copy), but a 0-d
// array (a Discrete observation) as a numpy scalar, as Gymnasium's envs return it.
py::object observation_to_python(const Value& obs) {
  return to_python(obs, /*copy=*/false, /*scalars=*/true);
}

// One env made from the registry (with a wrapper stack), as the Python class _core.Env. Calls
// release the GIL while C++ runs; a mutex keeps two Python threads from using the env at once
// (an Env is used from one thread at a time: the second caller waits).
class EnvHandle {
 public:
  EnvHandle(const std::string& id, const py::dict& kwargs, std::vector<std::string> wrappers)
      : id_(id), wrappers_(std::move(wrappers)) {
    kwargs_ = params_from_python(kwargs, id);
    EnvDescription description;
    with_kwarg_errors(id, kwargs_, [&] {
      description = wrappers::describe_wrapped(describe(id, kwargs_), wrappers_);
    });
    max_episode_steps_ = description.max_episode_steps;
    py::gil_scoped_release release;
    env_ = wrappers::apply_wrappers(make(id, kwargs_), wrappers_);
    resolved_kwargs_ = env_->spec() != nullptr ? env_->spec()->kwargs : Params{};
  }

  py::tuple reset(const py::object& seed, const py::object& options) {
    const std::optional<std::uint64_t> seed_value = seed_from_python(seed, name() + ".reset");
    Options options_value;
    if (!options.is_none()) {
      options_value = params_from_python(options.cast<py::dict>(), name() + ".reset options");
    }
    ResetResult result;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      result = env_->reset(seed_value, options_value);
    }
    return py::make_tuple(observation_to_python(result.obs), info_to_python(result.info));
  }

  py::tuple step(const py::handle& action) {
    const Value action_value =
        value_from_python(action, env_->action_space(), Cast::kSameKind, name() + ".step");
    StepResult result;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      result = env_->step(action_value);
    }
    return py::make_tuple(observation_to_python(result.obs), result.reward, result.terminated,
                          result.truncated, info_to_python(result.info));
  }

  py::object render() {
    Array frame;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      frame = env_->render();
    }
    return to_numpy(frame);
  }

  void close() {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    env_->close();
  }

  // The spaces keep the env's memory alive (aliasing shared_ptrs): a space outlives its env.
  std::shared_ptr<Space> observation_space() const {
    return std::shared_ptr<Space>(env_, const_cast<Space*>(&env_->observation_space()));
  }
  std::shared_ptr<Space> action_space() const {
    return std::shared_ptr<Space>(env_, const_cast<Space*>(&env_->action_space()));
  }

  py::dict metadata() const { return metadata_to_python(env_->metadata()); }
  const std::string& id() const { return id_; }
  std::string name() const { return env_ ? env_->name() : id_; }
  std::optional<std::int64_t> max_episode_steps() const { return max_episode_steps_; }
  py::dict kwargs() const { return params_to_python(resolved_kwargs_); }
  const std::vector<std::string>& wrappers() const { return wrappers_; }
  bool closed() const { return env_->closed(); }

 private:
  std::string id_;
  std::vector<std::string> wrappers_;
  Params kwargs_;
  Params resolved_kwargs_;
  std::optional<std::int64_t> max_episode_steps_;
  std::shared_ptr<Env> env_;
  std::mutex mutex_;
};

}  // namespace

void with_kwarg_errors(const std::string& id, const Params& kwargs,
                       const std::function<void()>& make) {
  try {
    make();
  } catch (const std::invalid_argument& error) {
    if (first_kwarg_problem_is_type(id, kwargs)) throw py::type_error(error.what());
    throw;
  }
}

void bind_env(py::module_& module) {
  py::class_<EnvHandle>(module, "Env",
                        "One pixelgym env (C++), made from the registry: use pixelgym.make.")
      .def(py::init<const std::string&, const py::dict&, std::vector<std::string>>(), py::arg("id"),
           py::arg("kwargs") = py::dict(), py::arg("wrappers") = std::vector<std::string>{})
      .def("reset", &EnvHandle::reset, py::arg("seed") = py::none(),
           py::arg("options") = py::none(),
           "Starts an episode: (obs, info). The GIL is released while C++ runs.")
      .def("step", &EnvHandle::step, py::arg("action"),
           "(obs, reward, terminated, truncated, info); the action is converted and checked "
           "against the action space")
      .def("render", &EnvHandle::render, "The current frame, (H, W, 3) uint8.")
      .def("close", &EnvHandle::close, "Releases the env; calling it again does nothing.")
      .def_property_readonly("observation_space", &EnvHandle::observation_space,
                             "The env's observation space (it keeps the env's memory alive).")
      .def_property_readonly("action_space", &EnvHandle::action_space)
      .def_property_readonly("metadata", &EnvHandle::metadata)
      .def_property_readonly("id", &EnvHandle::id)
      .def_property_readonly("name", &EnvHandle::name)
      .def_property_readonly("max_episode_steps", &EnvHandle::max_episode_steps,
                             "The step at which the env truncates; None for no limit.")
      .def_property_readonly("kwargs", &EnvHandle::kwargs,
                             "The kwargs the env was made with, every declared one (defaults "
                             "filled in), max_episode_steps excluded.")
      .def_property_readonly("wrappers", &EnvHandle::wrappers)
      .def_property_readonly("closed", &EnvHandle::closed);

  module.def("ids", &registered_ids, "Every registered env id, sorted.");

  module.def(
      "describe",
      [](const std::string& id, const py::dict& kwargs, const std::vector<std::string>& wrappers) {
        const Params params = params_from_python(kwargs, id);
        EnvDescription description;
        with_kwarg_errors(id, params, [&] {
          description = wrappers::describe_wrapped(describe(id, params), wrappers);
        });
        const std::shared_ptr<const EnvSpec> spec = default_registry().spec(id);
        py::dict out;
        out["id"] = id;
        out["description"] = spec->description;
        out["observation_space"] = std::const_pointer_cast<Space>(description.observation_space);
        out["action_space"] = std::const_pointer_cast<Space>(description.action_space);
        out["max_episode_steps"] = description.max_episode_steps;
        out["cameras"] = description.cameras;
        out["metadata"] = metadata_to_python(description.metadata);
        py::list accepted;
        for (const ParamSpec& param : spec->params) {
          py::dict entry;
          entry["name"] = param.name;
          entry["type"] = param_type_name(param.type());
          entry["default"] = param_to_python(param.default_value);
          entry["doc"] = param.doc;
          accepted.append(entry);
        }
        out["kwargs"] = accepted;
        return out;
      },
      py::arg("id"), py::arg("kwargs") = py::dict(),
      py::arg("wrappers") = std::vector<std::string>{},
      "What make(id, **kwargs) gives, without making it: spaces, time limit, cameras, metadata and "
      "the kwargs the env accepts.");

  module.def(
      "wrapper_specs",
      [] {
        py::list out;
        for (const auto& help : wrappers::wrapper_spec_help()) {
          out.append(py::make_tuple(help.name, help.usage, help.summary));
        }
        return out;
      },
      "The --wrap spec forms: (name, usage, summary) for each wrapper.");
}

}  // namespace pixelgym::python
