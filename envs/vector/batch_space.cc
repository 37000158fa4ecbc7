#include "pixelgym/envs/vector/batch_space.h"

#include <cstring>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/spaces/multi_binary.h"
#include "pixelgym/envs/spaces/multi_discrete.h"
#include "pixelgym/envs/spaces/tuple.h"

namespace pixelgym::vector {
namespace {

Shape batched_shape(std::int64_t n, const Shape& shape) {
  Shape batched{n};
  batched.insert(batched.end(), shape.begin(), shape.end());
  return batched;
}

template <typename T>
std::vector<T> repeated(const std::vector<T>& values, std::int64_t n) {
  std::vector<T> out;
  out.reserve(values.size() * static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) out.insert(out.end(), values.begin(), values.end());
  return out;
}

}  // namespace

SpacePtr batch_space(const Space& space, std::int64_t n) {
  if (n < 1) {
    throw std::invalid_argument("batch_space: n must be >= 1, got " + std::to_string(n));
  }
  if (const auto* box = dynamic_cast<const spaces::Box*>(&space)) {
    return std::make_shared<spaces::Box>(repeated(box->low(), n), repeated(box->high(), n),
                                         batched_shape(n, *box->shape()), *box->dtype());
  }
  if (const auto* discrete = dynamic_cast<const spaces::Discrete*>(&space)) {
    const auto count = static_cast<std::size_t>(n);
    return std::make_shared<spaces::MultiDiscrete>(
        std::vector<std::int64_t>(count, discrete->n()),
        std::vector<std::int64_t>(count, discrete->start()));
  }
  if (const auto* multi = dynamic_cast<const spaces::MultiDiscrete*>(&space)) {
    std::vector<double> low;
    std::vector<double> high;
    for (std::size_t k = 0; k < multi->nvec().size(); ++k) {
      low.push_back(static_cast<double>(multi->start()[k]));
      high.push_back(static_cast<double>(multi->start()[k] + multi->nvec()[k] - 1));
    }
    return std::make_shared<spaces::Box>(repeated(low, n), repeated(high, n),
                                         batched_shape(n, *multi->shape()), DType::kInt64);
  }
  if (const auto* binary = dynamic_cast<const spaces::MultiBinary*>(&space)) {
    return std::make_shared<spaces::Box>(0.0, 1.0, batched_shape(n, *binary->shape()),
                                         DType::kUInt8);
  }
  if (const auto* dict = dynamic_cast<const spaces::Dict*>(&space)) {
    spaces::Dict::Entries entries;
    for (const auto& [key, subspace] : dict->entries()) {
      entries.emplace_back(key, batch_space(*subspace, n));
    }
    return std::make_shared<spaces::Dict>(std::move(entries));
  }
  if (const auto* tuple = dynamic_cast<const spaces::Tuple*>(&space)) {
    std::vector<SpacePtr> spaces;
    for (const SpacePtr& subspace : tuple->spaces()) spaces.push_back(batch_space(*subspace, n));
    return std::make_shared<spaces::Tuple>(std::move(spaces));
  }
  throw std::invalid_argument(
      "batch_space: cannot batch " + space.to_string() +
      " (supported: Box, Discrete, MultiDiscrete, MultiBinary, Dict, Tuple)");
}

Value batch_slot(const Value& batch, std::int64_t i) {
  if (batch.is_dict()) {
    ValueDict slot;
    const ValueDict& dict = batch.dict();
    for (std::size_t k = 0; k < dict.size(); ++k) {
      slot.insert(dict.keys()[k], batch_slot(dict.values()[k], i));
    }
    return slot;
  }
  if (batch.is_tuple()) {
    std::vector<Value> items;
    for (const Value& item : batch.tuple().items()) items.push_back(batch_slot(item, i));
    return ValueTuple(std::move(items));
  }
  return batch.array().index(i);
}

namespace {

// The memory of an array inside a const Value: the elements of a view are not const (the Value is
// const only because Tuple items are reachable through const accessors alone). Copying the
// Array handle instead would allocate (its shape is a std::vector).
void* writable_data(const Array& array) { return const_cast<void*>(array.raw_data()); }

}  // namespace

void copy_value(const Value& source, const Value& destination) {
  if (source.is_dict() && destination.is_dict()) {
    const ValueDict& from = source.dict();
    const ValueDict& to = destination.dict();
    if (from.keys() != to.keys()) {
      throw std::invalid_argument("copy_value: Dict keys differ: " + source.to_string() + " into " +
                                  destination.to_string());
    }
    for (std::size_t k = 0; k < from.size(); ++k) copy_value(from.values()[k], to.values()[k]);
    return;
  }
  if (source.is_tuple() && destination.is_tuple()) {
    const ValueTuple& from = source.tuple();
    const ValueTuple& to = destination.tuple();
    if (from.size() != to.size()) {
      throw std::invalid_argument("copy_value: Tuple lengths differ: " + source.to_string() +
                                  " into " + destination.to_string());
    }
    for (std::size_t k = 0; k < from.size(); ++k) copy_value(from.at(k), to.at(k));
    return;
  }
  if (source.is_array() && destination.is_array()) {
    const Array& from = source.array();
    const Array& to = destination.array();
    if (from.dtype() != to.dtype() || from.shape() != to.shape()) {
      throw std::invalid_argument("copy_value: cannot copy " + from.to_string() + " into " +
                                  to.to_string());
    }
    if (to.nbytes() > 0) std::memmove(writable_data(to), from.raw_data(), to.nbytes());
    return;
  }
  throw std::invalid_argument(std::string("copy_value: cannot copy a ") + source.kind() +
                              " into a " + destination.kind());
}

void zero_value(const Value& value) {
  if (value.is_dict()) {
    for (const Value& entry : value.dict().values()) zero_value(entry);
  } else if (value.is_tuple()) {
    for (const Value& item : value.tuple().items()) zero_value(item);
  } else if (value.array().nbytes() > 0) {
    std::memset(writable_data(value.array()), 0, value.array().nbytes());
  }
}

}  // namespace pixelgym::vector
