// The C++ spaces as Python classes: what pixelgym returns as observation_space / action_space when
// gymnasium is not importable (pixelgym/_gymnasium.py converts them to gymnasium.spaces).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>

#include "envs/space.h"
#include "envs/spaces/box.h"
#include "envs/spaces/dict.h"
#include "envs/spaces/discrete.h"
#include "envs/spaces/multi_binary.h"
#include "envs/spaces/multi_discrete.h"
#include "envs/spaces/tuple.h"
#include "python/bindings.h"
#include "python/convert.h"

namespace pixelgym::python {
namespace {

// Spaces are immutable but for the generator of the argument-less sample(); pybind11 holds them
// through non-const shared_ptrs.
using SpaceHolder = std::shared_ptr<Space>;

SpaceHolder hold(const SpacePtr& space) { return std::const_pointer_cast<Space>(space); }

py::tuple shape_tuple(const Shape& shape) {
  py::tuple tuple(shape.size());
  for (std::size_t i = 0; i < shape.size(); ++i) tuple[i] = shape[i];
  return tuple;
}

// `values` (row-major) as a numpy array of `dtype` and `shape`.
template <typename T>
py::array numpy_of(const std::vector<T>& values, const Shape& shape, DType dtype) {
  py::array flat = py::array(py::cast(values));
  return flat.attr("astype")(numpy_dtype(dtype)).attr("reshape")(shape_tuple(shape));
}

}  // namespace

void bind_spaces(py::module_& module) {
  py::class_<Space, SpaceHolder>(module, "Space",
                                 "A set of valid observations or actions (gymnasium.spaces.Space).")
      .def(
          "sample",
          [](const Space& space) {
            const Value value = space.sample();
            return to_python(value);
          },
          "A random element, drawn from the space's own generator (see seed).")
      .def(
          "seed",
          [](const Space& space, py::object seed) {
            return space.seed(seed_from_python(seed, "seed"));
          },
          py::arg("seed") = py::none(),
          "Reseeds the generator sample() draws from; returns the seed used.")
      .def(
          "contains",
          [](const Space& space, py::handle x) {
            try {
              return space.contains(value_from_python(x, space, Cast::kSafe, "contains"));
            } catch (const py::type_error&) {
              return false;
            }
          },
          py::arg("x"), "True when x is an element of this space.")
      .def("__contains__",
           [](const Space& space, py::handle x) {
             try {
               return space.contains(value_from_python(x, space, Cast::kSafe, "contains"));
             } catch (const py::type_error&) {
               return false;
             }
           })
      .def(
          "mismatch",
          [](const Space& space, py::handle x) {
            return space.mismatch(value_from_python(x, space, Cast::kSafe, "mismatch"));
          },
          py::arg("x"), "Why x is not an element of this space, or \"\" when it is.")
      .def_property_readonly("shape",
                             [](const Space& space) -> py::object {
                               const auto shape = space.shape();
                               if (!shape) return py::none();
                               return shape_tuple(*shape);
                             })
      .def_property_readonly("dtype",
                             [](const Space& space) -> py::object {
                               const auto dtype = space.dtype();
                               if (!dtype) return py::none();
                               return numpy_dtype(*dtype);
                             })
      .def("__repr__", &Space::to_string)
      .def("__eq__", [](const Space& space, py::handle other) {
        return py::isinstance<Space>(other) && space.equals(other.cast<const Space&>());
      });

  py::class_<spaces::Box, Space, std::shared_ptr<spaces::Box>>(module, "Box")
      .def_property_readonly("low",
                             [](const spaces::Box& box) {
                               return numpy_of(box.low(), box.shape().value(), *box.dtype());
                             })
      .def_property_readonly("high",
                             [](const spaces::Box& box) {
                               return numpy_of(box.high(), box.shape().value(), *box.dtype());
                             })
      .def("is_bounded", &spaces::Box::is_bounded);

  py::class_<spaces::Discrete, Space, std::shared_ptr<spaces::Discrete>>(module, "Discrete")
      .def_property_readonly("n", &spaces::Discrete::n)
      .def_property_readonly("start", &spaces::Discrete::start);

  py::class_<spaces::MultiDiscrete, Space, std::shared_ptr<spaces::MultiDiscrete>>(module,
                                                                                   "MultiDiscrete")
      .def_property_readonly("nvec",
                             [](const spaces::MultiDiscrete& space) {
                               return numpy_of(space.nvec(), *space.shape(), DType::kInt64);
                             })
      .def_property_readonly("start", [](const spaces::MultiDiscrete& space) {
        return numpy_of(space.start(), *space.shape(), DType::kInt64);
      });

  py::class_<spaces::MultiBinary, Space, std::shared_ptr<spaces::MultiBinary>>(module,
                                                                               "MultiBinary")
      .def_property_readonly("n", [](const spaces::MultiBinary& space) {
        const Shape shape = *space.shape();
        return shape.size() == 1 ? py::object(py::int_(shape[0])) : py::object(shape_tuple(shape));
      });

  py::class_<spaces::Dict, Space, std::shared_ptr<spaces::Dict>>(module, "Dict")
      .def("keys",
           [](const spaces::Dict& dict) {
             std::vector<std::string> keys;
             for (const auto& [key, space] : dict.entries()) keys.push_back(key);
             return keys;
           })
      .def_property_readonly("spaces",
                             [](const spaces::Dict& dict) {
                               py::dict out;
                               for (const auto& [key, space] : dict.entries()) {
                                 out[py::str(key)] = hold(space);
                               }
                               return out;
                             })
      .def("__getitem__",
           [](const spaces::Dict& dict, const std::string& key) {
             for (const auto& [name, space] : dict.entries()) {
               if (name == key) return hold(space);
             }
             throw py::key_error(key);
           })
      .def("__len__", [](const spaces::Dict& dict) { return dict.entries().size(); })
      .def("__iter__", [](const spaces::Dict& dict) {
        py::list keys;
        for (const auto& [key, space] : dict.entries()) keys.append(key);
        return py::iter(keys);
      });

  py::class_<spaces::Tuple, Space, std::shared_ptr<spaces::Tuple>>(module, "Tuple")
      .def_property_readonly("spaces",
                             [](const spaces::Tuple& tuple) {
                               py::tuple out(tuple.spaces().size());
                               for (std::size_t i = 0; i < tuple.spaces().size(); ++i) {
                                 out[i] = hold(tuple.spaces()[i]);
                               }
                               return out;
                             })
      .def("__getitem__",
           [](const spaces::Tuple& tuple, std::size_t i) {
             if (i >= tuple.spaces().size()) throw py::index_error(std::to_string(i));
             return hold(tuple.spaces()[i]);
           })
      .def("__len__", [](const spaces::Tuple& tuple) { return tuple.spaces().size(); });
}

}  // namespace pixelgym::python
