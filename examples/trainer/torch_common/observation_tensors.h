// Observations as torch tensors: a vector env's batched arrays viewed without copying, by key.
#pragma once

#include <torch/torch.h>

#include <map>
#include <string>

#include "pixelgym/envs/value.h"

namespace pixelgym::trainer {

/// A batch of observations as tensors, one per key of the observation space (the single key ""
/// for a bare Box observation), each (B, *shape of the key) in the key's dtype.
using ObservationTensors = std::map<std::string, torch::Tensor>;

/// The torch dtype that stores a pixelgym dtype (kBool: torch::kBool, one byte per element).
torch::ScalarType torch_dtype(DType dtype);

/// A CPU tensor viewing `array`'s memory without copying (torch::from_blob); the tensor keeps
/// the array's storage alive. The memory is not copied, so the tensor sees later writes to it
/// (a vector env's next step); it must not be written through (a vector env's buffers are its
/// own).
torch::Tensor array_tensor(const Array& array);

/// Every array of a batched observation (a vector env's `obs`, or infos["final_obs"]) viewed as
/// array_tensor does: a bare Array under key "", a Dict's entries under their keys. Throws
/// std::invalid_argument for a Tuple or nested Dict.
ObservationTensors observation_tensors(const Value& batch);

/// Rows `index` (int64 (K,)) of every tensor of `obs` (dim 0), copied.
ObservationTensors select_rows(const ObservationTensors& obs, const torch::Tensor& index);

}  // namespace pixelgym::trainer
