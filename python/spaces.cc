// The C++ spaces as Python classes: what pixelgym returns as observation_space / action_space when
// gymnasium is not importable (pixelgym/_gymnasium.py converts them to gymnasium.spaces).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/space.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/spaces/multi_binary.h"
#include "pixelgym/envs/spaces/multi_discrete.h"
#include "pixelgym/envs/spaces/tuple.h"
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

// Pickling (and so copy.deepcopy): each space's state is its parameters and the state of the
// generator its sample() draws from (None while unseeded), so that a copy samples as the original
// would (Gymnasium's spaces pickle their np_random as well). Subspaces of a Dict or Tuple travel as
// space objects, each with its own generator.
py::object generator_state(const Space& space) {
  const auto state = space.generator_state();
  if (!state) return py::none();
  return py::cast(*state);
}

template <typename SpaceType>
std::shared_ptr<SpaceType> with_generator(std::shared_ptr<SpaceType> space,
                                          const py::handle& state) {
  if (!state.is_none()) space->set_generator_state(state.cast<std::array<std::uint64_t, 4>>());
  return space;
}

// The pickled state `state` of a `name`, checked to be a tuple of `size` items.
py::tuple pickled(const char* name, const py::tuple& state, std::size_t size) {
  if (state.size() != size) {
    throw std::invalid_argument(std::string(name) + ".__setstate__: expected a tuple of " +
                                std::to_string(size) + " items (a pickled " + name + "), got " +
                                std::to_string(state.size()));
  }
  return state;
}

DType dtype_named(const std::string& name) {
  for (const DType dtype : {DType::kBool, DType::kUInt8, DType::kInt32, DType::kInt64,
                            DType::kFloat32, DType::kFloat64}) {
    if (name == dtype_name(dtype)) return dtype;
  }
  throw std::invalid_argument("Box.__setstate__: unknown dtype \"" + name + "\"");
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
      .def("is_bounded", &spaces::Box::is_bounded)
      .def(py::pickle(
          [](const spaces::Box& box) {
            return py::make_tuple(box.low(), box.high(), *box.shape(), dtype_name(*box.dtype()),
                                  generator_state(box));
          },
          [](const py::tuple& state) {
            pickled("Box", state, 5);
            return with_generator(
                std::make_shared<spaces::Box>(
                    state[0].cast<std::vector<double>>(), state[1].cast<std::vector<double>>(),
                    state[2].cast<Shape>(), dtype_named(state[3].cast<std::string>())),
                state[4]);
          }));

  py::class_<spaces::Discrete, Space, std::shared_ptr<spaces::Discrete>>(module, "Discrete")
      .def_property_readonly("n", &spaces::Discrete::n)
      .def_property_readonly("start", &spaces::Discrete::start)
      .def(py::pickle(
          [](const spaces::Discrete& space) {
            return py::make_tuple(space.n(), space.start(), generator_state(space));
          },
          [](const py::tuple& state) {
            pickled("Discrete", state, 3);
            return with_generator(std::make_shared<spaces::Discrete>(state[0].cast<std::int64_t>(),
                                                                     state[1].cast<std::int64_t>()),
                                  state[2]);
          }));

  py::class_<spaces::MultiDiscrete, Space, std::shared_ptr<spaces::MultiDiscrete>>(module,
                                                                                   "MultiDiscrete")
      .def_property_readonly("nvec",
                             [](const spaces::MultiDiscrete& space) {
                               return numpy_of(space.nvec(), *space.shape(), DType::kInt64);
                             })
      .def_property_readonly("start",
                             [](const spaces::MultiDiscrete& space) {
                               return numpy_of(space.start(), *space.shape(), DType::kInt64);
                             })
      .def(py::pickle(
          [](const spaces::MultiDiscrete& space) {
            return py::make_tuple(space.nvec(), space.start(), *space.shape(),
                                  generator_state(space));
          },
          [](const py::tuple& state) {
            pickled("MultiDiscrete", state, 4);
            return with_generator(
                std::make_shared<spaces::MultiDiscrete>(state[0].cast<std::vector<std::int64_t>>(),
                                                        state[1].cast<std::vector<std::int64_t>>(),
                                                        state[2].cast<Shape>()),
                state[3]);
          }));

  py::class_<spaces::MultiBinary, Space, std::shared_ptr<spaces::MultiBinary>>(module,
                                                                               "MultiBinary")
      .def_property_readonly("n",
                             [](const spaces::MultiBinary& space) {
                               const Shape shape = *space.shape();
                               return shape.size() == 1 ? py::object(py::int_(shape[0]))
                                                        : py::object(shape_tuple(shape));
                             })
      .def(py::pickle(
          [](const spaces::MultiBinary& space) {
            return py::make_tuple(*space.shape(), generator_state(space));
          },
          [](const py::tuple& state) {
            pickled("MultiBinary", state, 2);
            return with_generator(std::make_shared<spaces::MultiBinary>(state[0].cast<Shape>()),
                                  state[1]);
          }));

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
      .def(py::pickle(
          [](const spaces::Dict& dict) {
            py::list entries;
            for (const auto& [key, space] : dict.entries()) {
              entries.append(py::make_tuple(key, hold(space)));
            }
            return py::make_tuple(entries, generator_state(dict));
          },
          [](const py::tuple& state) {
            pickled("Dict", state, 2);
            spaces::Dict::Entries entries;
            for (const py::handle entry : state[0].cast<py::list>()) {
              const auto pair = entry.cast<py::tuple>();
              entries.emplace_back(pair[0].cast<std::string>(), pair[1].cast<SpaceHolder>());
            }
            return with_generator(std::make_shared<spaces::Dict>(std::move(entries)), state[1]);
          }))
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
      .def("__len__", [](const spaces::Tuple& tuple) { return tuple.spaces().size(); })
      .def(py::pickle(
          [](const spaces::Tuple& tuple) {
            py::list items;
            for (const SpacePtr& space : tuple.spaces()) items.append(hold(space));
            return py::make_tuple(items, generator_state(tuple));
          },
          [](const py::tuple& state) {
            pickled("Tuple", state, 2);
            std::vector<SpacePtr> items;
            for (const py::handle item : state[0].cast<py::list>()) {
              items.push_back(item.cast<SpaceHolder>());
            }
            return with_generator(std::make_shared<spaces::Tuple>(std::move(items)), state[1]);
          }));
}

}  // namespace pixelgym::python
