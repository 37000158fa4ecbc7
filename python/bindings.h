// The pieces of the pixelgym._core module, each defined in its own file and added by module.cc.
#pragma once

#include <pybind11/pybind11.h>

#include <functional>
#include <string>

#include "pixelgym/envs/params.h"

namespace pixelgym::python {

namespace py = pybind11;

/// Buffer (an Array seen through the buffer protocol) and the error translators.
void bind_buffer_and_errors(py::module_& module);
/// Space and its subclasses (Box, Discrete, MultiDiscrete, MultiBinary, Dict, Tuple).
void bind_spaces(py::module_& module);
/// Env (one env made from the registry), ids(), info().
void bind_env(py::module_& module);
/// VectorEnv (make_vec: the loop or the thread pool).
void bind_vector(py::module_& module);

/// Runs `make` (which makes or describes env `id` with `kwargs`) and raises what it throws as
/// pixelgym does, except that a std::invalid_argument caused by a kwarg of the wrong type becomes
/// a Python TypeError with the same message (the registry reports unknown kwargs and wrong types
/// alike as std::invalid_argument; the binding tells them apart from the spec's declared types,
/// in the order the registry checks them).
void with_kwarg_errors(const std::string& id, const Params& kwargs,
                       const std::function<void()>& make);

}  // namespace pixelgym::python
