// Fuzz target: the parsers of what users type to configure an env: `--set key=value` (parse_sets,
// then the env's own kwargs check, resolve_params), and `--wrap NAME[=ARGS]`
// (parse_wrapper_spec, then apply_wrapper on GridWorld-v0's pixels, which checks the values).
// The first byte picks the env id; each following line is a --set entry until an empty line, and
// each line after it a --wrap spec. Refusals are UsageError / std::invalid_argument with a
// message; anything else is a finding. A wrapper with a number past 256 is parsed, not applied.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "examples/pixelgym/cli.h"
#include "fuzz/fuzz_input.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/wrappers/wrapper_spec.h"

namespace {

void require_message(const std::exception& error) {
  if (std::string(error.what()).empty()) std::abort();
}

// Whether an argument holds a run of digits past 256 (a size, a stack depth): such a wrapper is
// only slower to apply, not another path through the code (resize=2222 took 12 s under ASan and
// stopped a run as a slow unit), so it is parsed but not applied.
bool has_large_number(const pixelgym::wrappers::WrapperSpec& spec) {
  for (const auto& argument : spec.arguments) {
    long long number = 0;
    for (const char c : argument.second) {
      number = (c >= '0' && c <= '9') ? std::min(number * 10 + (c - '0'), 1000000LL) : 0;
      if (number > 256) return true;
    }
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pixelgym;  // NOLINT(google-build-using-namespace): a fuzz target's body
  fuzz::FuzzInput input(data, size);
  static const std::vector<std::string> ids = registered_ids();
  const std::string& id = ids[input.pick(ids.size())];
  std::vector<std::string> sets;
  std::vector<std::string> wraps;
  for (std::string line = input.line(); !line.empty() && sets.size() < 8; line = input.line()) {
    sets.push_back(line);
  }
  while (!input.empty() && wraps.size() < 4) wraps.push_back(input.line());

  try {
    const Params given = cli::parse_sets(id, sets);
    resolve_params(default_registry().spec(id)->params, given, id);
  } catch (const cli::UsageError& error) {
    require_message(error);
  } catch (const std::invalid_argument& error) {
    require_message(error);
  }
  for (const std::string& text : wraps) {
    try {
      const wrappers::WrapperSpec spec = wrappers::parse_wrapper_spec(text);
      if (has_large_number(spec)) continue;
      const Params small{{"obs_mode", "pixels"}, {"width", 16}, {"height", 16}};
      wrappers::apply_wrapper(make("GridWorld-v0", small), spec);
    } catch (const std::invalid_argument& error) {
      require_message(error);
    }
  }
  return 0;
}
