// Reading an algorithm's config from JSON: members by name, with errors that name the config,
// the member and what was wrong (an unknown member lists the known ones).
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace pixelgym::trainer {

/// Reads member `name` of `json` into `field` when present (absent: `field` keeps its value).
/// Throws std::invalid_argument "{what} JSON: member \"{name}\" has the wrong type: ..." when it
/// does not convert.
template <typename T>
void read_member(const nlohmann::json& json, const char* name, T& field, const char* what) {
  const auto found = json.find(name);
  if (found == json.end()) return;
  try {
    field = found->get<T>();
  } catch (const nlohmann::json::exception& error) {
    throw std::invalid_argument(std::string(what) + " JSON: member \"" + name +
                                "\" has the wrong type: " + error.what());
  }
}

/// Throws std::invalid_argument when `json` is not an object ("{what} JSON must be an object,
/// got {type}") or has a member not in `known` ("{what} JSON: unknown member \"{key}\"; known:
/// {the known names}").
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
      std::string list;
      for (const std::string& name : known) list += (list.empty() ? "" : ", ") + name;
      throw std::invalid_argument(std::string(what) + " JSON: unknown member \"" + item.key() +
                                  "\"; known: " + list);
    }
  }
}

}  // namespace pixelgym::trainer
