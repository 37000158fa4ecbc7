#include "pixelgym/wrappers/box_key.h"

#include <stdexcept>
#include <utility>
#include <vector>

#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/wrappers/image_key.h"

namespace pixelgym::wrappers {
namespace {

std::string box_keys(const spaces::Dict& dict) {
  std::string keys;
  for (const auto& [name, subspace] : dict.entries()) {
    if (dynamic_cast<const spaces::Box*>(subspace.get()) == nullptr) continue;
    if (!keys.empty()) keys += ", ";
    keys += "\"" + name + "\"";
  }
  return keys.empty() ? "none" : keys;
}

}  // namespace

BoxKey find_box(const Space& space, const std::string& key, const std::string& wrapper) {
  BoxKey where;
  where.key = key;
  if (const auto* dict = dynamic_cast<const spaces::Dict*>(&space)) {
    const std::string keys = "; Box keys: " + box_keys(*dict);
    if (key.empty()) {
      throw std::invalid_argument(wrapper +
                                  ": the observation space is a Dict, so a key is needed (got "
                                  "none): " +
                                  space.to_string() + keys);
    }
    if (!dict->has(key)) {
      throw std::invalid_argument(wrapper + ": key \"" + key +
                                  "\" is not in the observation space " + space.to_string() + keys);
    }
    where.box = dynamic_cast<const spaces::Box*>(&dict->at(key));
    if (where.box == nullptr) {
      throw std::invalid_argument(wrapper + ": key \"" + key + "\" must be a Box, got " +
                                  dict->at(key).to_string() + keys);
    }
    where.in_dict = true;
    where.index = dict->index(key);
    return where;
  }
  where.box = dynamic_cast<const spaces::Box*>(&space);
  if (where.box == nullptr) {
    throw std::invalid_argument(wrapper +
                                ": the observation space must be a Box or a Dict holding one "
                                "under a key, got " +
                                space.to_string());
  }
  if (!key.empty()) {
    throw std::invalid_argument(wrapper + ": key \"" + key +
                                "\" given, but the observation space is a bare Box (" +
                                space.to_string() + "), not a Dict; use key \"\"");
  }
  return where;
}

SpacePtr replace_box(const Space& space, const BoxKey& where, SpacePtr box_space) {
  if (!where.in_dict) return box_space;
  return dynamic_cast<const spaces::Dict&>(space).replaced(where.key, std::move(box_space));
}

const Array& box_of(const Value& observation, const BoxKey& where) {
  return where.in_dict ? observation.dict().values()[where.index].array() : observation.array();
}

Array& box_of(Value& observation, const BoxKey& where) {
  return where.in_dict ? observation.dict().values()[where.index].array() : observation.array();
}

void copy_other_entries(const Value& in, Value& out, const BoxKey& where) {
  if (!where.in_dict) return;
  const std::vector<Value>& from = in.dict().values();
  std::vector<Value>& to = out.dict().values();
  for (std::size_t i = 0; i < from.size(); ++i) {
    if (i != where.index) copy_value(from[i], to[i]);
  }
}

}  // namespace pixelgym::wrappers
