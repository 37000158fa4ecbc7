#include "pixelgym/wrappers/add_render_observation.h"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/spaces/multi_binary.h"
#include "pixelgym/envs/spaces/multi_discrete.h"
#include "pixelgym/envs/spaces/tuple.h"
#include "pixelgym/wrappers/image_key.h"

namespace pixelgym::wrappers {
namespace {

std::string keys_of(const spaces::Dict& dict) {
  std::string keys;
  for (const auto& entry : dict.entries()) {
    if (!keys.empty()) keys += ", ";
    keys += "\"" + entry.first + "\"";
  }
  return keys;
}

// A copy of `space` that the wrapper's Dict space can own (Env hands out spaces by reference).
template <typename First, typename... Rest>
SpacePtr copy_space(const Space& space) {
  if (const auto* typed = dynamic_cast<const First*>(&space)) {
    return std::make_shared<First>(*typed);
  }
  if constexpr (sizeof...(Rest) > 0) {
    return copy_space<Rest...>(space);
  } else {
    return nullptr;
  }
}

}  // namespace

AddRenderObservation::AddRenderObservation(std::unique_ptr<Env> env, bool render_only,
                                           const std::string& render_key,
                                           const std::string& obs_key)
    : ObservationWrapper(std::move(env)),
      render_only_(render_only),
      render_key_(render_key),
      obs_key_(obs_key) {
  const Metadata& metadata = env_->metadata();
  const auto& modes = metadata.render_modes;
  if (std::find(modes.begin(), modes.end(), "rgb_array") == modes.end()) {
    std::string names;
    for (const std::string& mode : modes) names += (names.empty() ? "\"" : ", \"") + mode + "\"";
    throw std::invalid_argument("AddRenderObservation: " + env_->name() +
                                " must render \"rgb_array\" frames; its render_modes are [" +
                                names + "]");
  }
  if (!metadata.render_shape) {
    throw std::invalid_argument(
        "AddRenderObservation: " + env_->name() +
        " does not declare metadata().render_shape, so the frame's space is unknown before "
        "rendering; set render_shape = (H, W, 3) in its metadata");
  }
  frame_shape_ = *metadata.render_shape;
  if (frame_shape_.size() != 3 || frame_shape_[2] != 3 || frame_shape_[0] < 1 ||
      frame_shape_[1] < 1) {
    throw std::invalid_argument("AddRenderObservation: " + env_->name() +
                                "'s metadata().render_shape must be (H, W, 3) with H, W >= 1, "
                                "got " +
                                shape_to_string(frame_shape_));
  }
  if (render_key.empty() || obs_key.empty()) {
    throw std::invalid_argument(
        "AddRenderObservation: render_key and obs_key must not be empty, "
        "got \"" +
        render_key + "\" and \"" + obs_key + "\"");
  }
  SpacePtr frame_space = uint8_image_space(frame_shape_);
  const Space& inner = env_->observation_space();
  if (render_only) {
    layout_ = Layout::kRenderOnly;
    set_observation_space(std::move(frame_space));
  } else if (const auto* dict = dynamic_cast<const spaces::Dict*>(&inner)) {
    if (dict->has(render_key)) {
      throw std::invalid_argument("AddRenderObservation: render_key \"" + render_key +
                                  "\" is already a key of the observation space " +
                                  inner.to_string() + "; keys: " + keys_of(*dict) +
                                  "; give another render_key");
    }
    layout_ = Layout::kDict;
    set_observation_space(dict->inserted(render_key, std::move(frame_space), 0));
  } else {
    if (render_key == obs_key) {
      throw std::invalid_argument(
          "AddRenderObservation: render_key and obs_key must differ, "
          "both are \"" +
          render_key + "\"");
    }
    SpacePtr copy = copy_space<spaces::Box, spaces::Discrete, spaces::MultiBinary,
                               spaces::MultiDiscrete, spaces::Tuple>(inner);
    if (copy == nullptr) {
      throw std::invalid_argument(
          "AddRenderObservation: the observation space must be a Dict, Box, Discrete, "
          "MultiBinary, MultiDiscrete or Tuple to be put under obs_key \"" +
          obs_key + "\", got " + inner.to_string());
    }
    layout_ = Layout::kWrapped;
    set_observation_space(std::make_shared<spaces::Dict>(
        spaces::Dict::Entries{{obs_key, std::move(copy)}, {render_key, std::move(frame_space)}}));
  }
}

void AddRenderObservation::observation(const Value& in, Value& out) {
  const Array frame = env_->render();
  if (frame.dtype() != DType::kUInt8 || frame.shape() != frame_shape_) {
    throw std::runtime_error("AddRenderObservation: " + env_->name() + "'s render() returned " +
                             dtype_name(frame.dtype()) + " " + shape_to_string(frame.shape()) +
                             ", its metadata().render_shape promised uint8 " +
                             shape_to_string(frame_shape_));
  }
  switch (layout_) {
    case Layout::kRenderOnly:
      out.array().copy_from(frame);
      break;
    case Layout::kDict: {
      std::vector<Value>& to = out.dict().values();
      to[0].array().copy_from(frame);
      const std::vector<Value>& from = in.dict().values();
      for (std::size_t i = 0; i < from.size(); ++i) copy_value(from[i], to[i + 1]);
      break;
    }
    case Layout::kWrapped:
      copy_value(in, out.dict().values()[0]);
      out.dict().values()[1].array().copy_from(frame);
      break;
  }
}

}  // namespace pixelgym::wrappers
