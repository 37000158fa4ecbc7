#include "pixelgym/wrappers/filter_observation.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/wrappers/image_key.h"

namespace pixelgym::wrappers {
namespace {

std::string quoted(const std::vector<std::string>& keys) {
  std::string text;
  for (const std::string& key : keys) text += (text.empty() ? "\"" : ", \"") + key + "\"";
  return "[" + text + "]";
}

}  // namespace

FilterObservation::FilterObservation(std::unique_ptr<Env> env, std::vector<std::string> keys)
    : ObservationWrapper(std::move(env)), keys_(std::move(keys)) {
  const Space& inner = env_->observation_space();
  const auto* dict = dynamic_cast<const spaces::Dict*>(&inner);
  if (dict == nullptr) {
    throw std::invalid_argument("FilterObservation: the observation space must be a Dict, got " +
                                inner.to_string());
  }
  std::vector<std::string> present;
  for (const auto& entry : dict->entries()) present.push_back(entry.first);
  if (keys_.empty()) {
    throw std::invalid_argument(
        "FilterObservation: keys must name at least one key, got none; "
        "keys present: " +
        quoted(present));
  }
  std::vector<std::string> missing;
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    if (std::find(keys_.begin(), keys_.begin() + static_cast<std::ptrdiff_t>(i), keys_[i]) !=
        keys_.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw std::invalid_argument("FilterObservation: key \"" + keys_[i] + "\" is given twice in " +
                                  quoted(keys_));
    }
    if (!dict->has(keys_[i])) missing.push_back(keys_[i]);
  }
  if (!missing.empty()) {
    throw std::invalid_argument(
        "FilterObservation: keys " + quoted(missing) +
        " are not in the observation space; keys present: " + quoted(present));
  }
  spaces::Dict::Entries entries;
  for (const std::string& key : keys_) {
    source_.push_back(dict->index(key));
    entries.emplace_back(key, dict->entries()[source_.back()].second);
  }
  set_observation_space(std::make_shared<spaces::Dict>(std::move(entries)));
}

void FilterObservation::observation(const Value& in, Value& out) {
  const std::vector<Value>& from = in.dict().values();
  std::vector<Value>& to = out.dict().values();
  for (std::size_t i = 0; i < source_.size(); ++i) copy_value(from[source_[i]], to[i]);
}

}  // namespace pixelgym::wrappers
