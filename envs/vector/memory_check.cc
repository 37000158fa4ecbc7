#include "pixelgym/envs/vector/memory_check.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace pixelgym::vector {
namespace {

bool is_image(const Array& leaf) {
  return leaf.dtype() == DType::kUInt8 && leaf.ndim() == 3 &&
         (leaf.shape()[2] == 1 || leaf.shape()[2] == 3 || leaf.shape()[2] == 4);
}

std::optional<std::uint64_t> read_number(const std::string& path) {
  std::ifstream file(path);
  std::string text;
  if (!(file >> text) || text == "max") return std::nullopt;
  try {
    return std::stoull(text);
  } catch (const std::logic_error&) {
    return std::nullopt;
  }
}

std::optional<std::uint64_t> mem_available() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib) {
    std::getline(meminfo, unit);
    if (key == "MemAvailable:") return kib * 1024;
  }
  return std::nullopt;
}

// What the cgroup at `folder` (a v2 folder, or v1's memory controller) still allows, or nullopt
// when it sets no limit.
std::optional<std::uint64_t> cgroup_headroom(const std::string& folder, bool v2,
                                             std::string& files) {
  const std::string limit_file = folder + (v2 ? "/memory.max" : "/memory.limit_in_bytes");
  const std::string usage_file = folder + (v2 ? "/memory.current" : "/memory.usage_in_bytes");
  const std::optional<std::uint64_t> limit = read_number(limit_file);
  // cgroup v1 writes "no limit" as a huge number.
  if (!limit || *limit >= (std::uint64_t{1} << 60)) return std::nullopt;
  const std::uint64_t usage = read_number(usage_file).value_or(0);
  files = limit_file + " less " + usage_file.substr(usage_file.rfind('/') + 1);
  return *limit > usage ? *limit - usage : 0;
}

// The lowest headroom of the process's cgroup and those above it.
std::optional<AvailableMemory> cgroup_available() {
  std::ifstream cgroups("/proc/self/cgroup");
  std::string line;
  std::optional<AvailableMemory> lowest;
  while (std::getline(cgroups, line)) {
    // "0::/path" (v2) or "N:memory:/path" (v1).
    const auto first = line.find(':');
    const auto second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1);
    const bool v2 = line.compare(0, first, "0") == 0 && controllers.empty();
    if (!v2 && controllers.find("memory") == std::string::npos) continue;
    const std::string root = v2 ? "/sys/fs/cgroup" : "/sys/fs/cgroup/memory";
    std::string path = line.substr(second + 1);
    for (;;) {
      std::string files;
      const std::optional<std::uint64_t> headroom =
          cgroup_headroom(root + (path == "/" ? "" : path), v2, files);
      if (headroom && (!lowest || *headroom < lowest->bytes)) {
        lowest = AvailableMemory{*headroom, "the cgroup limit: " + files};
      }
      if (path.empty() || path == "/") break;
      path = path.substr(0, path.rfind('/'));
    }
  }
  return lowest;
}

}  // namespace

std::uint64_t estimate_env_bytes(const Space& unwrapped_observation_space,
                                 const Space& observation_space) {
  std::uint64_t bytes = kEnvBaseBytes;
  for (const Array& leaf : observation_space.zeros().leaves()) bytes += 2 * leaf.nbytes();
  for (const Array& leaf : unwrapped_observation_space.zeros().leaves()) {
    if (is_image(leaf)) {
      bytes += kBytesPerDrawnPixel * static_cast<std::uint64_t>(leaf.shape()[0] * leaf.shape()[1]);
    }
  }
  return bytes;
}

std::optional<AvailableMemory> available_memory() {
  std::optional<AvailableMemory> available;
  if (const std::optional<std::uint64_t> bytes = mem_available()) {
    available = AvailableMemory{*bytes, "MemAvailable in /proc/meminfo"};
  }
  const std::optional<AvailableMemory> cgroup = cgroup_available();
  if (cgroup && (!available || cgroup->bytes < available->bytes)) available = cgroup;
  return available;
}

std::string format_bytes(double bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double value = bytes;
  int unit = 0;
  while (value >= 1024.0 && unit < 6) {
    value /= 1024.0;
    ++unit;
  }
  char text[64];
  if (unit == 0) {
    std::snprintf(text, sizeof(text), "%.0f bytes", value);
  } else {
    std::snprintf(text, sizeof(text), value < 10 ? "%.1f %s" : "%.0f %s", value, units[unit]);
  }
  return text;
}

void check_memory(const std::string& who, int num_envs, std::uint64_t per_env_bytes,
                  const std::optional<AvailableMemory>& available) {
  if (!available || num_envs < 1) return;
  const std::uint64_t needed = per_env_bytes * static_cast<std::uint64_t>(num_envs);
  if (needed <= available->bytes) return;
  throw std::invalid_argument(
      who + ": num_envs = " + std::to_string(num_envs) + " envs would take about " +
      format_bytes(static_cast<double>(needed)) +
      " (an estimate: " + format_bytes(static_cast<double>(per_env_bytes)) +
      " per env), more than the " + format_bytes(static_cast<double>(available->bytes)) +
      " available (" + available->source + "); make fewer envs, or smaller observations");
}

}  // namespace pixelgym::vector
