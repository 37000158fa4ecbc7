// FilterObservation: keeps only some keys of a Dict observation, in the order given
// (gymnasium.wrappers.FilterObservation).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/wrapper.h"

namespace pixelgym::wrappers {

/// The observation space becomes the Dict of the entries `keys` names, in the order of `keys`
/// (as Gymnasium 1.x, which builds the Dict from filter_keys), each subspace unchanged. The kept
/// arrays are copied into the caller's buffer; nothing is allocated per step.
class FilterObservation final : public ObservationWrapper {
 public:
  /// Throws std::invalid_argument when the observation space is not a spaces::Dict, when `keys`
  /// is empty or holds a key twice, and when a key is not in the Dict (naming the missing keys
  /// and listing those present).
  FilterObservation(std::unique_ptr<Env> env, std::vector<std::string> keys);

  /// The keys kept, in the observation's order.
  const std::vector<std::string>& keys() const { return keys_; }

 protected:
  std::string type_name() const override { return "FilterObservation"; }
  void observation(const Value& in, Value& out) override;

 private:
  std::vector<std::string> keys_;
  std::vector<std::size_t> source_;  // for each kept key, its position in the inner Dict
};

}  // namespace pixelgym::wrappers
