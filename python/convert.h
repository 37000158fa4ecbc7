// Conversions between pixelgym's values and Python objects: Arrays as zero-copy numpy views,
// Values as dicts and tuples, kwargs as typed Params.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <string>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/params.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/envs/value.h"

namespace pixelgym::python {

namespace py = pybind11;

/// A numpy array viewing `array`'s memory, no copy made; its `base` is a pixelgym Buffer holding
/// `array` (a shallow copy, which keeps the allocation alive as long as the numpy array lives).
py::array to_numpy(const Array& array);

/// An Array as a numpy view (to_numpy), a ValueDict as a dict (keys in order), a ValueTuple as a
/// tuple. With `copy`, every array is a numpy copy instead: for results whose buffers pixelgym
/// reuses (batched infos). With `scalars`, 0-d arrays become numpy scalars (np.int64(3), as
/// Gymnasium's envs return a Discrete observation).
py::object to_python(const Value& value, bool copy = false, bool scalars = false);

/// How far `value_from_python` converts a leaf whose dtype differs from its space's.
enum class Cast {
  /// Actions: numpy's "same_kind" casts (float64 to a float32 Box, int64 to int32...); a value of
  /// another kind (a float for a Discrete) keeps its dtype, and the space refuses it.
  kSameKind,
  /// `space.contains(x)`: Python scalars and lists take the space's dtype when numpy's
  /// "same_kind" allows it; numpy arrays only when the cast is "safe" (as gymnasium's Box.contains
  /// uses np.can_cast).
  kSafe,
};

/// `object` as a Value laid out as `space` says: a Mapping for a Dict space, a sequence for a
/// Tuple, an array-like for the rest, each leaf converted to the space's dtype as `cast` allows
/// and copied into memory pixelgym owns. Values, shapes and dtypes that do not fit are left for
/// the space to refuse (with its own message). Throws py::type_error for what cannot be an array
/// at all (None, a string, an object) and for dtypes pixelgym has no Array type for; `context`
/// starts that message.
Value value_from_python(py::handle object, const Space& space, Cast cast,
                        const std::string& context);

/// An array-like as an Array of its own dtype, copied (no cast). Throws py::type_error naming
/// `context` for what is not numeric or has no pixelgym dtype.
Array array_from_python(py::handle object, const std::string& context);

/// Python kwargs as typed Params: bool, int, float and str (numpy's scalars too). Throws
/// py::type_error "<context>: kwarg "k" must be a bool, int, float or str, got list" for any
/// other type, and py::value_error for an int beyond int64.
Params params_from_python(const py::dict& kwargs, const std::string& context);

/// A reset seed: None, or an int in [0, 2**64). Throws py::type_error / py::value_error naming
/// `context` and the value.
std::optional<std::uint64_t> seed_from_python(py::handle seed, const std::string& context);

/// numpy's dtype for `dtype`.
py::dtype numpy_dtype(DType dtype);

}  // namespace pixelgym::python
