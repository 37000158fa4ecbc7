#include "examples/trainer/run/memory_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pixelgym::trainer {
namespace {

// The first number in file `path`; negative when it cannot be read or says "max".
double read_number(const std::string& path) {
  std::ifstream in(path);
  double value = -1;
  if (!(in >> value)) return -1;
  return value;
}

// MemAvailable of /proc/meminfo, in bytes; negative when absent.
double mem_available() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    double kib = 0;
    if (std::sscanf(line.c_str(), "MemAvailable: %lf kB", &kib) == 1) return kib * 1024.0;
  }
  return -1;
}

// The path of this process's cgroup (v2: the "0::" line of /proc/self/cgroup), or "".
std::string cgroup_path() {
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("0::", 0) == 0) return line.substr(3);
  }
  return "";
}

}  // namespace

double available_memory_bytes(std::string* source) {
  double available = mem_available();
  std::string from = "MemAvailable in /proc/meminfo";
  // A cgroup's limit binds before the machine's memory runs out (a container, a systemd slice).
  const std::string v2 = "/sys/fs/cgroup" + cgroup_path();
  double limit = read_number(v2 + "/memory.max");
  double used = read_number(v2 + "/memory.current");
  std::string limit_name = v2 + "/memory.max";
  if (limit < 0) {
    limit = read_number("/sys/fs/cgroup/memory/memory.limit_in_bytes");
    used = read_number("/sys/fs/cgroup/memory/memory.usage_in_bytes");
    limit_name = "/sys/fs/cgroup/memory/memory.limit_in_bytes";
  }
  // cgroup v1 reports "no limit" as a huge number (about 2^63).
  if (limit > 0 && used >= 0 && limit < 1e18 && (available < 0 || limit - used < available)) {
    available = std::max(0.0, limit - used);
    from = "the cgroup's limit, " + limit_name + ", less its use";
  }
  if (source != nullptr) *source = from;
  return available;
}

std::string format_bytes(double bytes) {
  static const char* const kUnits[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  std::size_t unit = 0;
  while (std::fabs(bytes) >= 1000.0 && unit + 1 < std::size(kUnits)) {
    bytes /= 1000.0;
    ++unit;
  }
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(unit == 0 ? 0 : 1);
  if (bytes >= 1000.0) text.setf(std::ios::scientific, std::ios::floatfield);
  text << bytes << " " << kUnits[unit];
  return text.str();
}

void require_memory(const std::string& what, const std::vector<MemoryUse>& uses, double available,
                    const std::string& source) {
  if (available < 0 || uses.empty()) return;
  double total = 0;
  for (const MemoryUse& use : uses) total += use.bytes;
  if (total <= available) return;
  const MemoryUse& most =
      *std::max_element(uses.begin(), uses.end(),
                        [](const MemoryUse& a, const MemoryUse& b) { return a.bytes < b.bytes; });
  const auto value = [](double number) {
    std::ostringstream text;
    text.precision(std::numeric_limits<double>::max_digits10);
    text << number;
    return text.str();
  };
  std::ostringstream message;
  message << what << ": these settings need about " << format_bytes(total) << " of memory, but "
          << format_bytes(available) << " is available (" << source << "); the most is "
          << most.member << " " << value(most.value) << ": about " << format_bytes(most.bytes)
          << " for " << most.what << ". Lower " << most.member << ". The estimate:";
  for (const MemoryUse& use : uses) {
    message << " " << use.member << " " << value(use.value) << ", " << format_bytes(use.bytes)
            << " (" << use.what << ");";
  }
  std::string text = message.str();
  text.back() = '.';
  throw std::invalid_argument(text);
}

void require_memory(const std::string& what, const std::vector<MemoryUse>& uses) {
  std::string source;
  const double available = available_memory_bytes(&source);
  require_memory(what, uses, available, source);
}

}  // namespace pixelgym::trainer
