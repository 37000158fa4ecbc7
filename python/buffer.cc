// Buffer: an Array exposed through Python's buffer protocol (the base of every numpy observation
// pixelgym returns), and the translation of pixelgym's exceptions (envs/errors.h).
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/errors.h"
#include "python/bindings.h"
#include "python/convert.h"

namespace pixelgym::python {
namespace {

// The struct-module format character of `dtype`.
std::string buffer_format(DType dtype) {
  switch (dtype) {
    case DType::kBool:
      return "?";
    case DType::kUInt8:
      return py::format_descriptor<std::uint8_t>::format();
    case DType::kInt32:
      return py::format_descriptor<std::int32_t>::format();
    case DType::kInt64:
      return py::format_descriptor<std::int64_t>::format();
    case DType::kFloat32:
      return py::format_descriptor<float>::format();
    case DType::kFloat64:
      return py::format_descriptor<double>::format();
  }
  return "B";
}

// The Python class ResetNeeded is raised as; pixelgym/__init__.py sets it (a subclass of
// RuntimeError, and of gymnasium.error.ResetNeeded when gymnasium is importable).
py::object& reset_needed_type() {
  static auto* type = new py::object(py::reinterpret_borrow<py::object>(PyExc_RuntimeError));
  return *type;
}

}  // namespace

void bind_buffer_and_errors(py::module_& module) {
  py::class_<Array>(module, "Buffer", py::buffer_protocol(),
                    "Memory owned by pixelgym (an Array), seen through the buffer protocol: the "
                    "`base` of every numpy array pixelgym returns without copying. It keeps the "
                    "memory alive as long as any view of it exists.")
      .def_buffer([](Array& array) {
        std::vector<py::ssize_t> shape(array.shape().begin(), array.shape().end());
        std::vector<py::ssize_t> strides(shape.size());
        auto stride = static_cast<py::ssize_t>(dtype_size(array.dtype()));
        for (std::size_t i = shape.size(); i-- > 0;) {
          strides[i] = stride;
          stride *= shape[i];
        }
        return py::buffer_info(
            array.raw_data(), static_cast<py::ssize_t>(dtype_size(array.dtype())),
            buffer_format(array.dtype()), static_cast<py::ssize_t>(shape.size()), shape, strides);
      })
      .def_property_readonly("dtype", [](const Array& array) { return dtype_name(array.dtype()); })
      .def_property_readonly("shape",
                             [](const Array& array) {
                               py::tuple shape(array.shape().size());
                               for (std::size_t i = 0; i < array.shape().size(); ++i) {
                                 shape[i] = array.shape()[i];
                               }
                               return shape;
                             })
      .def_property_readonly("nbytes", &Array::nbytes)
      .def("__repr__",
           [](const Array& array) { return "pixelgym.Buffer(" + array.to_string() + ")"; });

  module.def(
      "_set_reset_needed_type", [](py::object type) { reset_needed_type() = std::move(type); },
      "The exception class that pixelgym::ResetNeeded is raised as.");

  // ResetNeeded derives from std::logic_error, as std::invalid_argument does: it is translated
  // here, before pybind11's own translators (std::invalid_argument -> ValueError,
  // std::out_of_range -> IndexError, std::runtime_error -> RuntimeError) see it.
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const ResetNeeded& reset_needed) {
      PyErr_SetString(reset_needed_type().ptr(), reset_needed.what());
    }
  });
}

}  // namespace pixelgym::python
