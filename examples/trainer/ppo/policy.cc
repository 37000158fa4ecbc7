#include "examples/trainer/ppo/policy.h"

#include <cmath>
#include <iterator>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"

namespace pixelgym::ppo {
namespace {

namespace nn = torch::nn;
constexpr double kLog2Pi = 1.8378770664093453;  // log(2 pi)
constexpr double kNormalizeEpsilon = 1e-8;      // as Gymnasium's NormalizeObservation

std::string describe(const std::string& key) {
  return key.empty() ? std::string("the observation") : "key \"" + key + "\"";
}

// Reads one Box of the observation space into a PolicyInput.
PolicyInput make_input(const std::string& key, const Space& space) {
  const auto* box = dynamic_cast<const spaces::Box*>(&space);
  if (box == nullptr) {
    throw std::invalid_argument("Policy: " + describe(key) + " must be a Box, got " +
                                space.to_string());
  }
  PolicyInput input;
  input.key = key;
  input.shape = *box->shape();
  input.dtype = *box->dtype();
  if (input.dtype == DType::kBool) {
    throw std::invalid_argument("Policy: " + describe(key) +
                                " is a bool Box, not supported: " + space.to_string());
  }
  const Shape& s = input.shape;
  input.image = input.dtype == DType::kUInt8 && s.size() >= 2 && s.size() <= 4;
  if (!input.image) return input;
  if (s.size() == 2) {
    input.layout = ImageLayout::kHW;
    input.channels = 1;
    input.height = s[0];
    input.width = s[1];
  } else if (s.size() == 3) {
    if (s[2] <= s[0]) {
      input.layout = ImageLayout::kHWC;
      input.channels = s[2];
      input.height = s[0];
      input.width = s[1];
    } else {
      input.layout = ImageLayout::kCHW;
      input.channels = s[0];
      input.height = s[1];
      input.width = s[2];
    }
  } else if (s[3] <= s[1]) {
    input.layout = ImageLayout::kStackedHWC;
    input.channels = s[0] * s[3];
    input.height = s[1];
    input.width = s[2];
  } else {
    input.layout = ImageLayout::kStackedCHW;
    input.channels = s[0] * s[1];
    input.height = s[2];
    input.width = s[3];
  }
  return input;
}

void orthogonal(nn::Linear& layer, double gain) {
  nn::init::orthogonal_(layer->weight, gain);
  nn::init::zeros_(layer->bias);
}
void orthogonal(nn::Conv2d& layer, double gain) {
  nn::init::orthogonal_(layer->weight, gain);
  nn::init::zeros_(layer->bias);
}

struct Conv {
  std::int64_t channels, kernel, stride;
};
// Each CnnArchitecture: its name and its convolutions (a ReLU after each).
struct CnnSpec {
  CnnArchitecture architecture;
  const char* name;
  std::vector<Conv> convs;
};
const std::vector<CnnSpec>& cnn_specs() {
  static const std::vector<CnnSpec> specs = {
      {CnnArchitecture::kNature, "nature", {{32, 8, 4}, {64, 4, 2}, {64, 3, 1}}},
      {CnnArchitecture::kSmall, "small", {{16, 8, 4}, {32, 4, 2}}},
      {CnnArchitecture::kFine, "fine", {{32, 3, 2}, {32, 3, 2}, {32, 3, 2}}},
      {CnnArchitecture::kFiner, "finer", {{32, 3, 2}, {32, 3, 2}, {32, 3, 1}}},
  };
  return specs;
}
const CnnSpec& cnn_spec(CnnArchitecture architecture) {
  for (const CnnSpec& spec : cnn_specs()) {
    if (spec.architecture == architecture) return spec;
  }
  throw std::invalid_argument("unknown CNN architecture " +
                              std::to_string(static_cast<int>(architecture)));
}

nn::Sequential make_cnn(const PolicyInput& input, const PolicyConfig& config) {
  const CnnSpec& spec = cnn_spec(config.cnn);
  const double gain = std::sqrt(2.0);
  nn::Sequential cnn;
  std::int64_t channels = input.channels;
  std::int64_t height = input.height;
  std::int64_t width = input.width;
  for (const Conv& c : spec.convs) {
    height = (height - c.kernel) / c.stride + 1;
    width = (width - c.kernel) / c.stride + 1;
    if (height < 1 || width < 1) {
      throw std::invalid_argument(
          "Policy: image " + describe(input.key) + " of (C, H, W) = (" +
          std::to_string(input.channels) + ", " + std::to_string(input.height) + ", " +
          std::to_string(input.width) + ") is too small for the " + to_string(config.cnn) + " CNN");
    }
    nn::Conv2d conv(nn::Conv2dOptions(channels, c.channels, c.kernel).stride(c.stride));
    orthogonal(conv, gain);
    cnn->push_back(conv);
    cnn->push_back(nn::ReLU());
    channels = c.channels;
  }
  cnn->push_back(nn::Flatten());
  nn::Linear linear(channels * height * width, config.cnn_features);
  orthogonal(linear, gain);
  cnn->push_back(linear);
  cnn->push_back(nn::ReLU());
  return cnn;
}

void require_batch(const PolicyInput& input, const torch::Tensor& batch) {
  const auto sizes = batch.sizes();
  bool ok = batch.defined() && batch.dim() == static_cast<std::int64_t>(input.shape.size()) + 1 &&
            batch.scalar_type() == torch_dtype(input.dtype);
  for (std::size_t d = 0; ok && d < input.shape.size(); ++d) {
    ok = sizes[static_cast<std::int64_t>(d) + 1] == input.shape[d];
  }
  if (!ok) {
    std::string got = batch.defined() ? std::string(c10::toString(batch.scalar_type())) + " " +
                                            c10::str(batch.sizes())
                                      : std::string("an undefined tensor");
    throw std::invalid_argument("Policy: " + describe(input.key) + " must be a batch of " +
                                dtype_name(input.dtype) + " " + shape_to_string(input.shape) +
                                ", got " + got);
  }
}

}  // namespace

const char* to_string(CnnArchitecture architecture) { return cnn_spec(architecture).name; }

CnnArchitecture parse_cnn_architecture(const std::string& name) {
  std::string valid;
  for (const CnnSpec& spec : cnn_specs()) {
    if (name == spec.name) return spec.architecture;
    valid += std::string(valid.empty() ? "" : ", ") + "\"" + spec.name + "\"";
  }
  throw std::invalid_argument("unknown CNN architecture \"" + name + "\"; valid: " + valid);
}

void PolicyConfig::validate() const { trainer::check_settings(*this, "PolicyConfig"); }

const trainer::ChoiceNames<CnnArchitecture>& cnn_names() {
  static const trainer::ChoiceNames<CnnArchitecture> names = [] {
    trainer::ChoiceNames<CnnArchitecture> list;
    for (const CnnSpec& spec : cnn_specs()) list.emplace_back(spec.name, spec.architecture);
    return list;
  }();
  return names;
}

Policy::Policy(const Space& observation_space, const Space& action_space, PolicyConfig config)
    : config_(std::move(config)) {
  config_.validate();
  if (const auto* dict = dynamic_cast<const spaces::Dict*>(&observation_space)) {
    for (const auto& [key, space] : dict->entries()) inputs_.push_back(make_input(key, *space));
  } else {
    inputs_.push_back(make_input("", observation_space));
  }

  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    if (inputs_[i].image) continue;
    vector_inputs_.push_back(i);
    vector_sizes_.push_back(shape_size(inputs_[i].shape));
  }
  std::int64_t features = 0;
  std::tie(encoder_, features) = make_encoder("");
  for (std::size_t v = 0; v < vector_inputs_.size(); ++v) {
    const auto size = vector_sizes_[v];
    const std::string suffix = std::to_string(v);
    statistics_mean_.push_back(
        register_buffer("observation_mean" + suffix, torch::zeros({size}, torch::kFloat64)));
    statistics_var_.push_back(
        register_buffer("observation_var" + suffix, torch::ones({size}, torch::kFloat64)));
    statistics_count_.push_back(register_buffer(
        "observation_count" + suffix,
        torch::full({}, wrappers::RunningStatistics::kInitialCount, torch::kFloat64)));
  }

  if (const auto* discrete = dynamic_cast<const spaces::Discrete*>(&action_space)) {
    discrete_ = true;
    action_size_ = discrete->n();
    action_start_ = discrete->start();
  } else if (const auto* box = dynamic_cast<const spaces::Box*>(&action_space);
             box != nullptr && is_floating(*box->dtype())) {
    action_shape_ = *box->shape();
    action_size_ = shape_size(action_shape_);
    std::vector<float> low(box->low().begin(), box->low().end());
    std::vector<float> high(box->high().begin(), box->high().end());
    action_low_ = torch::tensor(low, torch::kFloat32);
    action_high_ = torch::tensor(high, torch::kFloat32);
    log_std_ = register_parameter(
        "log_std", torch::full({action_size_}, config_.initial_log_std, torch::kFloat32));
  } else {
    throw std::invalid_argument("Policy: the action space must be Discrete or a float Box, got " +
                                action_space.to_string());
  }
  action_head_ = register_module("action_head", nn::Linear(features, action_size_));
  orthogonal(action_head_, 0.01);
  // Built last, so that the shared network's initial weights do not depend on the option.
  std::int64_t value_features = features;
  if (config_.separate_value_network) {
    Encoder value_encoder;
    std::tie(value_encoder, value_features) = make_encoder("value_");
    value_encoder_ = std::move(value_encoder);
  }
  value_head_ = register_module("value_head", nn::Linear(value_features, 1));
  orthogonal(value_head_, 1.0);
}

std::pair<Policy::Encoder, std::int64_t> Policy::make_encoder(const std::string& prefix) {
  const double gain = std::sqrt(2.0);
  Encoder encoder;
  std::int64_t fused = 0;
  for (const PolicyInput& input : inputs_) {
    if (!input.image) continue;
    encoder.cnns.push_back(register_module(prefix + "cnn" + std::to_string(encoder.cnns.size()),
                                           make_cnn(input, config_)));
    fused += config_.cnn_features;
  }
  if (!vector_inputs_.empty()) {
    std::int64_t width = 0;
    for (std::int64_t size : vector_sizes_) width += size;
    encoder.mlp = nn::Sequential();
    for (std::int64_t hidden : config_.mlp_hidden) {
      nn::Linear linear(width, hidden);
      orthogonal(linear, gain);
      encoder.mlp->push_back(linear);
      encoder.mlp->push_back(nn::Tanh());
      width = hidden;
    }
    if (!config_.mlp_hidden.empty()) register_module(prefix + "mlp", encoder.mlp);
    fused += width;
  }
  if (config_.trunk_hidden == 0) return {encoder, fused};
  nn::Linear linear(fused, config_.trunk_hidden);
  orthogonal(linear, gain);
  encoder.trunk = register_module(prefix + "trunk", nn::Sequential(linear, nn::ReLU()));
  return {encoder, config_.trunk_hidden};
}

torch::Tensor Policy::encode(Encoder& encoder, const std::vector<torch::Tensor>& images,
                             const torch::Tensor& vectors) {
  std::vector<torch::Tensor> features;
  features.reserve(images.size() + 1);
  for (std::size_t i = 0; i < images.size(); ++i)
    features.push_back(encoder.cnns[i]->forward(images[i]));
  if (vectors.defined()) {
    features.push_back(config_.mlp_hidden.empty() ? vectors : encoder.mlp->forward(vectors));
  }
  torch::Tensor fused = features.size() == 1 ? features[0] : torch::cat(features, 1);
  return encoder.trunk ? encoder.trunk->forward(fused) : fused;
}

torch::Tensor Policy::image_input(const PolicyInput& input, const torch::Tensor& batch) const {
  const std::int64_t b = batch.size(0);
  torch::Tensor chw;
  switch (input.layout) {
    case ImageLayout::kHW:
      chw = batch.unsqueeze(1);
      break;
    case ImageLayout::kHWC:
      chw = batch.permute({0, 3, 1, 2});
      break;
    case ImageLayout::kCHW:
      chw = batch;
      break;
    case ImageLayout::kStackedHWC:
      chw = batch.permute({0, 1, 4, 2, 3}).reshape({b, input.channels, input.height, input.width});
      break;
    case ImageLayout::kStackedCHW:
      chw = batch.reshape({b, input.channels, input.height, input.width});
      break;
  }
  return chw.to(torch::kFloat32).contiguous().div_(255.0);
}

torch::Tensor Policy::vector_input(std::size_t v, const torch::Tensor& batch) const {
  torch::Tensor x = batch.reshape({batch.size(0), vector_sizes_[v]}).to(torch::kFloat32);
  if (!config_.normalize_observations) return x;
  const torch::Tensor mean = statistics_mean_[v].to(torch::kFloat32);
  const torch::Tensor scale = (statistics_var_[v] + kNormalizeEpsilon).rsqrt().to(torch::kFloat32);
  return ((x - mean) * scale).clamp(-config_.observation_clip, config_.observation_clip);
}

Policy::Heads Policy::forward(const ObservationTensors& obs, const torch::Tensor& shifts,
                              std::int64_t pad) {
  std::vector<torch::Tensor> images;
  std::vector<torch::Tensor> vectors;
  std::size_t vector = 0;
  std::int64_t batch_size = -1;
  for (const PolicyInput& input : inputs_) {
    auto found = obs.find(input.key);
    if (found == obs.end()) {
      throw std::invalid_argument("Policy: the observation batch has no " + describe(input.key));
    }
    const torch::Tensor& batch = found->second;
    require_batch(input, batch);
    if (batch_size >= 0 && batch.size(0) != batch_size) {
      throw std::invalid_argument("Policy: " + describe(input.key) + " has " +
                                  std::to_string(batch.size(0)) + " rows, the others " +
                                  std::to_string(batch_size));
    }
    batch_size = batch.size(0);
    if (input.image) {
      torch::Tensor image = image_input(input, batch);
      if (shifts.defined()) image = random_shift(image, shifts, pad);
      images.push_back(std::move(image));
    } else {
      vectors.push_back(vector_input(vector++, batch));
    }
  }
  torch::Tensor vector_batch;
  if (!vectors.empty()) vector_batch = vectors.size() == 1 ? vectors[0] : torch::cat(vectors, 1);
  const torch::Tensor features = encode(encoder_, images, vector_batch);
  const torch::Tensor value_features =
      value_encoder_ ? encode(*value_encoder_, images, vector_batch) : features;
  return {action_head_->forward(features), value_head_->forward(value_features).squeeze(1)};
}

ActResult Policy::act(const ObservationTensors& obs, bool deterministic,
                      std::optional<at::Generator> generator) {
  Heads heads = forward(obs, {}, 0);
  const c10::optional<at::Generator> gen =
      generator ? c10::optional<at::Generator>(*generator) : c10::nullopt;
  ActResult result;
  result.value = heads.value;
  const std::int64_t b = heads.logits_or_mean.size(0);
  if (discrete_) {
    const torch::Tensor log_probs = torch::log_softmax(heads.logits_or_mean, 1);
    if (deterministic) {
      result.action = log_probs.argmax(1);
    } else {
      result.action = torch::multinomial(log_probs.exp(), 1, /*replacement=*/true, gen).squeeze(1);
    }
    result.log_prob = log_probs.gather(1, result.action.unsqueeze(1)).squeeze(1);
  } else {
    const torch::Tensor& mean = heads.logits_or_mean;
    torch::Tensor flat = mean;
    if (!deterministic) {
      const torch::Tensor noise = at::normal(0.0, 1.0, mean.sizes(), gen);
      flat = mean + noise * log_std_.exp();
    }
    result.log_prob =
        (-0.5 * ((flat - mean) * (-log_std_).exp()).pow(2) - log_std_ - 0.5 * kLog2Pi).sum(1);
    std::vector<std::int64_t> shape{b};
    shape.insert(shape.end(), action_shape_.begin(), action_shape_.end());
    result.action = flat.reshape(shape);
  }
  result.env_action = env_action(result.action);
  return result;
}

Evaluation Policy::evaluate(const ObservationTensors& obs, const torch::Tensor& actions,
                            const torch::Tensor& shifts, std::int64_t shift_pad) {
  Heads heads = forward(obs, shifts, shift_pad);
  Evaluation result;
  result.value = heads.value;
  const std::int64_t b = heads.logits_or_mean.size(0);
  if (actions.size(0) != b) {
    throw std::invalid_argument("Policy::evaluate: " + std::to_string(actions.size(0)) +
                                " actions for " + std::to_string(b) + " observations");
  }
  if (discrete_) {
    const torch::Tensor log_probs = torch::log_softmax(heads.logits_or_mean, 1);
    result.log_prob = log_probs.gather(1, actions.reshape({b, 1}).to(torch::kInt64)).squeeze(1);
    result.entropy = -(log_probs.exp() * log_probs).sum(1);
  } else {
    const torch::Tensor flat = actions.reshape({b, action_size_}).to(torch::kFloat32);
    const torch::Tensor& mean = heads.logits_or_mean;
    result.log_prob =
        (-0.5 * ((flat - mean) * (-log_std_).exp()).pow(2) - log_std_ - 0.5 * kLog2Pi).sum(1);
    result.entropy = (0.5 + 0.5 * kLog2Pi + log_std_).sum().expand({b});
  }
  return result;
}

torch::Tensor Policy::value(const ObservationTensors& obs) { return forward(obs, {}, 0).value; }

torch::Tensor Policy::env_action(const torch::Tensor& action) const {
  if (discrete_) return action.to(torch::kInt64) + action_start_;
  const std::int64_t b = action.size(0);
  const torch::Tensor flat = action.reshape({b, action_size_}).to(torch::kFloat32);
  return torch::max(torch::min(flat, action_high_), action_low_).reshape(action.sizes());
}

void Policy::update_observation_statistics(const ObservationTensors& obs) {
  if (!config_.normalize_observations) return;
  torch::NoGradGuard no_grad;
  for (std::size_t v = 0; v < vector_inputs_.size(); ++v) {
    const PolicyInput& input = inputs_[vector_inputs_[v]];
    auto found = obs.find(input.key);
    if (found == obs.end()) {
      throw std::invalid_argument("Policy: the observation batch has no " + describe(input.key));
    }
    require_batch(input, found->second);
    const std::int64_t size = vector_sizes_[v];
    const torch::Tensor rows =
        found->second.reshape({found->second.size(0), size}).to(torch::kFloat64).contiguous();
    const double* data = rows.data_ptr<double>();
    wrappers::RunningStatistics statistics = observation_statistics(input.key);
    statistics.update_batch(
        static_cast<std::size_t>(rows.size(0)), [&](std::size_t row, std::size_t i) {
          return data[static_cast<std::int64_t>(row) * size + static_cast<std::int64_t>(i)];
        });
    set_observation_statistics(input.key, statistics);
  }
}

wrappers::RunningStatistics Policy::observation_statistics(const std::string& key) const {
  for (std::size_t v = 0; v < vector_inputs_.size(); ++v) {
    if (inputs_[vector_inputs_[v]].key != key) continue;
    const torch::Tensor mean = statistics_mean_[v].contiguous();
    const torch::Tensor var = statistics_var_[v].contiguous();
    wrappers::RunningStatistics statistics;
    statistics.mean.assign(mean.data_ptr<double>(), mean.data_ptr<double>() + mean.numel());
    statistics.var.assign(var.data_ptr<double>(), var.data_ptr<double>() + var.numel());
    statistics.count = statistics_count_[v].item<double>();
    return statistics;
  }
  throw std::out_of_range("Policy: " + describe(key) + " is not a vector key");
}

void Policy::set_observation_statistics(const std::string& key,
                                        const wrappers::RunningStatistics& statistics) {
  for (std::size_t v = 0; v < vector_inputs_.size(); ++v) {
    if (inputs_[vector_inputs_[v]].key != key) continue;
    const std::string reason =
        statistics.invalid_reason(static_cast<std::size_t>(vector_sizes_[v]));
    if (!reason.empty()) {
      throw std::invalid_argument("Policy: statistics of " + describe(key) + ": " + reason);
    }
    torch::NoGradGuard no_grad;
    statistics_mean_[v].copy_(torch::tensor(statistics.mean, torch::kFloat64));
    statistics_var_[v].copy_(torch::tensor(statistics.var, torch::kFloat64));
    statistics_count_[v].fill_(statistics.count);
    return;
  }
  throw std::out_of_range("Policy: " + describe(key) + " is not a vector key");
}

std::int64_t ActResult::clipped_elements() const {
  if (!action.is_floating_point()) return 0;
  return action.ne(env_action).sum().item<std::int64_t>();
}

}  // namespace pixelgym::ppo
