#include "pixelgym/envs/spaces/dict.h"

#include <stdexcept>

namespace pixelgym::spaces {
namespace {

std::string key_list(const Dict::Entries& entries) {
  std::string text;
  for (const auto& entry : entries) text += (text.empty() ? "\"" : ", \"") + entry.first + "\"";
  return text.empty() ? "none" : text;
}

std::string key_list(const std::vector<std::string>& keys) {
  std::string text;
  for (const auto& key : keys) text += (text.empty() ? "\"" : ", \"") + key + "\"";
  return text.empty() ? "none" : text;
}

}  // namespace

Dict::Dict(Entries entries) : entries_(std::move(entries)) {
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    const std::string& key = entries_[i].first;
    if (key.empty()) throw std::invalid_argument("spaces::Dict: empty key");
    if (entries_[i].second == nullptr) {
      throw std::invalid_argument("spaces::Dict: subspace \"" + key + "\" is null");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (entries_[j].first == key) {
        throw std::invalid_argument("spaces::Dict: duplicate key \"" + key + "\"");
      }
    }
  }
}

Value Dict::sample(Rng& rng) const {
  pixelgym::ValueDict value;
  for (const auto& [key, space] : entries_) value.insert(key, space->sample(rng));
  return value;
}

std::string Dict::mismatch(const Value& value) const {
  if (!value.is_dict()) return std::string("expected a Dict, got a ") + value.kind();
  const pixelgym::ValueDict& dict = value.dict();
  for (const auto& [key, space] : entries_) {
    if (!dict.contains(key)) return "missing key \"" + key + "\"";
    const std::string reason = space->mismatch(dict.at(key));
    if (!reason.empty()) return "key \"" + key + "\": " + reason;
  }
  for (const std::string& key : dict.keys()) {
    if (!has(key)) return "unexpected key \"" + key + "\" (expected " + key_list(entries_) + ")";
  }
  return "";
}

Value Dict::zeros() const {
  pixelgym::ValueDict value;
  for (const auto& [key, space] : entries_) value.insert(key, space->zeros());
  return value;
}

std::string Dict::layout_mismatch(const Value& value) const {
  if (!value.is_dict()) return std::string("expected a Dict, got a ") + value.kind();
  const pixelgym::ValueDict& dict = value.dict();
  if (dict.size() != entries_.size()) {
    return "keys " + key_list(dict.keys()) + ", expected " + key_list(entries_);
  }
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (dict.keys()[i] != entries_[i].first) {
      return "keys " + key_list(dict.keys()) + ", expected " + key_list(entries_);
    }
    std::string reason = entries_[i].second->layout_mismatch(dict.values()[i]);
    if (!reason.empty()) return "key \"" + entries_[i].first + "\": " + reason;
  }
  return "";
}

std::string Dict::to_string() const {
  std::string text = "Dict(";
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (i > 0) text += ", ";
    text += "'" + entries_[i].first + "': " + entries_[i].second->to_string();
  }
  return text + ")";
}

bool Dict::equals(const Space& other) const {
  const auto* dict = dynamic_cast<const Dict*>(&other);
  if (dict == nullptr || dict->entries_.size() != entries_.size()) return false;
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (dict->entries_[i].first != entries_[i].first ||
        !dict->entries_[i].second->equals(*entries_[i].second)) {
      return false;
    }
  }
  return true;
}

bool Dict::has(const std::string& key) const {
  for (const auto& entry : entries_) {
    if (entry.first == key) return true;
  }
  return false;
}

const Space& Dict::at(const std::string& key) const { return *entries_[index(key)].second; }

std::size_t Dict::index(const std::string& key) const {
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (entries_[i].first == key) return i;
  }
  throw std::out_of_range("spaces::Dict: no key \"" + key + "\" (keys: " + key_list(entries_) +
                          ")");
}

std::shared_ptr<const Dict> Dict::replaced(const std::string& key, SpacePtr space) const {
  Entries entries = entries_;
  entries[index(key)].second = std::move(space);
  return std::make_shared<const Dict>(std::move(entries));
}

std::shared_ptr<const Dict> Dict::inserted(const std::string& key, SpacePtr space,
                                           std::optional<std::size_t> position) const {
  if (has(key)) {
    throw std::invalid_argument("spaces::Dict: cannot insert \"" + key +
                                "\": the key is present (keys: " + key_list(entries_) + ")");
  }
  const std::size_t at = position.value_or(entries_.size());
  if (at > entries_.size()) {
    throw std::out_of_range("spaces::Dict: cannot insert \"" + key + "\" at position " +
                            std::to_string(at) + " of " + std::to_string(entries_.size()) +
                            " entries");
  }
  Entries entries = entries_;
  entries.insert(entries.begin() + static_cast<std::ptrdiff_t>(at), {key, std::move(space)});
  return std::make_shared<const Dict>(std::move(entries));
}

std::shared_ptr<const Dict> Dict::removed(const std::string& key) const {
  Entries entries = entries_;
  entries.erase(entries.begin() + static_cast<std::ptrdiff_t>(index(key)));
  return std::make_shared<const Dict>(std::move(entries));
}

}  // namespace pixelgym::spaces
