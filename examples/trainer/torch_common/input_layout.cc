#include "examples/trainer/torch_common/input_layout.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"

namespace pixelgym::trainer {
namespace {

std::string shape_text(const Shape& shape) {
  std::string text = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    text += (i ? ", " : "") + std::to_string(shape[i]);
  }
  return text + (shape.size() == 1 ? ",)" : ")");
}

}  // namespace

ReplayLayout InputLayout::replay_layout() const {
  ReplayLayout layout;
  if (has_image) layout.images.push_back({image_key, stack, height * width * channels});
  for (std::size_t v = 0; v < vector_keys.size(); ++v) {
    layout.vectors.push_back({vector_keys[v], vector_sizes[v]});
  }
  layout.action_size = action_size;
  return layout;
}

InputLayout input_layout(const Space& observation_space, const Space& action_space,
                         std::int64_t frame_stack, const std::string& learner,
                         const std::string& env_name) {
  const std::string where = learner + " on " + env_name + ": ";
  InputLayout input;
  input.stack = frame_stack;
  const auto* action_box = dynamic_cast<const spaces::Box*>(&action_space);
  if (action_box == nullptr || !is_floating(*action_box->dtype())) {
    throw std::invalid_argument(where +
                                "the learner acts with continuous (float Box) actions; the "
                                "action space is " +
                                action_space.to_string());
  }
  input.action_size = static_cast<std::int64_t>(action_box->low().size());
  for (std::size_t i = 0; i < action_box->low().size(); ++i) {
    const double low = action_box->low()[i];
    const double high = action_box->high()[i];
    if (!std::isfinite(low) || !std::isfinite(high)) {
      throw std::invalid_argument(where + "the action space must be bounded, got " +
                                  action_space.to_string());
    }
    input.action_low.push_back(static_cast<float>(low));
    input.action_high.push_back(static_cast<float>(high));
  }
  std::vector<std::pair<std::string, const Space*>> keys;
  if (const auto* dict = dynamic_cast<const spaces::Dict*>(&observation_space)) {
    for (const auto& [key, space] : dict->entries()) keys.emplace_back(key, space.get());
  } else {
    keys.emplace_back("", &observation_space);
  }
  for (const auto& [key, space] : keys) {
    const std::string named = key.empty() ? "the observation" : "key \"" + key + "\"";
    const auto* box = dynamic_cast<const spaces::Box*>(space);
    if (box == nullptr) {
      throw std::invalid_argument(where + named + " must be a Box, got " + space->to_string());
    }
    const Shape shape = *box->shape();
    if (*box->dtype() == DType::kUInt8 && shape.size() >= 2) {
      if (input.has_image) {
        throw std::invalid_argument(where + "one image key is supported; " + named +
                                    " is a second one");
      }
      // (stack, H, W[, C]) with a stack; (H, W[, C]) without.
      const std::size_t first = frame_stack > 1 ? 1 : 0;
      const bool fits = shape.size() == first + 2 || shape.size() == first + 3;
      if (!fits || (frame_stack > 1 && shape[0] != frame_stack)) {
        throw std::invalid_argument(
            where + "image " + named + " has shape " + shape_text(shape) + "; with frame_stack " +
            std::to_string(frame_stack) +
            (frame_stack > 1 ? " it must be a stack of that many frames on a new leading axis, "
                               "(stack, H, W) or (stack, H, W, C): add --wrap frame_stack=" +
                                   std::to_string(frame_stack) + " (or set frame_stack 1)"
                             : std::string(" it must be one frame, (H, W) or (H, W, C)")));
      }
      input.has_image = true;
      input.image_key = key;
      input.height = shape[first];
      input.width = shape[first + 1];
      input.channels = shape.size() == first + 3 ? shape[first + 2] : 1;
      if (input.height < 16 || input.width < 16) {
        throw std::invalid_argument(where + "image " + named + " of shape " + shape_text(shape) +
                                    " is smaller than the encoder's least, 16x16");
      }
      continue;
    }
    if (*box->dtype() != DType::kFloat32) {
      throw std::invalid_argument(
          where + named + " must be a uint8 image or a float32 vector, got " + space->to_string());
    }
    std::int64_t size = 1;
    for (const std::int64_t extent : shape) size *= extent;
    input.vector_keys.push_back(key);
    input.vector_sizes.push_back(size);
  }
  return input;
}

}  // namespace pixelgym::trainer

namespace pixelgym::trainer {
namespace {

// The array of `key` in a batched observation (the bare Array for key "").
const Array& observation_array(const Value& observations, const std::string& key) {
  return observations.is_array() && key.empty() ? observations.array()
                                                : observations.dict().at(key).array();
}

// Row `row` of the batched `observations` as the buffer reads it.
ObservationView view_row(const Value& observations, const InputLayout& input, std::int64_t row) {
  ObservationView view;
  if (input.has_image) {
    const Array& images = observation_array(observations, input.image_key);
    const std::size_t row_bytes = images.nbytes() / static_cast<std::size_t>(images.shape()[0]);
    view.images.push_back(static_cast<const std::uint8_t*>(images.raw_data()) +
                          static_cast<std::size_t>(row) * row_bytes);
  }
  for (std::size_t k = 0; k < input.vector_keys.size(); ++k) {
    const Array& values = observation_array(observations, input.vector_keys[k]);
    view.vectors.push_back(values.data<float>() + row * input.vector_sizes[k]);
  }
  return view;
}

}  // namespace

void add_first_observations(ReplayBuffer& buffer, const InputLayout& input,
                            const Value& observations) {
  const auto envs = observations.is_array()
                        ? observations.array().shape()[0]
                        : observations.dict().values().front().array().shape()[0];
  for (std::int64_t e = 0; e < envs; ++e) buffer.add_first(e, view_row(observations, input, e));
}

void add_env_step(ReplayBuffer& buffer, const InputLayout& input, const float* unit_actions,
                  const vector::VectorStepResult& step, const std::string& learner) {
  const double* rewards = step.rewards.data<double>();
  const bool* terminated = step.terminated.data<bool>();
  const bool* truncated = step.truncated.data<bool>();
  const auto envs = step.rewards.shape()[0];
  for (std::int64_t e = 0; e < envs; ++e) {
    const bool ended = terminated[e] || truncated[e];
    if (ended && !step.infos.contains("final_obs")) {
      throw std::logic_error(learner + ": an episode ended without infos[\"final_obs\"]");
    }
    buffer.add_step(e, unit_actions + e * input.action_size, rewards[e], terminated[e],
                    truncated[e],
                    view_row(ended ? step.infos.at("final_obs") : step.obs, input, e));
    if (ended) buffer.add_first(e, view_row(step.obs, input, e));
  }
}

}  // namespace pixelgym::trainer
