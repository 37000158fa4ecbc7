// Refusing a run whose settings need more memory than the machine has, before it allocates: a
// batch_size or replay_capacity of 1e9 otherwise allocated until the kernel's OOM killer ended
// the process, or ended in an allocator trace that named no setting.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pixelgym::trainer {

/// What one setting costs in memory, as an algorithm estimates it.
struct MemoryUse {
  std::string member;  // the config member that sets it ("batch_size")
  double value = 0;    // the member's value, as given
  std::string what;    // what it sizes ("the sampled batches and their activations")
  double bytes = 0;
};

/// Throws std::invalid_argument when the uses add up to more than `available` bytes (described
/// by `source`; negative: unknown, nothing is refused): "{what}: these settings need about {total}
/// of memory but {available} is available
/// ({source}); the most is {member} {value}: {bytes} for {what}. Lower it.", every use listed.
void require_memory(const std::string& what, const std::vector<MemoryUse>& uses, double available,
                    const std::string& source);
/// The same, against what this process can take now (vector::available_memory: MemAvailable, or
/// the cgroup's limit when lower).
void require_memory(const std::string& what, const std::vector<MemoryUse>& uses);

}  // namespace pixelgym::trainer
