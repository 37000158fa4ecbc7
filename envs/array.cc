#include "pixelgym/envs/array.h"

#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace pixelgym {

std::size_t dtype_size(DType dtype) {
  switch (dtype) {
    case DType::kBool:
    case DType::kUInt8:
      return 1;
    case DType::kInt32:
    case DType::kFloat32:
      return 4;
    case DType::kInt64:
    case DType::kFloat64:
      return 8;
  }
  throw std::invalid_argument("dtype_size: unknown dtype");
}

const char* dtype_name(DType dtype) {
  switch (dtype) {
    case DType::kBool:
      return "bool";
    case DType::kUInt8:
      return "uint8";
    case DType::kInt32:
      return "int32";
    case DType::kInt64:
      return "int64";
    case DType::kFloat32:
      return "float32";
    case DType::kFloat64:
      return "float64";
  }
  return "unknown";
}

bool is_integer(DType dtype) {
  return dtype == DType::kUInt8 || dtype == DType::kInt32 || dtype == DType::kInt64;
}

bool is_floating(DType dtype) { return dtype == DType::kFloat32 || dtype == DType::kFloat64; }

DTypeRange integer_range(DType dtype) {
  switch (dtype) {
    case DType::kBool:
      return {0.0, 1.0};
    case DType::kUInt8:
      return {0.0, 255.0};
    case DType::kInt32:
      return {static_cast<double>(std::numeric_limits<std::int32_t>::min()),
              static_cast<double>(std::numeric_limits<std::int32_t>::max())};
    case DType::kInt64:
      return {static_cast<double>(std::numeric_limits<std::int64_t>::min()),
              static_cast<double>(std::numeric_limits<std::int64_t>::max())};
    default:
      throw std::invalid_argument(std::string("integer_range: ") + dtype_name(dtype) +
                                  " is not an integer dtype");
  }
}

std::string shape_to_string(const Shape& shape) {
  std::string text = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) text += ", ";
    text += std::to_string(shape[i]);
  }
  if (shape.size() == 1) text += ",";
  return text + ")";
}

std::int64_t shape_size(const Shape& shape) {
  std::int64_t size = 1;
  for (std::int64_t extent : shape) {
    if (extent < 0) {
      throw std::invalid_argument("Array: shape " + shape_to_string(shape) +
                                  " has a negative extent");
    }
    size *= extent;
  }
  return size;
}

Array::Array() : Array(DType::kFloat32, {0}) {}

Array::Array(DType dtype, Shape shape)
    : dtype_(dtype), shape_(std::move(shape)), size_(shape_size(shape_)) {
  const std::size_t bytes = nbytes();
  // Value-initialized (zeroed); at least one byte so that every array has a distinct address.
  std::shared_ptr<std::byte[]> block(new std::byte[bytes > 0 ? bytes : 1]());
  data_ = block.get();
  storage_ = std::move(block);
}

Array Array::from_external(void* data, DType dtype, Shape shape, std::shared_ptr<void> owner) {
  if (data == nullptr) throw std::invalid_argument("Array::from_external: data is null");
  Array array(dtype, {0});
  array.shape_ = std::move(shape);
  array.size_ = shape_size(array.shape_);
  array.data_ = static_cast<std::byte*>(data);
  array.storage_ = std::move(owner);
  return array;
}

namespace {

// The address of element `flat_index` of `size` elements of `dtype` from `data`; throws
// std::out_of_range naming the index and the size when it is outside them.
const std::byte* element_at(const std::byte* data, std::int64_t size, DType dtype,
                            std::int64_t flat_index) {
  if (flat_index < 0 || flat_index >= size) {
    throw std::out_of_range("Array: element " + std::to_string(flat_index) +
                            " out of range for size " + std::to_string(size));
  }
  return data + flat_index * static_cast<std::int64_t>(dtype_size(dtype));
}

}  // namespace

std::int64_t Array::element_as_int64(std::int64_t flat_index) const {
  const std::byte* p = element_at(data_, size_, dtype_, flat_index);
  switch (dtype_) {
    case DType::kBool:
      return *reinterpret_cast<const bool*>(p) ? 1 : 0;
    case DType::kUInt8:
      return *reinterpret_cast<const std::uint8_t*>(p);
    case DType::kInt32:
      return *reinterpret_cast<const std::int32_t*>(p);
    case DType::kInt64:
      return *reinterpret_cast<const std::int64_t*>(p);
    default:
      throw std::invalid_argument(std::string("Array::element_as_int64: dtype ") +
                                  dtype_name(dtype_) + " is not an integer dtype");
  }
}

double Array::element_as_double(std::int64_t flat_index) const {
  const std::byte* p = element_at(data_, size_, dtype_, flat_index);
  switch (dtype_) {
    case DType::kBool:
      return *reinterpret_cast<const bool*>(p) ? 1.0 : 0.0;
    case DType::kUInt8:
      return *reinterpret_cast<const std::uint8_t*>(p);
    case DType::kInt32:
      return *reinterpret_cast<const std::int32_t*>(p);
    case DType::kInt64:
      return static_cast<double>(*reinterpret_cast<const std::int64_t*>(p));
    case DType::kFloat32:
      return *reinterpret_cast<const float*>(p);
    case DType::kFloat64:
      return *reinterpret_cast<const double*>(p);
  }
  return 0.0;
}

Array Array::clone() const {
  Array copy(dtype_, shape_);
  if (nbytes() > 0) std::memcpy(copy.data_, data_, nbytes());
  return copy;
}

Array Array::index(std::int64_t i) const {
  if (shape_.empty()) throw std::out_of_range("Array::index: a 0-dimensional array has no index");
  if (i < 0 || i >= shape_[0]) {
    throw std::out_of_range("Array::index: index " + std::to_string(i) +
                            " out of range for shape " + shape_to_string(shape_));
  }
  Array view = *this;
  view.shape_.erase(view.shape_.begin());
  view.size_ = shape_size(view.shape_);
  view.data_ = data_ + i * view.size_ * static_cast<std::int64_t>(dtype_size(dtype_));
  return view;
}

Array Array::slice(std::int64_t begin, std::int64_t end) const {
  if (shape_.empty()) throw std::out_of_range("Array::slice: a 0-dimensional array has no rows");
  if (begin < 0 || begin > end || end > shape_[0]) {
    throw std::out_of_range("Array::slice: rows [" + std::to_string(begin) + ", " +
                            std::to_string(end) + ") out of range for shape " +
                            shape_to_string(shape_));
  }
  Array view = *this;
  view.shape_[0] = end - begin;
  view.size_ = shape_size(view.shape_);
  const std::int64_t row_size = shape_[0] == 0 ? 0 : size_ / shape_[0];
  view.data_ = data_ + begin * row_size * static_cast<std::int64_t>(dtype_size(dtype_));
  return view;
}

Array Array::reshape(Shape shape) const {
  if (shape_size(shape) != size_) {
    throw std::invalid_argument("Array::reshape: cannot view " + std::to_string(size_) +
                                " elements of shape " + shape_to_string(shape_) + " as " +
                                shape_to_string(shape));
  }
  Array view = *this;
  view.shape_ = std::move(shape);
  return view;
}

void Array::copy_from(const Array& source) {
  if (source.dtype_ != dtype_ || source.shape_ != shape_) {
    throw std::invalid_argument("Array::copy_from: expected " + std::string(dtype_name(dtype_)) +
                                " " + shape_to_string(shape_) + ", got " +
                                dtype_name(source.dtype_) + " " + shape_to_string(source.shape_));
  }
  if (nbytes() > 0) std::memmove(data_, source.data_, nbytes());
}

bool Array::shares_memory(const Array& other) const {
  return storage_ != nullptr && storage_ == other.storage_;
}

bool Array::equals(const Array& other) const {
  return dtype_ == other.dtype_ && shape_ == other.shape_ &&
         (nbytes() == 0 || std::memcmp(data_, other.data_, nbytes()) == 0);
}

std::string Array::to_string() const {
  std::ostringstream out;
  out << dtype_name(dtype_) << " " << shape_to_string(shape_);
  constexpr std::int64_t kMaxPrinted = 8;
  if (size_ > kMaxPrinted) return out.str();
  out << " ";
  if (!shape_.empty()) out << "[";
  for (std::int64_t i = 0; i < size_; ++i) {
    if (i > 0) out << ", ";
    out << element_as_double(i);
  }
  if (!shape_.empty()) out << "]";
  return out.str();
}

void Array::check_dtype(DType requested) const {
  if (requested != dtype_) {
    throw std::invalid_argument(std::string("Array: requested ") + dtype_name(requested) +
                                " data from a " + dtype_name(dtype_) + " array of shape " +
                                shape_to_string(shape_));
  }
}

void Array::check_single() const {
  if (size_ != 1) {
    throw std::invalid_argument("Array::item: needs exactly one element, shape is " +
                                shape_to_string(shape_));
  }
}

void Array::check_count(std::int64_t count) const {
  if (count != size_) {
    throw std::invalid_argument("Array: " + std::to_string(count) + " values given for shape " +
                                shape_to_string(shape_) + " (" + std::to_string(size_) +
                                " elements)");
  }
}

}  // namespace pixelgym
