// Fuzz target: action and observation checking, Space::contains / mismatch / layout_mismatch on
// arbitrary values (any structure, dtype, shape and bytes, NaN and infinities included) against
// spaces of every kind, and the space constructors on arbitrary parameters. A space either
// contains a value or says why not; a constructor either builds or throws std::invalid_argument
// with a message.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fuzz/fuzz_input.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/spaces/multi_binary.h"
#include "pixelgym/envs/spaces/multi_discrete.h"
#include "pixelgym/envs/spaces/tuple.h"
#include "pixelgym/envs/value.h"

namespace {

using pixelgym::fuzz::FuzzInput;
namespace pg = pixelgym;
namespace sp = pixelgym::spaces;

// A value of any structure (arrays up to 3 levels inside dicts and tuples), dtype and shape; its
// bytes come from the input, zero-filled when the input runs out.
pg::Value make_value(FuzzInput& input, int depth) {
  const std::size_t kind = depth < 3 ? input.pick(4) : 0;
  if (kind == 1) {  // Dict
    pg::ValueDict dict;
    const std::size_t n = input.pick(4);
    static const char* const kKeys[] = {"pixels", "state", "a", "b", ""};
    for (std::size_t i = 0; i < n; ++i) {
      const std::string key = kKeys[input.pick(5)];
      if (!dict.contains(key)) dict.insert(key, make_value(input, depth + 1));
    }
    return dict;
  }
  if (kind == 2) {  // Tuple
    std::vector<pg::Value> items;
    const std::size_t n = input.pick(4);
    for (std::size_t i = 0; i < n; ++i) items.push_back(make_value(input, depth + 1));
    return pg::ValueTuple(std::move(items));
  }
  const auto dtype = static_cast<pg::DType>(input.pick(6));
  pg::Shape shape;
  const std::size_t ndim = input.pick(4);
  for (std::size_t d = 0; d < ndim; ++d) shape.push_back(static_cast<std::int64_t>(input.pick(6)));
  pg::Array array(dtype, shape);
  const std::string raw = input.bytes(array.nbytes());
  std::memcpy(array.raw_data(), raw.data(), raw.size());
  if (dtype == pg::DType::kBool) {  // a bool is 0 or 1 in memory, as numpy keeps them
    for (std::int64_t i = 0; i < array.size(); ++i)
      array.data<bool>()[i] =
          (raw.size() > static_cast<std::size_t>(i) && (raw[static_cast<std::size_t>(i)] & 1) != 0);
  }
  return array;
}

// Spaces of every kind, as the registered envs use them and at their edges.
std::vector<pg::SpacePtr> make_spaces() {
  std::vector<pg::SpacePtr> spaces;
  spaces.push_back(std::make_shared<sp::Box>(-1.0, 1.0, pg::Shape{1}));
  spaces.push_back(std::make_shared<sp::Box>(-1.0, 1.0, pg::Shape{2}, pg::DType::kFloat64));
  spaces.push_back(std::make_shared<sp::Box>(std::vector<double>{-1.0, 0.0, -3.0},
                                             std::vector<double>{1.0, 0.0, 3.0}, pg::Shape{3}));
  spaces.push_back(std::make_shared<sp::Box>(0.0, 255.0, pg::Shape{4, 4, 3}, pg::DType::kUInt8));
  spaces.push_back(std::make_shared<sp::Box>(-1e300, 1e300, pg::Shape{2, 2}, pg::DType::kFloat32));
  spaces.push_back(std::make_shared<sp::Box>(-5.0, 5.0, pg::Shape{}, pg::DType::kInt64));
  spaces.push_back(std::make_shared<sp::Discrete>(4));
  spaces.push_back(std::make_shared<sp::Discrete>(3, -1));
  spaces.push_back(std::make_shared<sp::MultiDiscrete>(std::vector<std::int64_t>{3, 4}));
  spaces.push_back(std::make_shared<sp::MultiBinary>(pg::Shape{2, 3}));
  spaces.push_back(
      std::make_shared<sp::Dict>(sp::Dict::Entries{{"pixels", spaces[3]}, {"state", spaces[1]}}));
  spaces.push_back(std::make_shared<sp::Tuple>(std::vector<pg::SpacePtr>{spaces[6], spaces[0]}));
  return spaces;
}

// A space built from arbitrary parameters, or null when its constructor refused them.
pg::SpacePtr make_space(FuzzInput& input) {
  try {
    switch (input.pick(4)) {
      case 0: {
        pg::Shape shape;
        const std::size_t ndim = input.pick(3);
        for (std::size_t d = 0; d < ndim; ++d)
          shape.push_back(static_cast<std::int8_t>(input.byte()));
        const double low = input.any_double();
        const double high = input.any_double();
        return std::make_shared<sp::Box>(low, high, shape, static_cast<pg::DType>(input.pick(6)));
      }
      case 1: {
        std::int64_t n = 0;
        std::int64_t start = 0;
        const std::string raw = input.bytes(16);
        std::memcpy(&n, raw.data(), std::min<std::size_t>(raw.size(), 8));
        if (raw.size() > 8) std::memcpy(&start, raw.data() + 8, raw.size() - 8);
        return std::make_shared<sp::Discrete>(n, start);
      }
      case 2: {
        std::vector<std::int64_t> nvec;
        const std::size_t n = input.pick(4);
        for (std::size_t i = 0; i < n; ++i) nvec.push_back(static_cast<std::int8_t>(input.byte()));
        return std::make_shared<sp::MultiDiscrete>(nvec);
      }
      default: {
        pg::Shape shape;
        const std::size_t ndim = input.pick(3);
        for (std::size_t d = 0; d < ndim; ++d)
          shape.push_back(static_cast<std::int8_t>(input.byte()));
        return std::make_shared<sp::MultiBinary>(shape);
      }
    }
  } catch (const std::invalid_argument& error) {
    if (std::string(error.what()).empty()) std::abort();
    return nullptr;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::vector<pg::SpacePtr> spaces = make_spaces();
  FuzzInput input(data, size);
  pg::SpacePtr space = input.pick(2) == 0 ? spaces[input.pick(spaces.size())] : make_space(input);
  if (space == nullptr) return 0;
  const pg::Value value = make_value(input, 0);
  const std::string why = space->mismatch(value);
  const std::string layout = space->layout_mismatch(value);
  // A space's zeros() is laid out as the space. (An element need not be: contains() takes any
  // integer dtype for a Discrete and bool for a MultiBinary, the layout only the space's own. The
  // first run's only finding was this check made the other way round, on a bool scalar.)
  if (!space->layout_mismatch(space->zeros()).empty()) std::abort();
  if (!layout.empty() && why.empty() && value.is_array() && space->dtype() &&
      value.array().dtype() == *space->dtype()) {
    std::abort();  // of the space's own dtype, an element is laid out as one
  }
  try {
    pg::require_contains(*space, value, "fuzz");
    if (!why.empty()) std::abort();
  } catch (const std::invalid_argument& error) {
    if (why.empty() || std::string(error.what()).find(why) == std::string::npos) std::abort();
  }
  // What a space draws is in it.
  if (!space->contains(space->sample())) std::abort();
  space->to_string();
  return 0;
}
