// Array: the n-dimensional typed buffer that observations, actions and images are made of.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace pixelgym {

/// Element types an Array can hold, named as numpy's (kUInt8 is uint8, kFloat32 float32, ...).
/// `kBool` is stored as one byte per element (0 or 1).
enum class DType : std::uint8_t { kBool, kUInt8, kInt32, kInt64, kFloat32, kFloat64 };

/// Bytes per element of `dtype`.
std::size_t dtype_size(DType dtype);
/// numpy's name for `dtype`: "bool", "uint8", "int32", "int64", "float32", "float64".
const char* dtype_name(DType dtype);
/// True for kUInt8, kInt32 and kInt64.
bool is_integer(DType dtype);
/// True for kFloat32 and kFloat64.
bool is_floating(DType dtype);

/// The values a dtype can hold, as doubles (int64's ends rounded to the nearest double).
struct DTypeRange {
  /// The smallest value, inclusive.
  double low;
  /// The largest value, inclusive.
  double high;
};
/// The range of an integer dtype (kUInt8, kInt32, kInt64); kBool gives [0, 1]. Throws
/// std::invalid_argument for a floating dtype.
DTypeRange integer_range(DType dtype);

/// The DType that stores C++ type T; a compile error for any other type.
template <typename T>
constexpr DType dtype_of() {
  if constexpr (std::is_same_v<T, bool>)
    return DType::kBool;
  else if constexpr (std::is_same_v<T, std::uint8_t>)
    return DType::kUInt8;
  else if constexpr (std::is_same_v<T, std::int32_t>)
    return DType::kInt32;
  else if constexpr (std::is_same_v<T, std::int64_t>)
    return DType::kInt64;
  else if constexpr (std::is_same_v<T, float>)
    return DType::kFloat32;
  else if constexpr (std::is_same_v<T, double>)
    return DType::kFloat64;
  else
    static_assert(!sizeof(T), "pixelgym::Array has no dtype for this C++ type");
}

/// Extent of each dimension, outermost first (row-major, like numpy's default).
using Shape = std::vector<std::int64_t>;

/// numpy's spelling of a shape: "()", "(4,)", "(84, 84, 3)".
std::string shape_to_string(const Shape& shape);
/// Number of elements of a shape (1 for the scalar shape "()"). Throws std::invalid_argument
/// for a negative extent.
std::int64_t shape_size(const Shape& shape);

/// A contiguous, row-major, typed n-dimensional buffer.
///
/// Copying an Array is shallow: both copies view the same memory, which is reference-counted and
/// freed with its last view. `clone()` makes a deep copy. Views (`index`, `reshape`) share memory
/// with their source, so frame stacks and batched vector-env buffers cost no copies.
/// The memory layout (contiguous, explicit dtype and shape) is what numpy's buffer protocol and
/// `torch::from_blob` expect.
class Array {
 public:
  /// An empty float32 array of shape (0,).
  Array();
  /// A zero-filled array. Throws std::invalid_argument for a negative extent.
  Array(DType dtype, Shape shape);

  /// Wraps memory owned elsewhere without copying; `owner` is kept alive while any view exists
  /// (null: the caller keeps `data` alive, and shares_memory() is then always false). `data` must
  /// hold shape_size(shape) contiguous elements of `dtype`. Throws std::invalid_argument for null
  /// `data` or a negative extent.
  static Array from_external(void* data, DType dtype, Shape shape, std::shared_ptr<void> owner);

  /// A 0-dimensional array holding `value`.
  template <typename T>
  static Array scalar(T value) {
    Array array(dtype_of<T>(), {});
    *array.data<T>() = value;
    return array;
  }

  /// An array of the given shape filled from `values` in row-major order. Throws
  /// std::invalid_argument when the count does not match the shape.
  template <typename T>
  static Array from_vector(Shape shape, const std::vector<T>& values) {
    Array array(dtype_of<T>(), std::move(shape));
    array.check_count(static_cast<std::int64_t>(values.size()));
    std::copy(values.begin(), values.end(), array.data<T>());
    return array;
  }

  /// The element type.
  DType dtype() const { return dtype_; }
  /// The extent of each dimension, outermost first; empty for a 0-dimensional array.
  const Shape& shape() const { return shape_; }
  /// Number of dimensions: shape().size().
  int ndim() const { return static_cast<int>(shape_.size()); }
  /// Number of elements.
  std::int64_t size() const { return size_; }
  /// Bytes of the elements: size() * dtype_size(dtype()).
  std::size_t nbytes() const { return static_cast<std::size_t>(size_) * dtype_size(dtype_); }

  /// Typed pointer to the first element. Throws std::invalid_argument when T is not the dtype.
  template <typename T>
  T* data() {
    check_dtype(dtype_of<T>());
    return reinterpret_cast<T*>(data_);
  }
  /// Typed pointer to the first element, read-only. Throws as the non-const form.
  template <typename T>
  const T* data() const {
    check_dtype(dtype_of<T>());
    return reinterpret_cast<const T*>(data_);
  }
  /// Untyped pointer to the first element, whatever the dtype (nbytes() bytes follow it).
  void* raw_data() { return data_; }
  const void* raw_data() const { return data_; }

  /// The single element of a one-element array. Throws std::invalid_argument on a dtype
  /// mismatch or when size() != 1.
  template <typename T>
  T item() const {
    check_single();
    return *data<T>();
  }
  /// Element `flat_index` (row-major) converted to double, whatever the dtype. Throws
  /// std::out_of_range unless 0 <= flat_index < size().
  double element_as_double(std::int64_t flat_index) const;
  /// Element `flat_index` of a bool or integer array, exactly (a double rounds int64s past 2^53).
  /// Throws std::invalid_argument for a floating dtype, std::out_of_range as element_as_double.
  std::int64_t element_as_int64(std::int64_t flat_index) const;

  /// A deep copy with its own memory.
  Array clone() const;
  /// The sub-array at position `i` of the leading dimension, sharing memory (numpy's `a[i]`).
  /// Throws std::out_of_range for a 0-dimensional array or i outside [0, shape()[0]).
  Array index(std::int64_t i) const;
  /// Rows [begin, end) of the leading dimension, sharing memory (numpy's `a[begin:end]`): a slot
  /// range of a batch, a window of a frame ring. Throws std::out_of_range unless
  /// 0 <= begin <= end <= shape()[0].
  Array slice(std::int64_t begin, std::int64_t end) const;
  /// The same memory seen with another shape of the same size. Throws std::invalid_argument.
  Array reshape(Shape shape) const;
  /// Copies `source`'s elements into this array's memory. Throws std::invalid_argument on a
  /// dtype or shape mismatch.
  void copy_from(const Array& source);

  /// The allocation this array keeps alive, shared by every view of it (for `from_external`, the
  /// owner given): for accounting the memory that arrays hold, and for recognizing whose memory
  /// a view is (std::get_deleter on an owner made with a deleter of its own).
  const std::shared_ptr<void>& storage() const { return storage_; }
  /// True when both arrays view the same allocation (numpy's `shares_memory` for our layouts);
  /// false when either has no storage (from_external with a null owner).
  bool shares_memory(const Array& other) const;
  /// Same dtype, same shape and identical bytes.
  bool equals(const Array& other) const;

  /// "int64 () 3", "float32 (2,) [0.5, -1]", or "uint8 (84, 84, 3)" when large.
  std::string to_string() const;

 private:
  void check_dtype(DType requested) const;
  void check_single() const;
  void check_count(std::int64_t count) const;

  std::shared_ptr<void> storage_;  // keeps the allocation alive
  std::byte* data_ = nullptr;      // first element of this view
  DType dtype_ = DType::kFloat32;
  Shape shape_;
  std::int64_t size_ = 0;
};

}  // namespace pixelgym
