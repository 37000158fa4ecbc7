#include "examples/trainer/torch_common/observation_tensors.h"

#include <cstdint>
#include <stdexcept>
#include <vector>

namespace pixelgym::trainer {

torch::ScalarType torch_dtype(DType dtype) {
  switch (dtype) {
    case DType::kBool:
      return torch::kBool;
    case DType::kUInt8:
      return torch::kUInt8;
    case DType::kInt32:
      return torch::kInt32;
    case DType::kInt64:
      return torch::kInt64;
    case DType::kFloat32:
      return torch::kFloat32;
    case DType::kFloat64:
      return torch::kFloat64;
  }
  throw std::invalid_argument("torch_dtype: unknown dtype");
}

torch::Tensor array_tensor(const Array& array) {
  const Shape& shape = array.shape();
  // from_blob takes a non-const pointer; the tensor is documented as read-only.
  void* data = const_cast<void*>(array.raw_data());
  return torch::from_blob(
      data, std::vector<std::int64_t>(shape.begin(), shape.end()), [keep = array](void*) {},
      torch::TensorOptions().dtype(torch_dtype(array.dtype())));
}

ObservationTensors observation_tensors(const Value& batch) {
  ObservationTensors tensors;
  if (batch.is_array()) {
    tensors.emplace("", array_tensor(batch.array()));
    return tensors;
  }
  if (!batch.is_dict()) {
    throw std::invalid_argument("observation_tensors: expected an Array or a Dict of Arrays, got " +
                                std::string(batch.kind()));
  }
  const ValueDict& dict = batch.dict();
  for (std::size_t i = 0; i < dict.size(); ++i) {
    const Value& entry = dict.values()[i];
    if (!entry.is_array()) {
      throw std::invalid_argument("observation_tensors: key \"" + dict.keys()[i] +
                                  "\" must be an Array, got " + entry.kind());
    }
    tensors.emplace(dict.keys()[i], array_tensor(entry.array()));
  }
  return tensors;
}

ObservationTensors select_rows(const ObservationTensors& obs, const torch::Tensor& index) {
  ObservationTensors rows;
  for (const auto& [key, tensor] : obs) rows.emplace(key, tensor.index_select(0, index));
  return rows;
}

}  // namespace pixelgym::trainer
