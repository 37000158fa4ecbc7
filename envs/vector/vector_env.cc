#include "pixelgym/envs/vector/vector_env.h"

#include <cctype>
#include <stdexcept>
#include <string>

namespace pixelgym::vector {

const char* autoreset_mode_name(AutoresetMode mode) {
  switch (mode) {
    case AutoresetMode::kNextStep:
      return "NextStep";
    case AutoresetMode::kSameStep:
      return "SameStep";
    case AutoresetMode::kDisabled:
      return "Disabled";
  }
  return "?";
}

AutoresetMode parse_autoreset_mode(const std::string& name) {
  std::string key;
  for (const char c : name) {
    if (c != '_') key += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (key == "nextstep") return AutoresetMode::kNextStep;
  if (key == "samestep") return AutoresetMode::kSameStep;
  if (key == "disabled") return AutoresetMode::kDisabled;
  throw std::invalid_argument("autoreset mode: expected NextStep, SameStep or Disabled, got \"" +
                              name + "\"");
}

VectorEnv::~VectorEnv() = default;

}  // namespace pixelgym::vector
