#include "pixelgym/envs/spaces/discrete.h"

#include <limits>
#include <stdexcept>
#include <string>

namespace pixelgym::spaces {

Discrete::Discrete(std::int64_t n, std::int64_t start) : n_(n), start_(start) {
  if (n <= 0) throw std::invalid_argument("Discrete: n must be positive, got " + std::to_string(n));
  // start + n - 1, the largest element, must be an int64 (found by fuzz/spaces_fuzz.cc: it
  // overflowed in mismatch()).
  if (start > std::numeric_limits<std::int64_t>::max() - (n - 1)) {
    throw std::invalid_argument("Discrete: start + n - 1 must fit in int64, got start = " +
                                std::to_string(start) + ", n = " + std::to_string(n));
  }
}

Value Discrete::sample(Rng& rng) const {
  return Array::scalar<std::int64_t>(start_ + rng.integer(0, n_ - 1));
}

std::string Discrete::mismatch(const Value& value) const {
  if (!value.is_array()) return std::string("expected an integer scalar, got a ") + value.kind();
  const Array& array = value.array();
  if (!is_integer(array.dtype())) {
    return std::string("dtype ") + dtype_name(array.dtype()) + ", expected an integer dtype";
  }
  if (!array.shape().empty()) return "shape " + shape_to_string(array.shape()) + ", expected ()";
  // Read exactly: through a double, int64s past 2^53 were rounded (found by fuzz/spaces_fuzz: a
  // sample of Discrete(97, start=7006863666131853568) was judged outside it).
  const std::int64_t x = array.element_as_int64(0);
  if (x < start_ || static_cast<std::uint64_t>(x) - static_cast<std::uint64_t>(start_) >=
                        static_cast<std::uint64_t>(n_)) {
    return std::to_string(x) + " is outside {" + std::to_string(start_) + ", ..., " +
           std::to_string(start_ + (n_ - 1)) + "}";
  }
  return "";
}

std::string Discrete::to_string() const {
  return "Discrete(" + std::to_string(n_) +
         (start_ != 0 ? ", start=" + std::to_string(start_) : std::string()) + ")";
}

bool Discrete::equals(const Space& other) const {
  const auto* discrete = dynamic_cast<const Discrete*>(&other);
  return discrete != nullptr && discrete->n_ == n_ && discrete->start_ == start_;
}

}  // namespace pixelgym::spaces
