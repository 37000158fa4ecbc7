#include "pixelgym/wrappers/image_key.h"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <utility>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"

namespace pixelgym::wrappers {
namespace {

const char* kDefaultKey = "pixels";

bool is_image(const Space& space, const ImageRequirement& requirement) {
  const auto* box = dynamic_cast<const spaces::Box*>(&space);
  if (box == nullptr || box->dtype() != DType::kUInt8) return false;
  const Shape shape = box->shape().value();
  if (shape.size() != 2 && shape.size() != 3) return false;
  if (shape[0] < 1 || shape[1] < 1) return false;
  const std::int64_t channels = shape.size() == 3 ? shape[2] : 0;
  if (requirement.any_rank3 && channels != 0) return shape[2] >= 1;
  return std::find(requirement.channels.begin(), requirement.channels.end(), channels) !=
         requirement.channels.end();
}

// "uint8 (H, W, C) Box with C = 1 or 3", "uint8 (H, W) or (H, W, 3) Box", ...
std::string describe(const ImageRequirement& requirement) {
  bool two_d = false;
  std::string channels;
  for (const std::int64_t c : requirement.channels) {
    if (c == 0) {
      two_d = true;
      continue;
    }
    if (!channels.empty()) channels += " or ";
    channels += std::to_string(c);
  }
  std::string text = "a uint8 ";
  if (requirement.any_rank3)
    return text + (two_d ? "(H, W), (H, W, C) or (C, H, W) Box" : "(H, W, C) or (C, H, W) Box");
  if (two_d) text += "(H, W) or ";
  if (!channels.empty()) text += "(H, W, C) Box with C = " + channels;
  return text;
}

std::string image_keys(const spaces::Dict& dict, const ImageRequirement& requirement) {
  std::string keys;
  for (const auto& [name, subspace] : dict.entries()) {
    if (!is_image(*subspace, requirement)) continue;
    if (!keys.empty()) keys += ", ";
    keys += "\"" + name + "\"";
  }
  return keys.empty() ? "none" : keys;
}

}  // namespace

ImageKey find_image(const Space& space, const std::string& key, const std::string& wrapper,
                    const ImageRequirement& requirement) {
  ImageKey image;
  image.key = key;
  if (const auto* dict = dynamic_cast<const spaces::Dict*>(&space)) {
    const std::string keys = "; image keys: " + image_keys(*dict, requirement);
    if (!dict->has(key)) {
      throw std::invalid_argument(wrapper + ": key \"" + key +
                                  "\" is not in the observation space " + space.to_string() + keys);
    }
    const Space& entry = dict->at(key);
    if (!is_image(entry, requirement)) {
      throw std::invalid_argument(wrapper + ": key \"" + key + "\" must be " +
                                  describe(requirement) + ", got " + entry.to_string() + keys);
    }
    image.in_dict = true;
    image.index = dict->index(key);
    image.shape = *entry.shape();
    return image;
  }
  if (dynamic_cast<const spaces::Box*>(&space) == nullptr) {
    throw std::invalid_argument(wrapper + ": the observation space must be " +
                                describe(requirement) + " or a Dict holding one under key \"" +
                                key + "\", got " + space.to_string() + "; image keys: none");
  }
  if (!key.empty() && key != kDefaultKey) {
    throw std::invalid_argument(wrapper + ": key \"" + key +
                                "\" given, but the observation space is a bare Box (" +
                                space.to_string() + "), not a Dict; use key \"" + kDefaultKey +
                                "\" or \"\"; image keys: none (a bare Box has no keys)");
  }
  if (!is_image(space, requirement)) {
    throw std::invalid_argument(wrapper + ": the observation space (key \"" + key + "\") must be " +
                                describe(requirement) + ", got " + space.to_string() +
                                "; image keys: none");
  }
  image.key.clear();
  image.shape = *space.shape();
  return image;
}

SpacePtr replace_image(const Space& space, const ImageKey& image, SpacePtr image_space) {
  if (!image.in_dict) return image_space;
  return dynamic_cast<const spaces::Dict&>(space).replaced(image.key, std::move(image_space));
}

SpacePtr uint8_image_space(Shape shape) {
  return std::make_shared<spaces::Box>(0.0, 255.0, std::move(shape), DType::kUInt8);
}

const Array& image_of(const Value& observation, const ImageKey& image) {
  return image.in_dict ? observation.dict().values()[image.index].array() : observation.array();
}

Array& image_of(Value& observation, const ImageKey& image) {
  return image.in_dict ? observation.dict().values()[image.index].array() : observation.array();
}

void copy_other_entries(const Value& in, Value& out, const ImageKey& image) {
  if (!image.in_dict) return;
  const std::vector<Value>& from = in.dict().values();
  std::vector<Value>& to = out.dict().values();
  for (std::size_t i = 0; i < from.size(); ++i) {
    if (i != image.index) copy_value(from[i], to[i]);
  }
}

void copy_value(const Value& from, Value& to) {
  if (from.is_array()) {
    to.array().copy_from(from.array());
  } else if (from.is_dict()) {
    const std::vector<Value>& source = from.dict().values();
    std::vector<Value>& target = to.dict().values();
    for (std::size_t i = 0; i < source.size(); ++i) copy_value(source[i], target[i]);
  } else {
    // ValueTuple gives only const access to its items; `to` itself is not const, so its arrays
    // may be written (Array copies are shallow: this writes the caller's memory, no allocation).
    const std::vector<Value>& source = from.tuple().items();
    const std::vector<Value>& target = to.tuple().items();
    for (std::size_t i = 0; i < source.size(); ++i) {
      copy_value(source[i],
                 const_cast<Value&>(target[i]));  // NOLINT(cppcoreguidelines-pro-type-const-cast)
    }
  }
}

}  // namespace pixelgym::wrappers
