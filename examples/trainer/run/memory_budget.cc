#include "pixelgym/trainer/memory_budget.h"

#include <algorithm>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "pixelgym/envs/vector/memory_check.h"

namespace pixelgym::trainer {

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
  message << what << ": these settings need about " << vector::format_bytes(total)
          << " of memory, but " << vector::format_bytes(available) << " is available (" << source
          << "); the most is " << most.member << " " << value(most.value) << ": about "
          << vector::format_bytes(most.bytes) << " for " << most.what << ". Lower " << most.member
          << ". The estimate:";
  for (const MemoryUse& use : uses) {
    message << " " << use.member << " " << value(use.value) << ", "
            << vector::format_bytes(use.bytes) << " (" << use.what << ");";
  }
  std::string text = message.str();
  text.back() = '.';
  throw std::invalid_argument(text);
}

void require_memory(const std::string& what, const std::vector<MemoryUse>& uses) {
  const std::optional<vector::AvailableMemory> available = vector::available_memory();
  if (!available) return;
  require_memory(what, uses, static_cast<double>(available->bytes), available->source);
}

}  // namespace pixelgym::trainer
