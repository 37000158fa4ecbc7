#include "pixelgym/envs/spaces/tuple.h"

#include <stdexcept>

namespace pixelgym::spaces {

Tuple::Tuple(std::vector<SpacePtr> spaces) : spaces_(std::move(spaces)) {
  for (std::size_t i = 0; i < spaces_.size(); ++i) {
    if (spaces_[i] == nullptr) {
      throw std::invalid_argument("spaces::Tuple: subspace " + std::to_string(i) + " is null");
    }
  }
}

Value Tuple::sample(Rng& rng) const {
  std::vector<Value> items;
  items.reserve(spaces_.size());
  for (const SpacePtr& space : spaces_) items.push_back(space->sample(rng));
  return pixelgym::ValueTuple(std::move(items));
}

std::string Tuple::mismatch(const Value& value) const {
  if (!value.is_tuple()) return std::string("expected a Tuple, got a ") + value.kind();
  const pixelgym::ValueTuple& tuple = value.tuple();
  if (tuple.size() != spaces_.size()) {
    return "length " + std::to_string(tuple.size()) + ", expected " +
           std::to_string(spaces_.size());
  }
  for (std::size_t i = 0; i < spaces_.size(); ++i) {
    const std::string reason = spaces_[i]->mismatch(tuple.at(i));
    if (!reason.empty()) return "item " + std::to_string(i) + ": " + reason;
  }
  return "";
}

Value Tuple::zeros() const {
  std::vector<Value> items;
  for (const SpacePtr& space : spaces_) items.push_back(space->zeros());
  return pixelgym::ValueTuple(std::move(items));
}

std::string Tuple::layout_mismatch(const Value& value) const {
  if (!value.is_tuple()) return std::string("expected a Tuple, got a ") + value.kind();
  const pixelgym::ValueTuple& tuple = value.tuple();
  if (tuple.size() != spaces_.size()) {
    return "length " + std::to_string(tuple.size()) + ", expected " +
           std::to_string(spaces_.size());
  }
  for (std::size_t i = 0; i < spaces_.size(); ++i) {
    std::string reason = spaces_[i]->layout_mismatch(tuple.items()[i]);
    if (!reason.empty()) return "item " + std::to_string(i) + ": " + reason;
  }
  return "";
}

std::string Tuple::to_string() const {
  std::string text = "Tuple(";
  for (std::size_t i = 0; i < spaces_.size(); ++i) {
    if (i > 0) text += ", ";
    text += spaces_[i]->to_string();
  }
  return text + ")";
}

bool Tuple::equals(const Space& other) const {
  const auto* tuple = dynamic_cast<const Tuple*>(&other);
  if (tuple == nullptr || tuple->spaces_.size() != spaces_.size()) return false;
  for (std::size_t i = 0; i < spaces_.size(); ++i) {
    if (!tuple->spaces_[i]->equals(*spaces_[i])) return false;
  }
  return true;
}

}  // namespace pixelgym::spaces
