#include "envs/space.h"

#include <stdexcept>

namespace pixelgym {

Value Space::sample() const {
  if (!rng_) seed();
  return sample(*rng_);
}

std::uint64_t Space::seed(std::optional<std::uint64_t> seed) const {
  const std::uint64_t used = seed ? *seed : Rng::entropy_seed();
  rng_.emplace(used);
  return used;
}

void require_contains(const Space& space, const Value& value, const std::string& context) {
  const std::string reason = space.mismatch(value);
  if (!reason.empty()) {
    throw std::invalid_argument(context + ": " + value.to_string() + " is not in " +
                                space.to_string() + ": " + reason);
  }
}

}  // namespace pixelgym
