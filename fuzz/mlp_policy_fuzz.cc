// Fuzz target: the policy-file reader (testing::MlpPolicy::parse, what MlpPolicy::load reads) on
// arbitrary text. A refusal is std::runtime_error with a message; a policy it accepts acts on an
// observation of zeros with an action of its size, finite and within its bounds.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/testing/mlp_policy.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const pixelgym::testing::MlpPolicy policy =
        pixelgym::testing::MlpPolicy::parse(text, "fuzz.policy.json");
    pixelgym::ValueDict observation;
    for (const auto& [key, length] : policy.inputs()) {
      observation.insert(key, pixelgym::Value(pixelgym::Array::from_vector<float>(
                                  {length}, std::vector<float>(static_cast<std::size_t>(length)))));
    }
    const pixelgym::Array action = policy.act(pixelgym::Value(std::move(observation)));
    if (action.size() != policy.action_size()) std::abort();
    for (std::int64_t i = 0; i < action.size(); ++i) {
      const float value = action.data<float>()[i];
      if (!std::isfinite(value)) std::abort();
    }
  } catch (const std::runtime_error& error) {
    if (std::string(error.what()).empty()) std::abort();
  }
  return 0;
}
