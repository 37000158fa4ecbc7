// Reading an algorithm's config from JSON: members by name, with errors that name the config,
// the member and what was wrong (an unknown member lists the known ones).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "pixelgym/envs/suggestions.h"

namespace pixelgym::trainer {

/// Reads an integer member's value: an integer, or a number with no fraction (1e6) that `T`
/// holds. Throws std::invalid_argument "{what} JSON: member \"{name}\" must be an integer from
/// {lowest} to {highest}, got {value}" otherwise: JSON's conversions truncate 2.9 to 2, wrap -1
/// to 2^64 - 1 and leave 1e30 undefined.
template <typename T>
T integer_member(const nlohmann::json& value, const char* name, const char* what) {
  static_assert(std::is_integral_v<T> && !std::is_same_v<T, bool>);
  using Limits = std::numeric_limits<T>;
  const auto refuse = [&] {
    throw std::invalid_argument(std::string(what) + " JSON: member \"" + name +
                                "\" must be an integer from " + std::to_string(Limits::min()) +
                                " to " + std::to_string(Limits::max()) + ", got " + value.dump());
  };
  if (value.is_number_unsigned()) {
    const auto number = value.get<std::uint64_t>();
    if (number > static_cast<std::uint64_t>(Limits::max())) refuse();
    return static_cast<T>(number);
  }
  if (value.is_number_integer()) {
    const auto number = value.get<std::int64_t>();
    if (number < 0 && !Limits::is_signed) refuse();
    if (Limits::is_signed && (number < static_cast<std::int64_t>(Limits::min()) ||
                              number > static_cast<std::int64_t>(Limits::max()))) {
      refuse();
    }
    return static_cast<T>(number);
  }
  if (value.is_number_float()) {
    // Exactly representable bounds: min() is -2^k or 0, and max() + 1 is 2^k.
    const double number = value.get<double>();
    const double below = static_cast<double>(Limits::min());
    const double past = static_cast<double>(Limits::max() / 2 + 1) * 2.0;
    if (!(number >= below && number < past) || std::trunc(number) != number) refuse();
    return static_cast<T>(number);
  }
  throw std::invalid_argument(std::string(what) + " JSON: member \"" + name +
                              "\" has the wrong type: expected an integer, got " +
                              value.type_name() + " " + value.dump());
}

/// Reads member `name` of `json` into `field` when present (absent: `field` keeps its value).
/// Throws std::invalid_argument "{what} JSON: member \"{name}\" has the wrong type: expected
/// {the field's JSON type}, got {the value's type} {the value}" when it does not convert (a number
/// for a bool, "0.9" for a number); integers as integer_member reads them.
template <typename T>
void read_member(const nlohmann::json& json, const char* name, T& field, const char* what) {
  const auto found = json.find(name);
  if (found == json.end()) return;
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    field = integer_member<T>(*found, name, what);
  } else {
    try {
      field = found->get<T>();
    } catch (const nlohmann::json::exception&) {
      const std::string wanted = nlohmann::json(field).type_name();
      const bool vowel = wanted.find_first_of("aeiou") == 0;
      throw std::invalid_argument(std::string(what) + " JSON: member \"" + name +
                                  "\" has the wrong type: expected " + (vowel ? "an " : "a ") +
                                  wanted + ", got " + found->type_name() + " " + found->dump());
    }
  }
}

/// Throws std::invalid_argument when `json` is not an object ("{what} JSON must be an object,
/// got {type}") or has a member not in `known` ("{what} JSON: unknown member \"{key}\"; did you
/// mean {the closest}? known: {the known names}", "did you mean" only when one is close).
inline void require_known_members(const nlohmann::json& json, const std::vector<std::string>& known,
                                  const char* what) {
  if (!json.is_object()) {
    throw std::invalid_argument(std::string(what) + " JSON must be an object, got " +
                                json.type_name());
  }
  for (const auto& item : json.items()) {
    bool ok = false;
    for (const std::string& name : known) ok = ok || item.key() == name;
    if (!ok) {
      const std::string suggestion = did_you_mean(item.key(), known);
      throw std::invalid_argument(std::string(what) + " JSON: unknown member \"" + item.key() +
                                  "\"; " + (suggestion.empty() ? "" : suggestion + " ") +
                                  "known: " + join_names(known));
    }
  }
}

/// The range checks of a config's validate(), each error "{config_name}: {member} must be ...,
/// got {value}" (std::invalid_argument).
class ConfigChecks {
 public:
  /// Counts are at most 2^40 (about 1.1e12): far past any run, and far from overflowing the
  /// products of counts that sizes are made of.
  static constexpr std::int64_t kMostCount = std::int64_t{1} << 40;

  explicit ConfigChecks(const char* config_name) : config_name_(config_name) {}

  /// Throws "{config_name}: {what}".
  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument(std::string(config_name_) + ": " + what);
  }
  /// A count from `minimum` to kMostCount.
  void at_least(const char* name, std::int64_t value, std::int64_t minimum) const {
    if (value < minimum || value > kMostCount) {
      fail(std::string(name) + " must be from " + std::to_string(minimum) + " to " +
           std::to_string(kMostCount) + ", got " + std::to_string(value));
    }
  }
  /// A number in [low, high] (NaN is not).
  void in_range(const char* name, double value, double low, double high) const {
    if (!(value >= low && value <= high)) {
      std::ostringstream message;
      message << name << " must be in [" << low << ", " << high << "], got " << value;
      fail(message.str());
    }
  }

 private:
  const char* config_name_;
};

}  // namespace pixelgym::trainer
