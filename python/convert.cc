#include "python/convert.h"

#include <cstring>
#include <limits>
#include <stdexcept>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/spaces/multi_binary.h"
#include "pixelgym/envs/spaces/multi_discrete.h"
#include "pixelgym/envs/spaces/tuple.h"

namespace pixelgym::python {
namespace {

// The pixelgym dtype of a numpy dtype, when it has one (native byte order is not required: the
// copy into an Array converts it).
std::optional<DType> dtype_from_numpy(const py::dtype& dtype) {
  const char kind = dtype.kind();
  const auto size = dtype.itemsize();
  if (kind == 'b' && size == 1) return DType::kBool;
  if (kind == 'u' && size == 1) return DType::kUInt8;
  if (kind == 'i' && size == 4) return DType::kInt32;
  if (kind == 'i' && size == 8) return DType::kInt64;
  if (kind == 'f' && size == 4) return DType::kFloat32;
  if (kind == 'f' && size == 8) return DType::kFloat64;
  return std::nullopt;
}

std::string python_type_name(py::handle object) {
  return py::str(py::type::handle_of(object).attr("__name__"));
}

py::module_& numpy() {
  static py::module_* module = new py::module_(py::module_::import("numpy"));  // lives forever
  return *module;
}

// `array`'s elements in an Array of `dtype` (its own dtype, or one it converts to exactly): a
// C-contiguous, native-order numpy copy first, then its bytes.
Array copy_to_array(const py::array& array, DType dtype) {
  // (np.asarray with order "C", not np.ascontiguousarray, which turns a 0-d array into a 1-d one.)
  py::array contiguous =
      numpy().attr("asarray")(array, py::arg("dtype") = numpy_dtype(dtype), py::arg("order") = "C");
  Shape shape(contiguous.shape(), contiguous.shape() + contiguous.ndim());
  Array out(dtype, std::move(shape));
  if (out.nbytes() > 0) std::memcpy(out.raw_data(), contiguous.data(), out.nbytes());
  return out;
}

// A numpy array of `object` converted towards `target` as `cast` allows, then copied into an
// Array of its (possibly unchanged) dtype.
Array leaf_from_python(py::handle object, DType target, Cast cast, const Space& space,
                       const std::string& context) {
  const bool is_numpy =
      py::isinstance<py::array>(object) || py::isinstance(object, numpy().attr("generic"));
  py::array array = numpy().attr("asarray")(object);
  const char kind = array.dtype().kind();
  if (kind != 'b' && kind != 'u' && kind != 'i' && kind != 'f') {
    throw py::type_error(context + ": expected a numeric array for " + space.to_string() +
                         ", got " + python_type_name(object) +
                         (is_numpy ? " of dtype " + std::string(py::str(array.dtype())) : ""));
  }
  const py::dtype wanted = numpy_dtype(target);
  const char* rule = (cast == Cast::kSafe && is_numpy) ? "safe" : "same_kind";
  if (!array.dtype().is(wanted) &&
      numpy().attr("can_cast")(array.dtype(), wanted, py::arg("casting") = rule).cast<bool>()) {
    array = array.attr("astype")(wanted);
  }
  const std::optional<DType> dtype = dtype_from_numpy(array.dtype());
  if (!dtype) {
    throw py::type_error(context + ": dtype " + std::string(py::str(array.dtype())) +
                         " has no pixelgym Array type (bool, uint8, int32, int64, float32, "
                         "float64) and cannot be cast to " +
                         dtype_name(target) + " for " + space.to_string());
  }
  return copy_to_array(array, *dtype);
}

}  // namespace

Array array_from_python(py::handle object, const std::string& context) {
  const py::array array = numpy().attr("asarray")(object);
  const std::optional<DType> dtype = dtype_from_numpy(array.dtype());
  if (!dtype) {
    throw py::type_error(context +
                         ": expected an array of bool, uint8, int32, int64, float32 or "
                         "float64, got " +
                         python_type_name(object) + " of dtype " +
                         std::string(py::str(array.dtype())));
  }
  return copy_to_array(array, *dtype);
}

py::dtype numpy_dtype(DType dtype) { return py::dtype(dtype_name(dtype)); }

py::array to_numpy(const Array& array) {
  const Shape& shape = array.shape();
  std::vector<py::ssize_t> strides(shape.size());
  auto stride = static_cast<py::ssize_t>(dtype_size(array.dtype()));
  for (std::size_t i = shape.size(); i-- > 0;) {
    strides[i] = stride;
    stride *= static_cast<py::ssize_t>(shape[i]);
  }
  // The base: a Buffer (py::class_<Array>) holding a shallow copy, which owns a reference to the
  // allocation; numpy keeps the base alive as long as the view.
  py::object base = py::cast(array);
  return py::array(numpy_dtype(array.dtype()), std::vector<py::ssize_t>(shape.begin(), shape.end()),
                   strides, array.raw_data(), base);
}

py::object to_python(const Value& value, bool copy, bool scalars) {
  if (value.is_array()) {
    py::array array = to_numpy(value.array());
    if (scalars && array.ndim() == 0) return array[py::tuple()];
    if (copy) return array.attr("copy")();
    return std::move(array);
  }
  if (value.is_dict()) {
    py::dict dict;
    const ValueDict& entries = value.dict();
    for (std::size_t i = 0; i < entries.size(); ++i) {
      dict[py::str(entries.keys()[i])] = to_python(entries.values()[i], copy, scalars);
    }
    return std::move(dict);
  }
  const ValueTuple& items = value.tuple();
  py::tuple tuple(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) tuple[i] = to_python(items.at(i), copy, scalars);
  return std::move(tuple);
}

Value value_from_python(py::handle object, const Space& space, Cast cast,
                        const std::string& context) {
  if (const auto* dict = dynamic_cast<const spaces::Dict*>(&space)) {
    if (!py::isinstance(object, py::module_::import("collections.abc").attr("Mapping"))) {
      throw py::type_error(context + ": expected a dict for " + space.to_string() + ", got " +
                           python_type_name(object));
    }
    ValueDict out;
    for (const auto& item : py::reinterpret_borrow<py::object>(object).attr("items")()) {
      const auto pair = item.cast<py::tuple>();
      if (!py::isinstance<py::str>(pair[0])) {
        throw py::type_error(context + ": Dict keys are strings, got " + python_type_name(pair[0]));
      }
      const auto key = pair[0].cast<std::string>();
      // A key the space lacks is converted as it stands, for the space to name it.
      out.insert(key, dict->has(key)
                          ? value_from_python(pair[1], dict->at(key), cast, context)
                          : leaf_from_python(pair[1], DType::kFloat64, cast, space, context));
    }
    return out;
  }
  if (const auto* tuple = dynamic_cast<const spaces::Tuple*>(&space)) {
    if (!py::isinstance<py::tuple>(object) && !py::isinstance<py::list>(object)) {
      throw py::type_error(context + ": expected a tuple for " + space.to_string() + ", got " +
                           python_type_name(object));
    }
    const auto items = py::reinterpret_borrow<py::sequence>(object);
    std::vector<Value> out;
    for (std::size_t i = 0; i < items.size(); ++i) {
      out.push_back(i < tuple->spaces().size()
                        ? value_from_python(items[i], *tuple->spaces()[i], cast, context)
                        : leaf_from_python(items[i], DType::kFloat64, cast, space, context));
    }
    return ValueTuple(std::move(out));
  }
  const std::optional<DType> dtype = space.dtype();
  if (!dtype) throw std::logic_error("value_from_python: a space without a dtype");
  return leaf_from_python(object, *dtype, cast, space, context);
}

Params params_from_python(const py::dict& kwargs, const std::string& context) {
  Params params;
  for (const auto& [key_object, value] : kwargs) {
    const auto key = key_object.cast<std::string>();
    if (py::isinstance<py::bool_>(value) || py::isinstance(value, numpy().attr("bool_"))) {
      params.insert_or_assign(key, Param(value.cast<bool>()));
    } else if (py::isinstance<py::int_>(value) || py::isinstance(value, numpy().attr("integer"))) {
      const py::int_ integer(py::reinterpret_borrow<py::object>(value));
      if (integer < py::int_(std::numeric_limits<std::int64_t>::min()) ||
          integer > py::int_(std::numeric_limits<std::int64_t>::max())) {
        throw py::value_error(context + ": kwarg \"" + key + "\" is out of int64's range, got " +
                              std::string(py::str(value)));
      }
      params.insert_or_assign(key, Param(static_cast<long long>(integer.cast<std::int64_t>())));
    } else if (py::isinstance<py::float_>(value) ||
               py::isinstance(value, numpy().attr("floating"))) {
      params.insert_or_assign(key, Param(value.cast<double>()));
    } else if (py::isinstance<py::str>(value)) {
      params.insert_or_assign(key, Param(value.cast<std::string>()));
    } else {
      throw py::type_error(context + ": kwarg \"" + key +
                           "\" must be a bool, int, float or str, got " + python_type_name(value) +
                           " " + std::string(py::repr(value)));
    }
  }
  return params;
}

std::optional<std::uint64_t> seed_from_python(py::handle seed, const std::string& context) {
  if (seed.is_none()) return std::nullopt;
  if (py::isinstance<py::bool_>(seed) ||
      !(py::isinstance<py::int_>(seed) || py::isinstance(seed, numpy().attr("integer")))) {
    throw py::type_error(context + ": seed must be None or an int, got " + python_type_name(seed) +
                         " " + std::string(py::repr(seed)));
  }
  const py::int_ value(py::reinterpret_borrow<py::object>(seed));
  if (value < py::int_(0) || value > py::int_(std::numeric_limits<std::uint64_t>::max())) {
    throw py::value_error(context + ": seed must be in [0, 2**64), got " +
                          std::string(py::str(seed)));
  }
  return value.cast<std::uint64_t>();
}

}  // namespace pixelgym::python
