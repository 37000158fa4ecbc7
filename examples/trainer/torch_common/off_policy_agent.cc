#include "examples/trainer/torch_common/off_policy_agent.h"

#include <ATen/CPUGeneratorImpl.h>

#include <cstring>
#include <stdexcept>
#include <utility>

#include "examples/trainer/torch_common/off_policy_networks.h"
#include "examples/trainer/torch_common/random_shift.h"
#include "pixelgym/testing/mlp_policy.h"

namespace pixelgym::trainer {

OffPolicyAgent::OffPolicyAgent(InputLayout input, const OffPolicySettings& settings)
    : input_(std::move(input)),
      autocast_(settings.bfloat16 && cpu_has_bfloat16()),
      channels_last_(settings.channels_last) {
  low_ = register_buffer("action_low", torch::tensor(input_.action_low, torch::kFloat32));
  high_ = register_buffer("action_high", torch::tensor(input_.action_high, torch::kFloat32));
}

std::int64_t OffPolicyAgent::register_encoder(EncoderArchitecture architecture,
                                              const std::string& who) {
  if (!input_.has_image) return 0;
  ConvEncoder conv = make_conv_encoder(architecture, input_.stack * input_.channels, input_.height,
                                       input_.width, who);
  encoder = register_module("encoder", conv.layers);
  return conv.features;
}

torch::Tensor OffPolicyAgent::image_input(const torch::Tensor& images) const {
  const std::int64_t batch = images.size(0);
  const std::int64_t channels = input_.stack * input_.channels;
  const torch::Tensor frames =
      images.view({batch, input_.stack, input_.height, input_.width, input_.channels});
  if (channels_last_) {
    // (B, H, W, stack C) in memory: the channels-last layout of (B, stack C, H, W).
    return frames.permute({0, 2, 3, 1, 4})
        .reshape({batch, input_.height, input_.width, channels})
        .to(torch::kFloat32)
        .permute({0, 3, 1, 2});
  }
  return frames.permute({0, 1, 4, 2, 3})
      .reshape({batch, channels, input_.height, input_.width})
      .to(torch::kFloat32);
}

torch::Tensor OffPolicyAgent::shifted_images(const std::vector<std::uint8_t>& stacks,
                                             std::int64_t batch, std::int64_t pad,
                                             at::Generator& generator,
                                             std::vector<std::uint8_t>& scratch) const {
  const std::int64_t bytes = input_.stack * input_.height * input_.width * input_.channels;
  if (pad == 0) return image_input(view_of(stacks, {batch, bytes}, torch::kUInt8));
  const torch::Tensor shifts = torch::randint(0, 2 * pad + 1, {batch, 2}, generator, torch::kInt64);
  scratch.resize(stacks.size());
  shift_frames(stacks.data(), scratch.data(), batch, input_.stack, input_.height, input_.width,
               input_.channels, pad, shifts.data_ptr<std::int64_t>());
  // image_input copies (to float), so `scratch` may be reused by the next call.
  return image_input(view_of(scratch, {batch, bytes}, torch::kUInt8));
}

torch::Tensor OffPolicyAgent::convolve(const torch::Tensor& images) {
  if (!input_.has_image) return {};
  torch::Tensor x = images / 255.0 - 0.5;
  if (channels_last_) x = x.contiguous(at::MemoryFormat::ChannelsLast);
  torch::Tensor h;
  {
    const CpuAutocast autocast(autocast_);
    h = encoder->forward(x);
  }
  return h.to(torch::kFloat32);
}

AgentInput OffPolicyAgent::observation_input(const ObservationTensors& obs) const {
  AgentInput in;
  if (input_.has_image) {
    const torch::Tensor& stacked = obs.at(input_.image_key);
    const std::int64_t batch = stacked.size(0);
    in.images = image_input(stacked.reshape({batch, -1}).contiguous());
  }
  if (!input_.vector_keys.empty()) {
    std::vector<torch::Tensor> parts;
    for (const std::string& key : input_.vector_keys) {
      const torch::Tensor& value = obs.at(key);
      parts.push_back(value.reshape({value.size(0), -1}).to(torch::kFloat32));
    }
    in.vectors = parts.size() == 1 ? parts[0] : torch::cat(parts, 1);
  }
  return in;
}

torch::Tensor OffPolicyAgent::env_action(const torch::Tensor& unit_actions) const {
  return low_ + (unit_actions + 1.0) * 0.5 * (high_ - low_);
}

torch::Tensor OffPolicyAgent::unit_action(const torch::Tensor& env_actions) const {
  return ((env_actions.to(torch::kFloat32) - low_) / (high_ - low_) * 2.0 - 1.0).clamp(-1.0, 1.0);
}

std::vector<torch::Tensor> parameters_of(std::initializer_list<torch::nn::Module*> modules) {
  std::vector<torch::Tensor> parameters;
  for (torch::nn::Module* module : modules) {
    if (module == nullptr) continue;
    for (auto& parameter : module->parameters()) parameters.push_back(parameter);
  }
  return parameters;
}

torch::Tensor batch_vectors(const std::vector<std::vector<float>>& vectors,
                            const InputLayout& input, std::int64_t batch) {
  if (vectors.empty()) return {};
  std::vector<torch::Tensor> parts;
  for (std::size_t v = 0; v < vectors.size(); ++v) {
    parts.push_back(view_of(vectors[v], {batch, input.vector_sizes[v]}, torch::kFloat32));
  }
  return parts.size() == 1 ? parts[0] : torch::cat(parts, 1);
}

void write_env_actions(const OffPolicyAgent& agent, const torch::Tensor& unit_actions,
                       Value& actions) {
  Array& action = actions.array();
  const torch::Tensor chosen =
      agent.env_action(unit_actions).to(torch_dtype(action.dtype())).contiguous();
  std::memcpy(action.raw_data(), chosen.data_ptr(), action.nbytes());
}

OffPolicyActor::OffPolicyActor(std::shared_ptr<OffPolicyAgent> agent, std::uint64_t seed)
    : agent_(std::move(agent)), generator_(at::detail::createCPUGenerator(seed)) {
  if (!agent_) throw std::invalid_argument("OffPolicyActor: the agent is null");
}

ActCounts OffPolicyActor::act(const Value& observations, bool deterministic, Value& actions) {
  const torch::Tensor unit =
      agent_->act(observation_tensors(observations), deterministic, &generator_);
  write_env_actions(*agent_, unit, actions);
  // The tanh policies' actions lie within the bounds: none is clipped.
  return {0, unit.numel()};
}

nlohmann::json OffPolicyActor::mlp_policy() const {
  const InputLayout& input = agent_->input();
  if (input.has_image) {
    throw std::invalid_argument(
        "expected a policy that reads vectors only, got one that reads "
        "the image \"" +
        input.image_key + "\" (train from state, --set obs_mode=state, to export it)");
  }
  if (input.vector_keys.size() == 1 && input.vector_keys.front().empty()) {
    throw std::invalid_argument(
        "expected a Dict observation (a policy file reads its inputs by "
        "key), got a bare Box");
  }
  const torch::nn::Sequential mlp = agent_->policy_mlp();
  if (!mlp) {
    throw std::invalid_argument(
        "expected a policy that is an MLP over the vectors (drq's), got one with other layers "
        "before its MLP (drqv2's trunk)");
  }
  const auto base64 = [](const torch::Tensor& values) {
    const torch::Tensor floats = values.detach().to(torch::kFloat32).contiguous();
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(floats.numel()) * 4);
    // The file's floats are little-endian, as this machine stores them.
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "policy files are little-endian");
    std::memcpy(bytes.data(), floats.data_ptr<float>(), bytes.size());
    return testing::encode_base64(bytes);
  };
  nlohmann::json policy;
  policy["format"] = "pixelgym mlp policy";
  policy["version"] = 1;
  policy["inputs"] = nlohmann::json::array();
  for (std::size_t k = 0; k < input.vector_keys.size(); ++k) {
    policy["inputs"].push_back({{"key", input.vector_keys[k]}, {"size", input.vector_sizes[k]}});
  }
  nlohmann::json layers = nlohmann::json::array();
  for (const auto& child : mlp->children()) {
    if (const auto* linear = child->as<torch::nn::Linear>()) {
      layers.push_back({{"inputs", linear->weight.size(1)},
                        {"outputs", linear->weight.size(0)},
                        {"activation", "none"},
                        {"weight", base64(linear->weight)},
                        {"bias", base64(linear->bias)}});
    } else if (child->as<torch::nn::ReLU>() != nullptr && !layers.empty() &&
               layers.back()["activation"] == "none") {
      layers.back()["activation"] = "relu";
    } else {
      throw std::invalid_argument(
          "expected an MLP of Linear layers, each followed by at most one ReLU, got a " +
          child->name() + " after " + std::to_string(layers.size()) + " Linear layers");
    }
  }
  policy["layers"] = std::move(layers);
  policy["action"] = {
      {"size", input.action_size}, {"low", input.action_low}, {"high", input.action_high}};
  return policy;
}

}  // namespace pixelgym::trainer
