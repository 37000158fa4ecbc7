// The memory check of make_vec: about how much memory num_envs envs take, against what the
// machine (or the process's cgroup) has available, before any env is built.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "pixelgym/envs/space.h"

namespace pixelgym::vector {

/// About how many bytes one env takes, from its spaces alone (a lower estimate: what is not
/// counted here is not charged to the user):
/// - kEnvBaseBytes for the env itself (its simulation, wrappers, bookkeeping);
/// - twice the bytes of an element of `observation_space` (the env's observation as wrapped, and
///   its row of the vector env's batch);
/// - for each uint8 image leaf, (H, W, C) with C 1, 3 or 4, of `unwrapped_observation_space`,
///   kBytesPerDrawnPixel per pixel: what the renderer keeps to draw it (llvmpipe's color, depth
///   and multisample buffers; measured 100-140 bytes per pixel for 32x32 to 256x256 frames).
std::uint64_t estimate_env_bytes(const Space& unwrapped_observation_space,
                                 const Space& observation_space);

/// What an env costs beside its observations (measured: a state-only cart-pole about 270 KiB,
/// a grid world less than this).
inline constexpr std::uint64_t kEnvBaseBytes = 64 * 1024;
/// What the renderer keeps per pixel of an image observation (see estimate_env_bytes).
inline constexpr std::uint64_t kBytesPerDrawnPixel = 96;

/// Memory the process may still take, and where the figure comes from.
struct AvailableMemory {
  std::uint64_t bytes = 0;
  /// "MemAvailable in /proc/meminfo", or the cgroup's file(s) when its limit is lower.
  std::string source;
};

/// The lower of /proc/meminfo's MemAvailable and what the process's cgroup (v2: memory.max less
/// memory.current, of its own cgroup and each above it; v1: memory.limit_in_bytes less
/// memory.usage_in_bytes) still allows; std::nullopt when neither can be read.
std::optional<AvailableMemory> available_memory();

/// Throws std::invalid_argument naming num_envs, the estimate and the memory available when
/// `num_envs` envs of `per_env_bytes` each would not fit in `available` (nothing is thrown when
/// `available` is unknown). `who` begins the message ("make_vec(\"CartPole-v0\")").
void check_memory(const std::string& who, int num_envs, std::uint64_t per_env_bytes,
                  const std::optional<AvailableMemory>& available);

/// "1.5 GiB", "740 KiB", "12 bytes" (up to EiB; the trainer's estimates pass 2^64 bytes).
std::string format_bytes(double bytes);

}  // namespace pixelgym::vector
