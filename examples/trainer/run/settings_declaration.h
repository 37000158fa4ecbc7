// An algorithm's settings declared once: each config type lists its members with their range and
// what they do, and its JSON form, its range checks and `train --list-settings` all come from
// that list. Torch-free, so that an algorithm outside the tree declares its config the same way.
//
// A config type declares its settings with a function found by argument-dependent lookup,
//
//   template <typename Config, typename Visit>  // Config: the type, or the type const
//   void declare_settings(Config& config, Visit& visit);
//
// which calls, for each member in the order its JSON lists them, one of
//
//   visit.count(name, field, minimum, help)      an integer from minimum to
//   ConfigChecks::kMostCount visit.integer(name, field, low, high, help)  an integer in [low, high]
//   visit.number(name, field, low, high, help)   a number in [low, high]
//   visit.positive(name, field, help)            a number > 0, finite
//   visit.non_negative(name, field, help)        a number >= 0, finite
//   visit.optional_number(name, field, low, high, help)   a number in [low, high], or null (NaN)
//   visit.flag(name, field, help)                true or false
//   visit.choice(name, field, names, help)       an enum by name: names lists {name, value}
//   visit.counts(name, field, minimum, help)     a list of integers, each >= minimum
//   visit.object(name, field, config_name, help) a config of its own declaration (a JSON object)
//
// and nothing else; checks between members stay in the config's validate().
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "pixelgym/trainer/config_members.h"

namespace pixelgym::trainer {

/// One setting as `train --list-settings` shows it.
struct SettingDescription {
  /// As JSON names it; "policy.cnn" for member cnn of object member policy.
  std::string name;
  /// Its value in the config described (the defaults, for --list-settings).
  nlohmann::json value;
  /// What it may be: "an integer from 1", "a number in [0, 1]", "one of mrq, fine, drqv2", ...
  std::string range;
  std::string help;
};

/// An enum's names, for visit.choice.
template <typename Enum>
using ChoiceNames = std::vector<std::pair<const char*, Enum>>;

namespace settings_detail {

inline std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

template <typename Enum>
const char* choice_name(Enum value, const ChoiceNames<Enum>& names) {
  for (const auto& [name, choice] : names) {
    if (choice == value) return name;
  }
  return "?";
}

template <typename Enum>
std::string choice_list(const ChoiceNames<Enum>& names) {
  std::string list;
  for (const auto& [name, choice] : names) list += (list.empty() ? "" : ", ") + std::string(name);
  return list;
}

// Writes every member into a JSON object.
struct Writer {
  nlohmann::json& out;

  template <typename T>
  void count(const char* name, const T& field, std::int64_t, const char*) {
    out[name] = field;
  }
  template <typename T, typename L>
  void integer(const char* name, const T& field, L, L, const char*) {
    out[name] = field;
  }
  void number(const char* name, double field, double, double, const char*) { out[name] = field; }
  void positive(const char* name, double field, const char*) { out[name] = field; }
  void non_negative(const char* name, double field, const char*) { out[name] = field; }
  void optional_number(const char* name, double field, double, double, const char*) {
    out[name] = std::isnan(field) ? nlohmann::json(nullptr) : nlohmann::json(field);
  }
  void flag(const char* name, bool field, const char*) { out[name] = field; }
  template <typename Enum>
  void choice(const char* name, Enum field, const ChoiceNames<Enum>& names, const char*) {
    out[name] = choice_name(field, names);
  }
  void counts(const char* name, const std::vector<std::int64_t>& field, std::int64_t, const char*) {
    out[name] = field;
  }
  template <typename Config>
  void object(const char* name, const Config& field, const char*, const char*) {
    nlohmann::json inner = nlohmann::json::object();
    Writer writer{inner};
    declare_settings(field, writer);
    out[name] = std::move(inner);
  }
};

// The members' names (for the unknown-member check), from the JSON form.
template <typename Config>
std::vector<std::string> member_names(const Config& config) {
  nlohmann::json json = nlohmann::json::object();
  Writer writer{json};
  declare_settings(config, writer);
  std::vector<std::string> names;
  for (const auto& item : json.items()) names.push_back(item.key());
  return names;
}

// Reads the members present in a JSON object (refusing unknown ones and wrong types).
struct Reader {
  const nlohmann::json& in;
  const char* what;

  template <typename T>
  void count(const char* name, T& field, std::int64_t, const char*) {
    read_member(in, name, field, what);
  }
  template <typename T, typename L>
  void integer(const char* name, T& field, L, L, const char*) {
    read_member(in, name, field, what);
  }
  void number(const char* name, double& field, double, double, const char*) {
    read_member(in, name, field, what);
  }
  void positive(const char* name, double& field, const char*) {
    read_member(in, name, field, what);
  }
  void non_negative(const char* name, double& field, const char*) {
    read_member(in, name, field, what);
  }
  void optional_number(const char* name, double& field, double, double, const char*) {
    if (in.contains(name) && in.at(name).is_null()) {
      field = std::numeric_limits<double>::quiet_NaN();
    } else {
      read_member(in, name, field, what);
    }
  }
  void flag(const char* name, bool& field, const char*) { read_member(in, name, field, what); }
  template <typename Enum>
  void choice(const char* name, Enum& field, const ChoiceNames<Enum>& names, const char*) {
    std::string given = choice_name(field, names);
    read_member(in, name, given, what);
    for (const auto& [known, value] : names) {
      if (given == known) {
        field = value;
        return;
      }
    }
    throw std::invalid_argument(std::string(what) + ": member \"" + name + "\": unknown " + name +
                                " \"" + given + "\"; known: " + choice_list(names));
  }
  void counts(const char* name, std::vector<std::int64_t>& field, std::int64_t, const char*) {
    read_member(in, name, field, what);
  }
  template <typename Config>
  void object(const char* name, Config& field, const char* config_name, const char*) {
    const auto found = in.find(name);
    if (found == in.end()) return;
    require_known_members(*found, member_names(field), config_name);
    Reader reader{*found, config_name};
    declare_settings(field, reader);
  }
};

// Checks each member's range.
struct Checker {
  ConfigChecks checks;

  template <typename T>
  void count(const char* name, const T& field, std::int64_t minimum, const char*) {
    checks.at_least(name, static_cast<std::int64_t>(field), minimum);
  }
  template <typename T, typename L>
  void integer(const char* name, const T& field, L low, L high, const char*) {
    if (field < static_cast<T>(low) || field > static_cast<T>(high)) {
      checks.fail(std::string(name) + " must be from " + std::to_string(low) + " to " +
                  std::to_string(high) + ", got " + std::to_string(field));
    }
  }
  void number(const char* name, double field, double low, double high, const char*) {
    checks.in_range(name, field, low, high);
  }
  void positive(const char* name, double field, const char*) {
    if (!(field > 0.0) || !std::isfinite(field)) {
      checks.fail(std::string(name) + " must be > 0 and finite, got " + number_text(field));
    }
  }
  void non_negative(const char* name, double field, const char*) {
    if (!(field >= 0.0) || !std::isfinite(field)) {
      checks.fail(std::string(name) + " must be >= 0 and finite, got " + number_text(field));
    }
  }
  void optional_number(const char* name, double field, double low, double high, const char*) {
    if (!std::isnan(field)) checks.in_range(name, field, low, high);
  }
  void flag(const char*, bool, const char*) {}
  template <typename Enum>
  void choice(const char*, Enum, const ChoiceNames<Enum>&, const char*) {}
  void counts(const char* name, const std::vector<std::int64_t>& field, std::int64_t minimum,
              const char*) {
    for (const std::int64_t value : field) {
      if (value < minimum) {
        checks.fail(std::string(name) + " must each be >= " + std::to_string(minimum) + ", got " +
                    std::to_string(value));
      }
    }
  }
  template <typename Config>
  void object(const char*, const Config& field, const char* config_name, const char*) {
    Checker inner{ConfigChecks(config_name)};
    declare_settings(field, inner);
  }
};

// Describes each member for --list-settings.
struct Describer {
  std::vector<SettingDescription>& out;
  std::string prefix;

  void add(const char* name, nlohmann::json value, std::string range, const char* help) {
    out.push_back({prefix + name, std::move(value), std::move(range), help});
  }
  template <typename T>
  void count(const char* name, const T& field, std::int64_t minimum, const char* help) {
    add(name, field, "an integer from " + std::to_string(minimum), help);
  }
  template <typename T, typename L>
  void integer(const char* name, const T& field, L low, L high, const char* help) {
    add(name, field, "an integer from " + std::to_string(low) + " to " + std::to_string(high),
        help);
  }
  void number(const char* name, double field, double low, double high, const char* help) {
    add(name, field, "a number in [" + number_text(low) + ", " + number_text(high) + "]", help);
  }
  void positive(const char* name, double field, const char* help) {
    add(name, field, "a number > 0", help);
  }
  void non_negative(const char* name, double field, const char* help) {
    add(name, field, "a number >= 0", help);
  }
  void optional_number(const char* name, double field, double low, double high, const char* help) {
    add(name, std::isnan(field) ? nlohmann::json(nullptr) : nlohmann::json(field),
        "null or a number in [" + number_text(low) + ", " + number_text(high) + "]", help);
  }
  void flag(const char* name, bool field, const char* help) {
    add(name, field, "true or false", help);
  }
  template <typename Enum>
  void choice(const char* name, Enum field, const ChoiceNames<Enum>& names, const char* help) {
    add(name, choice_name(field, names), "one of " + choice_list(names), help);
  }
  void counts(const char* name, const std::vector<std::int64_t>& field, std::int64_t minimum,
              const char* help) {
    add(name, field, "a list of integers, each from " + std::to_string(minimum), help);
  }
  template <typename Config>
  void object(const char* name, const Config& field, const char*, const char*) {
    Describer inner{out, prefix + name + "."};
    declare_settings(field, inner);
  }
};

}  // namespace settings_detail

/// `config` as a JSON object: one member per setting (an enum by its name, NaN of an optional
/// number as null, an object member as an object).
template <typename Config>
void write_settings(nlohmann::json& json, const Config& config) {
  json = nlohmann::json::object();
  settings_detail::Writer writer{json};
  declare_settings(config, writer);
}

/// Reads the settings `json` has into `config` (the others keep their values). Throws
/// std::invalid_argument, each error naming `config_name`, for JSON that is not an object, an
/// unknown member (listing the known ones), a value of the wrong type or an unknown name of a
/// choice. Does not check ranges: check_settings (or the config's validate()) does.
template <typename Config>
void read_settings(const nlohmann::json& json, Config& config, const char* config_name) {
  require_known_members(json, settings_detail::member_names(config), config_name);
  settings_detail::Reader reader{json, config_name};
  declare_settings(config, reader);
}

/// Throws std::invalid_argument "{config_name}: {member} must be ..., got {value}" for the
/// first setting out of its declared range.
template <typename Config>
void check_settings(const Config& config, const char* config_name) {
  settings_detail::Checker checker{ConfigChecks(config_name)};
  declare_settings(config, checker);
}

/// Every setting of `config` with its value, range and help, in declaration order.
template <typename Config>
std::vector<SettingDescription> describe_settings(const Config& config) {
  std::vector<SettingDescription> described;
  settings_detail::Describer describer{described, ""};
  declare_settings(config, describer);
  return described;
}

}  // namespace pixelgym::trainer
