#include "examples/trainer/torch_common/replay_buffer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace pixelgym::trainer {

ReplayBuffer::ReplayBuffer(ReplayLayout layout, std::int64_t num_envs, std::int64_t capacity,
                           std::int64_t n_step, double gamma)
    : layout_(std::move(layout)), num_envs_(num_envs), n_step_(n_step), gamma_(gamma) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("ReplayBuffer: " + what);
  };
  if (num_envs_ < 1) fail("num_envs must be at least 1, got " + std::to_string(num_envs_));
  if (n_step_ < 1) fail("n_step must be at least 1, got " + std::to_string(n_step_));
  if (!(gamma_ >= 0.0 && gamma_ <= 1.0))
    fail("gamma must be in [0, 1], got " + std::to_string(gamma_));
  if (layout_.action_size < 1) {
    fail("action_size must be at least 1, got " + std::to_string(layout_.action_size));
  }
  for (const ReplayLayout::Image& image : layout_.images) {
    if (image.stack < 1 || image.frame_bytes < 1) {
      fail("image key \"" + image.key + "\" needs stack >= 1 and frame_bytes >= 1, got " +
           std::to_string(image.stack) + " and " + std::to_string(image.frame_bytes));
    }
    max_stack_ = std::max(max_stack_, image.stack);
  }
  for (const ReplayLayout::Vector& vector : layout_.vectors) {
    if (vector.size < 1) {
      fail("vector key \"" + vector.key + "\" needs size >= 1, got " + std::to_string(vector.size));
    }
  }
  slots_per_env_ = capacity / num_envs_;
  const std::int64_t minimum = n_step_ + max_stack_ + 2;
  if (slots_per_env_ < minimum) {
    fail("capacity " + std::to_string(capacity) + " is too small: each of the " +
         std::to_string(num_envs_) +
         " envs needs at least n_step + frame stack + 2 = " + std::to_string(minimum) + " slots");
  }
  envs_.resize(static_cast<std::size_t>(num_envs_));
  const auto slots = static_cast<std::size_t>(slots_per_env_);
  for (EnvSlots& env : envs_) {
    for (const ReplayLayout::Image& image : layout_.images) {
      // Not zero-filled: pages the buffer never writes are never touched.
      env.frames.emplace_back(
          new std::uint8_t[slots * static_cast<std::size_t>(image.frame_bytes)]);
    }
    for (const ReplayLayout::Vector& vector : layout_.vectors) {
      env.vectors.emplace_back(slots * static_cast<std::size_t>(vector.size));
    }
    env.actions.resize(slots * static_cast<std::size_t>(layout_.action_size));
    env.rewards.resize(slots);
    env.flags.resize(slots);
    env.episode_start.resize(slots);
  }
}

std::int64_t ReplayBuffer::oldest(const EnvSlots& slots) const {
  return std::max<std::int64_t>(0, slots.written - slots_per_env_);
}

void ReplayBuffer::copy_stack(const EnvSlots& slots, std::size_t i, std::int64_t global,
                              std::uint8_t* dest) const {
  const ReplayLayout::Image& image = layout_.images[i];
  const auto bytes = static_cast<std::size_t>(image.frame_bytes);
  const std::int64_t start = slots.episode_start[static_cast<std::size_t>(ring(global))];
  for (std::int64_t d = 0; d < image.stack; ++d) {
    const std::int64_t source = std::max(global - (image.stack - 1) + d, start);
    std::memcpy(dest + static_cast<std::size_t>(d) * bytes,
                slots.frames[i].get() + static_cast<std::size_t>(ring(source)) * bytes, bytes);
  }
}

void ReplayBuffer::check_observation(std::int64_t env, std::int64_t global, std::int64_t start,
                                     const ObservationView& obs) const {
  if (obs.images.size() != layout_.images.size() || obs.vectors.size() != layout_.vectors.size()) {
    throw std::invalid_argument(
        "ReplayBuffer: an observation of " + std::to_string(obs.images.size()) + " images and " +
        std::to_string(obs.vectors.size()) + " vectors, expected " +
        std::to_string(layout_.images.size()) + " and " + std::to_string(layout_.vectors.size()));
  }
  const EnvSlots& slots = envs_[static_cast<std::size_t>(env)];
  for (std::size_t i = 0; i < layout_.images.size(); ++i) {
    const ReplayLayout::Image& image = layout_.images[i];
    const auto bytes = static_cast<std::size_t>(image.frame_bytes);
    const std::uint8_t* stack = obs.images[i];
    const std::uint8_t* newest = stack + static_cast<std::size_t>(image.stack - 1) * bytes;
    // The older frames of the stack must be the episode's, as they will be rebuilt.
    for (std::int64_t d = 0; d + 1 < image.stack; ++d) {
      const std::int64_t source = std::max(global - (image.stack - 1) + d, start);
      const std::uint8_t* expected =
          source == global ? newest
                           : slots.frames[i].get() + static_cast<std::size_t>(ring(source)) * bytes;
      if (std::memcmp(stack + static_cast<std::size_t>(d) * bytes, expected, bytes) != 0) {
        throw std::invalid_argument(
            "ReplayBuffer: image key \"" + image.key + "\" of env " + std::to_string(env) +
            ": frame " + std::to_string(d) + " of the stack of " + std::to_string(image.stack) +
            " is not the episode's frame from " + std::to_string(image.stack - 1 - d) +
            " steps before (the buffer rebuilds stacks as FrameStackObservation does with "
            "layout=new_axis and padding=reset, the oldest frame first)");
      }
    }
  }
}

void ReplayBuffer::write_observation(std::int64_t env, std::int64_t global, std::int64_t start,
                                     const ObservationView& obs) {
  EnvSlots& slots = envs_[static_cast<std::size_t>(env)];
  const auto slot = static_cast<std::size_t>(ring(global));
  slots.episode_start[slot] = start;
  slots.flags[slot] = 0;
  for (std::size_t i = 0; i < layout_.images.size(); ++i) {
    const ReplayLayout::Image& image = layout_.images[i];
    const auto bytes = static_cast<std::size_t>(image.frame_bytes);
    std::memcpy(slots.frames[i].get() + slot * bytes,
                obs.images[i] + static_cast<std::size_t>(image.stack - 1) * bytes, bytes);
  }
  for (std::size_t v = 0; v < layout_.vectors.size(); ++v) {
    const auto size = static_cast<std::size_t>(layout_.vectors[v].size);
    std::memcpy(slots.vectors[v].data() + slot * size, obs.vectors[v], size * sizeof(float));
  }
  slots.written = global + 1;
  slots.open = true;
}

void ReplayBuffer::add_first(std::int64_t env, const ObservationView& obs) {
  if (env < 0 || env >= num_envs_) {
    throw std::out_of_range("ReplayBuffer::add_first: env " + std::to_string(env) + " of " +
                            std::to_string(num_envs_));
  }
  EnvSlots& slots = envs_[static_cast<std::size_t>(env)];
  check_observation(env, slots.written, slots.written, obs);
  write_observation(env, slots.written, slots.written, obs);
}

void ReplayBuffer::add_step(std::int64_t env, const float* action, double reward, bool terminated,
                            bool truncated, const ObservationView& next_obs) {
  if (env < 0 || env >= num_envs_) {
    throw std::out_of_range("ReplayBuffer::add_step: env " + std::to_string(env) + " of " +
                            std::to_string(num_envs_));
  }
  EnvSlots& slots = envs_[static_cast<std::size_t>(env)];
  if (!slots.open) {
    throw std::logic_error("ReplayBuffer::add_step: env " + std::to_string(env) +
                           " has no observation to act from (add_first starts an episode)");
  }
  const std::int64_t current = slots.written - 1;
  const auto slot = static_cast<std::size_t>(ring(current));
  check_observation(env, current + 1, slots.episode_start[slot], next_obs);
  const auto size = static_cast<std::size_t>(layout_.action_size);
  std::memcpy(slots.actions.data() + slot * size, action, size * sizeof(float));
  slots.rewards[slot] = static_cast<float>(reward);
  slots.flags[slot] = static_cast<std::uint8_t>(kHasAction | (terminated ? kTerminated : 0) |
                                                (truncated ? kTruncated : 0));
  write_observation(env, current + 1, slots.episode_start[slot], next_obs);
  // The episode's last observation takes no action: the next must be an add_first.
  slots.open = !(terminated || truncated);
  ++steps_added_;
}

bool ReplayBuffer::window(const EnvSlots& slots, std::int64_t global, Window& out) const {
  const std::int64_t first = oldest(slots);
  if (global < first || global >= slots.written) return false;
  const auto slot = static_cast<std::size_t>(ring(global));
  if ((slots.flags[slot] & kHasAction) == 0) return false;
  if (std::max(global - (max_stack_ - 1), slots.episode_start[slot]) < first) return false;
  double reward = 0.0;
  double discount = 1.0;
  for (std::int64_t i = global;; ++i) {
    if (i >= slots.written) return false;
    const std::uint8_t flags = slots.flags[static_cast<std::size_t>(ring(i))];
    if ((flags & kHasAction) == 0) return false;  // the step is not known yet
    reward += discount * slots.rewards[static_cast<std::size_t>(ring(i))];
    discount *= gamma_;
    const bool terminated = (flags & kTerminated) != 0;
    if (terminated || (flags & kTruncated) != 0 || i + 1 - global == n_step_) {
      out.next = i + 1;
      out.reward = static_cast<float>(reward);
      out.discount = terminated ? 0.0f : static_cast<float>(discount);
      return true;
    }
  }
}

void ReplayBuffer::copy_observation(const EnvSlots& slots, std::int64_t global, std::int64_t row,
                                    std::vector<std::vector<std::uint8_t>>& images,
                                    std::vector<std::vector<float>>& vectors) const {
  for (std::size_t i = 0; i < layout_.images.size(); ++i) {
    const ReplayLayout::Image& image = layout_.images[i];
    copy_stack(slots, i, global,
               images[i].data() + static_cast<std::size_t>(row * image.stack * image.frame_bytes));
  }
  const auto slot = static_cast<std::size_t>(ring(global));
  for (std::size_t v = 0; v < layout_.vectors.size(); ++v) {
    const auto size = static_cast<std::size_t>(layout_.vectors[v].size);
    std::memcpy(vectors[v].data() + static_cast<std::size_t>(row) * size,
                slots.vectors[v].data() + slot * size, size * sizeof(float));
  }
}

void ReplayBuffer::sample(std::int64_t batch_size, std::mt19937_64& rng, ReplayBatch& batch) const {
  if (!can_sample()) {
    throw std::logic_error("ReplayBuffer::sample: no transition can be sampled yet (" +
                           std::to_string(steps_added_) + " steps added)");
  }
  const auto rows = static_cast<std::size_t>(batch_size);
  batch.size = batch_size;
  const auto resize = [&](auto& per_key, auto width) {
    per_key.resize(width.size());
    for (std::size_t k = 0; k < width.size(); ++k) per_key[k].resize(rows * width[k]);
  };
  std::vector<std::size_t> image_bytes;
  std::vector<std::size_t> vector_sizes;
  for (const auto& image : layout_.images) {
    image_bytes.push_back(static_cast<std::size_t>(image.stack * image.frame_bytes));
  }
  for (const auto& vector : layout_.vectors) {
    vector_sizes.push_back(static_cast<std::size_t>(vector.size));
  }
  resize(batch.images, image_bytes);
  resize(batch.next_images, image_bytes);
  resize(batch.vectors, vector_sizes);
  resize(batch.next_vectors, vector_sizes);
  const auto action_size = static_cast<std::size_t>(layout_.action_size);
  batch.actions.resize(rows * action_size);
  batch.rewards.resize(rows);
  batch.discounts.resize(rows);

  std::int64_t total = 0;
  for (const EnvSlots& slots : envs_) total += slots.written - oldest(slots);
  std::uniform_int_distribution<std::int64_t> pick(0, total - 1);
  for (std::int64_t row = 0; row < batch_size; ++row) {
    // Uniform over the slots in use; slots that cannot be sampled are drawn again.
    for (;;) {
      std::int64_t u = pick(rng);
      std::size_t e = 0;
      while (u >= envs_[e].written - oldest(envs_[e])) {
        u -= envs_[e].written - oldest(envs_[e]);
        ++e;
      }
      const EnvSlots& slots = envs_[e];
      const std::int64_t global = oldest(slots) + u;
      Window found;
      if (!window(slots, global, found)) continue;
      copy_observation(slots, global, row, batch.images, batch.vectors);
      copy_observation(slots, found.next, row, batch.next_images, batch.next_vectors);
      std::memcpy(batch.actions.data() + static_cast<std::size_t>(row) * action_size,
                  slots.actions.data() + static_cast<std::size_t>(ring(global)) * action_size,
                  action_size * sizeof(float));
      batch.rewards[static_cast<std::size_t>(row)] = found.reward;
      batch.discounts[static_cast<std::size_t>(row)] = found.discount;
      break;
    }
  }
}

bool ReplayBuffer::can_sample() const {
  for (const EnvSlots& slots : envs_) {
    Window found;
    for (std::int64_t g = oldest(slots); g < slots.written; ++g) {
      if (window(slots, g, found)) return true;
    }
  }
  return false;
}

std::int64_t ReplayBuffer::slots_used() const {
  std::int64_t used = 0;
  for (const EnvSlots& slots : envs_) used += slots.written - oldest(slots);
  return used;
}

std::int64_t ReplayBuffer::bytes() const {
  std::int64_t per_slot = static_cast<std::int64_t>(sizeof(float)) * (layout_.action_size + 1) + 1 +
                          static_cast<std::int64_t>(sizeof(std::int64_t));
  for (const auto& image : layout_.images) per_slot += image.frame_bytes;
  for (const auto& vector : layout_.vectors) {
    per_slot += vector.size * static_cast<std::int64_t>(sizeof(float));
  }
  return per_slot * slots_per_env_ * num_envs_;
}

}  // namespace pixelgym::trainer
