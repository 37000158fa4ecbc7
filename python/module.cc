// pixelgym._core: the C++ side of the Python package pixelgym (python/pixelgym/ wraps it into
// gymnasium classes when gymnasium is importable).
#include <pybind11/pybind11.h>

#include "pixelgym/engine/robot_model.h"
#include "python/bindings.h"

PYBIND11_MODULE(_core, module) {
  module.doc() =
      "pixelgym's C++ envs, spaces and vector envs. Use the package pixelgym, which wraps them "
      "into gymnasium classes when gymnasium is importable.";
  pixelgym::python::bind_buffer_and_errors(module);
  pixelgym::python::bind_spaces(module);
  pixelgym::python::bind_env(module);
  pixelgym::python::bind_vector(module);
  module.def("assets_folder", &pixelgym::engine::assets_folder,
             "The folder of pixelgym's own assets: in a wheel or an install, the one installed "
             "with the engine library (found from its location); in the build tree, the source "
             "tree's assets/.");
}
