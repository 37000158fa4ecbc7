#include "pixelgym/trainer/observation_summary.h"

#include <optional>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"

namespace pixelgym::trainer {
namespace {

bool is_image(const spaces::Box& box) {
  return *box.dtype() == DType::kUInt8 && box.shape()->size() >= 2;
}

std::string part(const std::string& name, const spaces::Box& box) {
  return name + " " + dtype_name(*box.dtype()) + " " + shape_to_string(*box.shape());
}

}  // namespace

std::string observation_summary(const Space& observation_space) {
  if (const auto* box = dynamic_cast<const spaces::Box*>(&observation_space)) {
    return part(is_image(*box) ? "image" : "state", *box);
  }
  const auto* dict = dynamic_cast<const spaces::Dict*>(&observation_space);
  if (dict == nullptr) return observation_space.to_string();
  std::string line;
  bool image = false;
  bool other = false;
  for (const auto& [key, space] : dict->entries()) {
    const auto* entry = dynamic_cast<const spaces::Box*>(space.get());
    line += (line.empty() ? "" : " + ") +
            (entry != nullptr ? part(key, *entry) : key + " " + space->to_string());
    const bool entry_image = entry != nullptr && is_image(*entry);
    image = image || entry_image;
    other = other || !entry_image;
  }
  if (image && other) {
    line +=
        " (the policy reads every part; --set obs_mode=rgb for the image alone, "
        "obs_mode=state for the state alone)";
  }
  return line;
}

}  // namespace pixelgym::trainer
