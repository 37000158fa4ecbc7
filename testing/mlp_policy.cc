#include "pixelgym/testing/mlp_policy.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace pixelgym::testing {
namespace {

using nlohmann::json;

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// The member `name` of `object`, which must be of `type` ("string", "number", ...).
const json& member(const json& object, const std::string& name, json::value_t type,
                   const std::string& where, const std::string& what) {
  if (!object.is_object()) {
    throw std::runtime_error(where + ": expected an object with \"" + name + "\", got " +
                             object.dump().substr(0, 60));
  }
  if (!object.contains(name)) {
    throw std::runtime_error(where + ": expected a member \"" + name + "\" (" + what +
                             "), got none");
  }
  const json& value = object.at(name);
  const bool number = type == json::value_t::number_integer &&
                      (value.is_number_integer() || value.is_number_unsigned());
  if (!number && value.type() != type) {
    throw std::runtime_error(where + ": expected \"" + name + "\" to be " + what + ", got " +
                             value.dump().substr(0, 60));
  }
  return value;
}

// The largest size a file may give (a layer's inputs or outputs, an input's size): far above
// any policy's, and small enough that no product or sum of sizes overflows.
constexpr std::int64_t kMaxSize = std::int64_t{1} << 24;

std::int64_t positive(const json& object, const std::string& name, const std::string& where) {
  const json& value =
      member(object, name, json::value_t::number_integer, where, "a positive integer");
  const bool in_range =
      value.is_number_unsigned()
          ? value.get<std::uint64_t>() >= 1 &&
                value.get<std::uint64_t>() <= static_cast<std::uint64_t>(kMaxSize)
          : value.get<std::int64_t>() >= 1 && value.get<std::int64_t>() <= kMaxSize;
  if (!in_range) {
    throw std::runtime_error(where + ": expected \"" + name + "\" to be an integer from 1 to " +
                             std::to_string(kMaxSize) + ", got " + value.dump());
  }
  return value.get<std::int64_t>();
}

// The float32 values of a base64 member, `count` of them.
std::vector<float> floats(const json& object, const std::string& name, std::int64_t count,
                          const std::string& where) {
  const std::string& text =
      member(object, name, json::value_t::string, where, "base64 of float32 values")
          .get_ref<const std::string&>();
  std::vector<std::uint8_t> bytes;
  try {
    bytes = decode_base64(text);
  } catch (const std::invalid_argument& error) {
    throw std::runtime_error(where + ": \"" + name + "\": " + error.what());
  }
  if (bytes.size() % 4 != 0 || bytes.size() / 4 != static_cast<std::size_t>(count)) {
    throw std::runtime_error(where + ": expected \"" + name + "\" to hold " +
                             std::to_string(count) + " float32 values (" +
                             std::to_string(count * 4) + " bytes), got " +
                             std::to_string(bytes.size()) + " bytes");
  }
  std::vector<float> values(static_cast<std::size_t>(count));
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::uint32_t bits = static_cast<std::uint32_t>(bytes[4 * i]) |
                               static_cast<std::uint32_t>(bytes[4 * i + 1]) << 8 |
                               static_cast<std::uint32_t>(bytes[4 * i + 2]) << 16 |
                               static_cast<std::uint32_t>(bytes[4 * i + 3]) << 24;
    std::memcpy(&values[i], &bits, 4);
    if (!std::isfinite(values[i])) {
      throw std::runtime_error(where + ": \"" + name + "\" value " + std::to_string(i) +
                               " is not finite");
    }
  }
  return values;
}

std::vector<float> bounds(const json& action, const std::string& name, std::int64_t size,
                          const std::string& where) {
  const json& values = member(action, name, json::value_t::array, where, "an array of numbers");
  if (static_cast<std::int64_t>(values.size()) != size ||
      !std::all_of(values.begin(), values.end(), [](const json& v) { return v.is_number(); })) {
    throw std::runtime_error(where + ": expected \"" + name + "\" to hold " + std::to_string(size) +
                             " numbers (the action's size), got " + values.dump().substr(0, 60));
  }
  std::vector<float> result;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double value = values[i].get<double>();
    if (!(std::abs(value) <= std::numeric_limits<float>::max())) {  // NaN too
      throw std::runtime_error(where + ": expected \"" + name + "\" value " + std::to_string(i) +
                               " to be a finite float32, got " + values[i].dump());
    }
    result.push_back(static_cast<float>(value));
  }
  return result;
}

Param param_of(const json& value, const std::string& name, const std::string& where) {
  if (value.is_boolean()) return value.get<bool>();
  if (value.is_number_integer() || value.is_number_unsigned()) return value.get<std::int64_t>();
  if (value.is_number_float()) return value.get<double>();
  if (value.is_string()) return value.get<std::string>();
  throw std::runtime_error(where + ": expected env_kwargs \"" + name +
                           "\" to be a bool, number or string, got " + value.dump());
}

}  // namespace

std::string encode_base64(const std::vector<std::uint8_t>& bytes) {
  std::string text;
  text.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t left = bytes.size() - i;
    const std::uint32_t block = static_cast<std::uint32_t>(bytes[i]) << 16 |
                                (left > 1 ? static_cast<std::uint32_t>(bytes[i + 1]) << 8 : 0) |
                                (left > 2 ? static_cast<std::uint32_t>(bytes[i + 2]) : 0);
    text += kAlphabet[block >> 18 & 63];
    text += kAlphabet[block >> 12 & 63];
    text += left > 1 ? kAlphabet[block >> 6 & 63] : '=';
    text += left > 2 ? kAlphabet[block & 63] : '=';
  }
  return text;
}

std::vector<std::uint8_t> decode_base64(const std::string& text) {
  std::array<int, 256> value;
  value.fill(-1);
  for (int i = 0; i < 64; ++i) value[static_cast<unsigned char>(kAlphabet[i])] = i;
  if (text.size() % 4 != 0) {
    throw std::invalid_argument("expected base64 in blocks of 4 characters, got " +
                                std::to_string(text.size()) + " characters");
  }
  std::vector<std::uint8_t> bytes;
  bytes.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    std::uint32_t block = 0;
    int padding = 0;
    for (std::size_t j = 0; j < 4; ++j) {
      const char c = text[i + j];
      const bool last_block = i + 4 == text.size();
      if (c == '=' && last_block && j >= 2 && (j == 3 || text[i + 3] == '=')) {
        ++padding;
        block <<= 6;
        continue;
      }
      const int v = value[static_cast<unsigned char>(c)];
      if (v < 0) {
        throw std::invalid_argument("expected base64, got '" + std::string(1, c) +
                                    "' at character " + std::to_string(i + j));
      }
      block = block << 6 | static_cast<std::uint32_t>(v);
    }
    bytes.push_back(static_cast<std::uint8_t>(block >> 16));
    if (padding < 2) bytes.push_back(static_cast<std::uint8_t>(block >> 8 & 255));
    if (padding < 1) bytes.push_back(static_cast<std::uint8_t>(block & 255));
  }
  return bytes;
}

MlpPolicy MlpPolicy::load(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("MLP policy " + path + ": cannot be opened for reading");
  std::stringstream text;
  text << file.rdbuf();
  return parse(text.str(), path);
}

MlpPolicy MlpPolicy::parse(const std::string& text, const std::string& path) {
  const std::string where = "MLP policy " + path;
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& error) {
    throw std::runtime_error(where + ": expected JSON, got text that is not (" + error.what() +
                             ")");
  }
  const std::string format =
      member(root, "format", json::value_t::string, where, "\"pixelgym mlp policy\"")
          .get<std::string>();
  if (format != "pixelgym mlp policy") {
    throw std::runtime_error(where + ": expected format \"pixelgym mlp policy\", got \"" + format +
                             "\"");
  }
  const std::int64_t version = positive(root, "version", where);
  if (version != 1) {
    throw std::runtime_error(where + ": expected version 1 (what this pixelgym reads), got " +
                             std::to_string(version));
  }
  MlpPolicy policy;
  policy.path_ = path;
  policy.env_id_ =
      member(root, "env_id", json::value_t::string, where, "an env id").get<std::string>();
  for (const auto& [name, value] :
       member(root, "env_kwargs", json::value_t::object, where, "an object").items()) {
    policy.env_kwargs_.emplace(name, param_of(value, name, where));
  }
  std::int64_t width = 0;
  const json& inputs =
      member(root, "inputs", json::value_t::array, where, "an array of {key, size}");
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const std::string at = where + ": input " + std::to_string(i);
    Input in{member(inputs[i], "key", json::value_t::string, at, "an observation key")
                 .get<std::string>(),
             positive(inputs[i], "size", at)};
    for (const Input& earlier : policy.inputs_) {
      if (earlier.key == in.key) {
        throw std::runtime_error(at + ": expected each key once, got \"" + in.key + "\" again");
      }
    }
    width += in.size;
    if (width > kMaxSize) {
      throw std::runtime_error(at + ": expected the inputs' sizes to add up to at most " +
                               std::to_string(kMaxSize) + ", got more");
    }
    policy.inputs_.push_back(std::move(in));
  }
  if (policy.inputs_.empty()) throw std::runtime_error(where + ": expected inputs, got none");
  const json& layers = member(root, "layers", json::value_t::array, where, "an array of layers");
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const std::string at = where + ": layer " + std::to_string(i);
    Layer layer;
    layer.inputs = positive(layers[i], "inputs", at);
    layer.outputs = positive(layers[i], "outputs", at);
    if (layer.inputs != width) {
      throw std::runtime_error(
          at + ": expected " + std::to_string(width) + " inputs (" +
          (i == 0 ? "the inputs' sizes together" : "the layer before's outputs") + "), got " +
          std::to_string(layer.inputs));
    }
    const std::string activation =
        member(layers[i], "activation", json::value_t::string, at, "\"relu\" or \"none\"")
            .get<std::string>();
    if (activation != "relu" && activation != "none") {
      throw std::runtime_error(at + ": expected activation \"relu\" or \"none\", got \"" +
                               activation + "\"");
    }
    layer.relu = activation == "relu";
    layer.weight = floats(layers[i], "weight", layer.inputs * layer.outputs, at);
    layer.bias = floats(layers[i], "bias", layer.outputs, at);
    width = layer.outputs;
    policy.layers_.push_back(std::move(layer));
  }
  if (policy.layers_.empty()) throw std::runtime_error(where + ": expected layers, got none");
  const json& action = member(root, "action", json::value_t::object, where, "{size, low, high}");
  policy.action_size_ = positive(action, "size", where + ": action");
  if (policy.action_size_ > width) {
    throw std::runtime_error(where + ": expected an action of at most the last layer's " +
                             std::to_string(width) + " outputs, got size " +
                             std::to_string(policy.action_size_));
  }
  policy.low_ = bounds(action, "low", policy.action_size_, where + ": action");
  policy.high_ = bounds(action, "high", policy.action_size_, where + ": action");
  for (std::size_t a = 0; a < policy.low_.size(); ++a) {
    if (!(policy.low_[a] <= policy.high_[a])) {
      throw std::runtime_error(
          where + ": action: expected \"low\" <= \"high\", got " + std::to_string(policy.low_[a]) +
          " > " + std::to_string(policy.high_[a]) + " at element " + std::to_string(a));
    }
  }
  return policy;
}

Array MlpPolicy::act(const Value& observation) const {
  if (!observation.is_dict()) {
    throw std::invalid_argument("MLP policy " + path_ +
                                ": expected a Dict observation holding its inputs, got another "
                                "kind of value");
  }
  std::vector<double> x;
  for (const Input& input : inputs_) {
    if (!observation.dict().contains(input.key)) {
      throw std::invalid_argument("MLP policy " + path_ + ": expected the observation key \"" +
                                  input.key + "\", which it does not have");
    }
    const Value& value = observation.dict().at(input.key);
    if (!value.is_array()) {
      throw std::invalid_argument("MLP policy " + path_ + ": expected \"" + input.key +
                                  "\" to be an array, got another kind of value");
    }
    const Array& array = value.array();
    if (!is_floating(array.dtype()) || array.size() != input.size) {
      throw std::invalid_argument("MLP policy " + path_ + ": expected \"" + input.key + "\" of " +
                                  std::to_string(input.size) + " floating elements, got " +
                                  std::to_string(array.size()) + " " + dtype_name(array.dtype()));
    }
    for (std::int64_t i = 0; i < array.size(); ++i) x.push_back(array.element_as_double(i));
  }
  std::vector<double> y;
  for (const Layer& layer : layers_) {
    y.assign(static_cast<std::size_t>(layer.outputs), 0.0);
    for (std::int64_t o = 0; o < layer.outputs; ++o) {
      const float* row = layer.weight.data() + o * layer.inputs;
      double sum = layer.bias[static_cast<std::size_t>(o)];
      for (std::int64_t i = 0; i < layer.inputs; ++i)
        sum += row[i] * x[static_cast<std::size_t>(i)];
      y[static_cast<std::size_t>(o)] = layer.relu ? std::max(sum, 0.0) : sum;
    }
    x.swap(y);
  }
  std::vector<float> action(static_cast<std::size_t>(action_size_));
  for (std::size_t a = 0; a < action.size(); ++a) {
    if (std::isnan(x[a])) {
      throw std::runtime_error("MLP policy " + path_ +
                               ": the action is not a number (the layers' sums overflowed)");
    }
    const double unit = std::tanh(x[a]);
    action[a] = static_cast<float>(low_[a] + (unit + 1.0) * 0.5 * (high_[a] - low_[a]));
  }
  return Array::from_vector({action_size_}, action);
}

}  // namespace pixelgym::testing
