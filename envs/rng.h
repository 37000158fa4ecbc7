// Rng: the seeded generator behind env resets and space sampling.
#pragma once

#include <array>
#include <cstdint>

namespace pixelgym {

/// xoshiro256** (Blackman & Vigna) with distributions written here, so a seed gives the same
/// numbers with any C++ standard library (std:: distributions differ between libstdc++ and libc++).
///
/// Seeding: a 64-bit seed is expanded into the 256-bit state by four successive SplitMix64
/// outputs, the expansion the generator's authors recommend; every seed (0 included) gives a
/// valid, well-mixed state. Not thread-safe: one generator per env or space.
class Rng {
 public:
  /// A generator seeded with `seed`.
  explicit Rng(std::uint64_t seed = 0);

  /// A seed drawn from the operating system's entropy (std::random_device), for envs and
  /// spaces that were never seeded explicitly.
  static std::uint64_t entropy_seed();

  /// The next 64 uniformly distributed bits.
  std::uint64_t next_u64();
  /// Uniform in [0, 1), 53 bits of resolution.
  double uniform();
  /// Uniform in [low, high): low + (high - low) * uniform(), so rounding can give `high` itself.
  double uniform(double low, double high);
  /// Uniform integer in [low, high], both inclusive, without modulo bias. Throws
  /// std::invalid_argument when low > high.
  std::int64_t integer(std::int64_t low, std::int64_t high);
  /// Standard normal (Marsaglia's polar method; no cached second value, so the state alone
  /// determines the sequence).
  double normal();
  /// Exponential with rate 1.
  double exponential();

  /// The 256-bit state, which alone determines every number to come.
  const std::array<std::uint64_t, 4>& state() const { return state_; }
  /// A generator in `state` (one that state() returned: it gives the same numbers from here on,
  /// as copying and pickling a space need). Throws std::invalid_argument for the all-zero state,
  /// which xoshiro256** never leaves.
  static Rng from_state(const std::array<std::uint64_t, 4>& state);
  /// Same state: both give the same numbers from here on.
  friend bool operator==(const Rng& a, const Rng& b) { return a.state_ == b.state_; }
  friend bool operator!=(const Rng& a, const Rng& b) { return !(a == b); }

 private:
  std::array<std::uint64_t, 4> state_;
};

}  // namespace pixelgym
