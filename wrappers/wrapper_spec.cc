#include "pixelgym/wrappers/wrapper_spec.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <optional>
#include <stdexcept>

#include "pixelgym/envs/described_env.h"
#include "pixelgym/envs/suggestions.h"
#include "pixelgym/envs/time_limit.h"
#include "pixelgym/wrappers/add_render_observation.h"
#include "pixelgym/wrappers/channel_first_observation.h"
#include "pixelgym/wrappers/clip_action.h"
#include "pixelgym/wrappers/dtype_observation.h"
#include "pixelgym/wrappers/filter_observation.h"
#include "pixelgym/wrappers/frame_stack_observation.h"
#include "pixelgym/wrappers/grayscale_observation.h"
#include "pixelgym/wrappers/normalize_observation.h"
#include "pixelgym/wrappers/normalize_reward.h"
#include "pixelgym/wrappers/record_episode_statistics.h"
#include "pixelgym/wrappers/rescale_action.h"
#include "pixelgym/wrappers/resize_observation.h"

namespace pixelgym::wrappers {
namespace {

// What a parameter's value must look like; `expected()` says it in messages.
enum class Kind { kInteger, kNumber, kBool, kText, kSize, kKeys };

struct Param {
  std::string name;
  Kind kind;
  /// Its value when absent ("pixels", "false"), "<name>" for an optional parameter whose absence
  /// means something else (no key: a bare Box), or empty for a required parameter.
  std::string default_text;
  bool required() const { return default_text.empty(); }
};

std::string expected(Kind kind) {
  switch (kind) {
    case Kind::kInteger:
      return "a whole number";
    case Kind::kNumber:
      return "a finite number";
    case Kind::kBool:
      return "true or false";
    case Kind::kText:
      return "a non-empty word";
    case Kind::kSize:
      return "HEIGHTxWIDTH (e.g. 64x64) or N for NxN";
    case Kind::kKeys:
      return "observation keys joined by '+' (e.g. pixels+joint_pos)";
  }
  return "";
}

class Arguments;
using Builder = std::function<std::unique_ptr<Env>(std::unique_ptr<Env>, const Arguments&)>;

struct Entry {
  std::string name;
  std::string summary;
  std::vector<Param> params;
  Builder build;
};

std::string quoted(const std::string& text) { return "\"" + text + "\""; }

std::string prefix(const WrapperSpec& spec) { return "wrapper spec " + quoted(spec.text) + ": "; }

// The arguments of one spec, typed on demand; each accessor throws std::invalid_argument naming
// the spec, the wrapper, the parameter, what it expected and what it got.
class Arguments {
 public:
  Arguments(const WrapperSpec& spec, const Entry& entry) : spec_(spec), entry_(entry) {}

  std::optional<std::string> text(const std::string& name) const {
    for (const auto& [key, value] : spec_.arguments) {
      if (key == name) return value;
    }
    return std::nullopt;
  }

  std::string word(const std::string& name, const std::string& fallback) const {
    const auto value = text(name);
    if (!value) return fallback;
    if (value->empty()) fail(name, Kind::kText, *value);
    return *value;
  }

  std::int64_t integer(const std::string& name, std::int64_t fallback) const {
    const auto value = text(name);
    if (!value) return fallback;
    std::int64_t result = 0;
    if (!parse_integer(*value, result)) fail(name, Kind::kInteger, *value);
    return result;
  }

  double number(const std::string& name, double fallback) const {
    const auto value = text(name);
    if (!value) return fallback;
    double result = 0.0;
    if (!parse_number(*value, result)) fail(name, Kind::kNumber, *value);
    return result;
  }

  bool boolean(const std::string& name, bool fallback) const {
    const auto value = text(name);
    if (!value) return fallback;
    if (*value == "true" || *value == "1" || *value == "yes") return true;
    if (*value == "false" || *value == "0" || *value == "no") return false;
    fail(name, Kind::kBool, *value);
  }

  ImageSize size(const std::string& name) const {
    const std::string value = text(name).value_or("");
    const std::size_t x = value.find('x');
    ImageSize size;
    const bool ok = x == std::string::npos
                        ? parse_integer(value, size.height) && (size.width = size.height, true)
                        : parse_integer(value.substr(0, x), size.height) &&
                              parse_integer(value.substr(x + 1), size.width);
    if (!ok) fail(name, Kind::kSize, value);
    return size;
  }

  std::vector<std::string> keys(const std::string& name) const {
    const std::string value = text(name).value_or("");
    std::vector<std::string> keys;
    std::size_t begin = 0;
    while (true) {
      const std::size_t end = value.find('+', begin);
      keys.push_back(value.substr(begin, end - begin));
      if (keys.back().empty()) fail(name, Kind::kKeys, value);
      if (end == std::string::npos) break;
      begin = end + 1;
    }
    return keys;
  }

  /// One of `choices`, or `fallback` when absent.
  std::string choice(const std::string& name, const std::vector<std::string>& choices,
                     const std::string& fallback) const {
    const auto value = text(name);
    if (!value) return fallback;
    if (std::find(choices.begin(), choices.end(), *value) != choices.end()) return *value;
    std::string list;
    for (const std::string& option : choices) list += (list.empty() ? "" : " | ") + option;
    throw std::invalid_argument(prefix(spec_) + entry_.name + "'s " + name + ": expected " + list +
                                ", got " + quoted(*value));
  }

 private:
  template <typename T>
  static bool parse_integer(const std::string& text, T& value) {
    const char* end = text.data() + text.size();
    const auto [stop, error] = std::from_chars(text.data(), end, value);
    return !text.empty() && error == std::errc() && stop == end;
  }

  static bool parse_number(const std::string& text, double& value) {
    if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
    char* end = nullptr;
    errno = 0;
    value = std::strtod(text.c_str(), &end);
    return errno == 0 && end == text.c_str() + text.size() && std::isfinite(value);
  }

  [[noreturn]] void fail(const std::string& name, Kind kind, const std::string& value) const {
    throw std::invalid_argument(prefix(spec_) + entry_.name + "'s " + name + ": expected " +
                                expected(kind) + ", got " + quoted(value));
  }

  const WrapperSpec& spec_;
  const Entry& entry_;
};

const Param key_param{"key", Kind::kText, "pixels"};

const std::vector<Entry>& entries() {
  static const std::vector<Entry> table = {
      {"resize",
       "ResizeObservation: resize the image (OpenCV INTER_AREA down, linear up)",
       {{"size", Kind::kSize, ""}, key_param},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<ResizeObservation>(std::move(env), args.size("size"),
                                                    args.word("key", "pixels"));
       }},
      {"grayscale",
       "GrayscaleObservation: RGB to gray (ITU-R 601), (H, W) or with keep_dim (H, W, 1)",
       {{"keep_dim", Kind::kBool, "false"}, key_param},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<GrayscaleObservation>(
             std::move(env), args.boolean("keep_dim", false), args.word("key", "pixels"));
       }},
      {"channel_first",
       "ChannelFirstObservation: (H, W, C) to (C, H, W) for CNNs",
       {key_param},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<ChannelFirstObservation>(std::move(env),
                                                          args.word("key", "pixels"));
       }},
      {"frame_stack",
       "FrameStackObservation: the last N frames (padding: the reset frame or zeros), sharing "
       "memory between steps",
       {{"stack_size", Kind::kInteger, ""},
        {"padding", Kind::kText, "reset"},
        key_param,
        {"layout", Kind::kText, "new_axis"}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         const std::string padding = args.choice("padding", {"reset", "zero"}, "reset");
         const std::string layout =
             args.choice("layout", {"new_axis", "channels_first", "channels_last"}, "new_axis");
         return std::make_unique<FrameStackObservation>(
             std::move(env), args.integer("stack_size", 0),
             padding == "zero" ? FrameStackPadding::kZero : FrameStackPadding::kReset,
             args.word("key", "pixels"),
             layout == "channels_first"  ? FrameStackLayout::kChannelsFirst
             : layout == "channels_last" ? FrameStackLayout::kChannelsLast
                                         : FrameStackLayout::kNewAxis);
       }},
      {"clip_action",
       "ClipAction: clip Box actions into the bounds (the action space becomes unbounded)",
       {},
       [](std::unique_ptr<Env> env, const Arguments&) -> std::unique_ptr<Env> {
         return std::make_unique<ClipAction>(std::move(env));
       }},
      {"rescale_action",
       "RescaleAction: Box actions in [min, max] mapped onto the env's bounds",
       {{"min", Kind::kNumber, ""}, {"max", Kind::kNumber, ""}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<RescaleAction>(std::move(env), args.number("min", 0.0),
                                                args.number("max", 0.0));
       }},
      {"normalize_observation",
       "NormalizeObservation: running mean and variance, float32 out (a Dict needs the key)",
       {{"key", Kind::kText, "<key>"}, {"epsilon", Kind::kNumber, "1e-8"}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<NormalizeObservation>(std::move(env), args.word("key", ""),
                                                       args.number("epsilon", 1e-8));
       }},
      {"normalize_reward",
       "NormalizeReward: rewards over the running deviation of the discounted return",
       {{"gamma", Kind::kNumber, "0.99"}, {"epsilon", Kind::kNumber, "1e-8"}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<NormalizeReward>(std::move(env), args.number("gamma", 0.99),
                                                  args.number("epsilon", 1e-8));
       }},
      {"record_episode_statistics",
       "RecordEpisodeStatistics: info[\"episode\"] = {r, l, t} at each episode's end",
       {{"buffer_length", Kind::kInteger, "100"}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<RecordEpisodeStatistics>(std::move(env),
                                                          args.integer("buffer_length", 100));
       }},
      {"add_render_observation",
       "AddRenderObservation: render() frames added to the observation under a key",
       {{"render_key", Kind::kText, "pixels"},
        {"render_only", Kind::kBool, "false"},
        {"obs_key", Kind::kText, "state"}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<AddRenderObservation>(
             std::move(env), args.boolean("render_only", false), args.word("render_key", "pixels"),
             args.word("obs_key", "state"));
       }},
      {"filter_observation",
       "FilterObservation: keep only these Dict keys, in this order",
       {{"keys", Kind::kKeys, ""}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<FilterObservation>(std::move(env), args.keys("keys"));
       }},
      {"dtype_observation",
       "DtypeObservation: cast a Box observation (or one Dict key) to another dtype",
       {{"dtype", Kind::kText, ""}, {"key", Kind::kText, "<key>"}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         const std::vector<std::string> names = {"bool",  "uint8",   "int32",
                                                 "int64", "float32", "float64"};
         const std::string name = args.choice("dtype", names, "");
         const auto index = std::find(names.begin(), names.end(), name) - names.begin();
         return std::make_unique<DtypeObservation>(std::move(env), static_cast<DType>(index),
                                                   args.word("key", ""));
       }},
      {"time_limit",
       "TimeLimit: truncate episodes after N steps",
       {{"max_episode_steps", Kind::kInteger, ""}},
       [](std::unique_ptr<Env> env, const Arguments& args) -> std::unique_ptr<Env> {
         return std::make_unique<TimeLimit>(std::move(env), args.integer("max_episode_steps", 0));
       }},
  };
  return table;
}

// Other names of wrappers (alias, wrapper): the words the docs use for them ("grey", "channels
// first"), so that a spec written as the docs read works.
const std::vector<std::pair<std::string, std::string>>& aliases() {
  static const std::vector<std::pair<std::string, std::string>> table = {
      {"greyscale", "grayscale"},
      {"grey", "grayscale"},
      {"gray", "grayscale"},
      {"channels_first", "channel_first"},
  };
  return table;
}

const Entry& find_entry(const std::string& name, const std::string& text) {
  std::string wanted = name;
  for (const auto& [alias, wrapper] : aliases()) {
    if (alias == name) wanted = wrapper;
  }
  const auto& table = entries();
  const auto found =
      std::find_if(table.begin(), table.end(), [&](const Entry& e) { return e.name == wanted; });
  if (found != table.end()) return *found;
  std::vector<std::string> names;
  for (const Entry& entry : table) names.push_back(entry.name);
  // The closest of the names and aliases, one per wrapper ("grayscal": grayscale, not greyscale
  // too).
  std::vector<std::string> known = names;
  for (const auto& [alias, wrapper] : aliases()) known.push_back(alias);
  std::vector<std::string> closest;
  std::vector<std::string> suggested;
  for (const std::string& candidate : closest_names(name, known)) {
    std::string wrapper = candidate;
    for (const auto& [alias, aliased] : aliases()) {
      if (alias == candidate) wrapper = aliased;
    }
    if (std::find(suggested.begin(), suggested.end(), wrapper) != suggested.end()) continue;
    suggested.push_back(wrapper);
    closest.push_back(candidate);
  }
  const std::string suggestion = did_you_mean(name, closest);
  // Each wrapper with the other words it takes, so that a suggested alias is in the list.
  for (std::string& listed : names) {
    std::string also;
    for (const auto& [alias, wrapper] : aliases()) {
      if (wrapper == listed) also += (also.empty() ? "" : ", ") + alias;
    }
    if (!also.empty()) listed += " (also " + also + ")";
  }
  throw std::invalid_argument("wrapper spec " + quoted(text) + ": unknown wrapper " + quoted(name) +
                              "; " + (suggestion.empty() ? "" : suggestion + " ") +
                              "the wrappers are: " + join_names(names));
}

std::vector<std::string> parameter_names(const Entry& entry) {
  std::vector<std::string> names;
  for (const Param& param : entry.params) names.push_back(param.name);
  return names;
}

std::string param_names(const Entry& entry) {
  if (entry.params.empty()) return entry.name + " takes no arguments";
  return entry.name + "'s parameters are: " + join_names(parameter_names(entry));
}

// "resize=HxW[,key=pixels]": the form of a spec, for messages and help.
std::string usage(const Entry& entry) {
  std::string usage = entry.name;
  bool first = true;
  for (const Param& param : entry.params) {
    const std::string separator = first ? "=" : ",";
    if (param.required()) {
      usage += separator + (param.kind == Kind::kSize ? "HxW" : "<" + param.name + ">");
    } else {
      usage += "[" + separator + param.name + "=" + param.default_text + "]";
    }
    first = false;
  }
  return usage;
}

}  // namespace

WrapperSpec parse_wrapper_spec(const std::string& text) {
  WrapperSpec spec;
  spec.text = text;
  const std::size_t equals = text.find('=');
  spec.name = text.substr(0, equals);
  if (spec.name.empty()) {
    throw std::invalid_argument("wrapper spec " + quoted(text) +
                                ": expected NAME or NAME=ARGS (e.g. resize=64x64), got no name");
  }
  if (const std::size_t comma = spec.name.find(','); comma != std::string::npos) {
    throw std::invalid_argument(prefix(spec) + "expected NAME=ARGS with '=' after the name (e.g. " +
                                spec.name.substr(0, comma) + "=" + text.substr(comma + 1) +
                                "), got a ',' in the name " + quoted(spec.name));
  }
  const Entry& entry = find_entry(spec.name, text);
  spec.name = entry.name;  // an alias ("greyscale") as the wrapper it names
  if (equals == std::string::npos) {
    // No arguments: fine unless a parameter is required (checked below).
  } else {
    const std::string rest = text.substr(equals + 1);
    std::size_t next_positional = 0;
    std::size_t begin = 0;
    while (true) {
      const std::size_t end = rest.find(',', begin);
      const std::string item = rest.substr(begin, end - begin);
      if (item.empty()) {
        throw std::invalid_argument(prefix(spec) + "expected comma-separated arguments (" +
                                    param_names(entry) + "), got an empty one");
      }
      std::string name;
      std::string value;
      const std::size_t item_equals = item.find('=');
      const auto param_named = [&](const std::string& n) {
        return std::find_if(entry.params.begin(), entry.params.end(),
                            [&](const Param& p) { return p.name == n; });
      };
      if (item_equals != std::string::npos) {
        name = item.substr(0, item_equals);
        value = item.substr(item_equals + 1);
        if (param_named(name) == entry.params.end()) {
          const std::string suggestion = did_you_mean(name, parameter_names(entry));
          throw std::invalid_argument(prefix(spec) + "unknown parameter " + quoted(name) + "; " +
                                      (suggestion.empty() ? "" : suggestion + " ") +
                                      param_names(entry));
        }
      } else if (const auto flag = param_named(item);
                 flag != entry.params.end() && flag->kind == Kind::kBool) {
        name = item;
        value = "true";
      } else {
        if (next_positional >= entry.params.size()) {
          throw std::invalid_argument(prefix(spec) + "too many values: " + param_names(entry) +
                                      ", got " + quoted(item) + " after them");
        }
        // "resize=64,48": a second number where the size's form is HEIGHTxWIDTH, not a key.
        if (next_positional > 0 && entry.params[next_positional - 1].kind == Kind::kSize &&
            entry.params[next_positional].kind == Kind::kText &&
            item.find_first_not_of("0123456789") == std::string::npos) {
          const std::string size = spec.arguments.empty() ? "" : spec.arguments.back().second;
          throw std::invalid_argument(prefix(spec) + entry.name + "'s " +
                                      entry.params[next_positional - 1].name + ": expected " +
                                      expected(Kind::kSize) + ", as " + entry.name + "=" + size +
                                      "x" + item + " for " + size + " high and " + item +
                                      " wide; got " + quoted(size + "," + item));
        }
        name = entry.params[next_positional].name;
        value = item;
      }
      const bool repeated = std::any_of(
          spec.arguments.begin(), spec.arguments.end(),
          [&](const std::pair<std::string, std::string>& a) { return a.first == name; });
      if (repeated) {
        throw std::invalid_argument(prefix(spec) + "parameter " + quoted(name) + " given twice");
      }
      spec.arguments.emplace_back(name, value);
      // Bare values fill the parameters after the last one named or filled.
      const auto position = param_named(name) - entry.params.begin();
      next_positional = std::max(next_positional, static_cast<std::size_t>(position) + 1);
      if (end == std::string::npos) break;
      begin = end + 1;
    }
  }
  for (const Param& param : entry.params) {
    const bool given = std::any_of(
        spec.arguments.begin(), spec.arguments.end(),
        [&](const std::pair<std::string, std::string>& a) { return a.first == param.name; });
    if (param.required() && !given) {
      throw std::invalid_argument(prefix(spec) + entry.name + " needs its " + param.name + " (" +
                                  expected(param.kind) + "): " + usage(entry));
    }
  }
  return spec;
}

std::unique_ptr<Env> apply_wrapper(std::unique_ptr<Env> env, const WrapperSpec& spec) {
  const Entry& entry = find_entry(spec.name, spec.text);
  const Arguments arguments(spec, entry);
  try {
    return entry.build(std::move(env), arguments);
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    if (message.rfind("wrapper spec ", 0) == 0) throw;  // already names the spec
    throw std::invalid_argument(prefix(spec) + message);
  }
}

std::unique_ptr<Env> apply_wrappers(std::unique_ptr<Env> env,
                                    const std::vector<std::string>& specs) {
  for (const std::string& text : specs)
    env = apply_wrapper(std::move(env), parse_wrapper_spec(text));
  return env;
}

EnvWrapping wrapping(const std::vector<std::string>& specs) {
  std::vector<WrapperSpec> parsed;
  parsed.reserve(specs.size());
  for (const std::string& text : specs) parsed.push_back(parse_wrapper_spec(text));
  if (parsed.empty()) return nullptr;
  return [parsed](std::unique_ptr<Env> env) {
    for (const WrapperSpec& spec : parsed) env = apply_wrapper(std::move(env), spec);
    return env;
  };
}

EnvDescription describe_wrapped(EnvDescription description, const std::vector<std::string>& specs) {
  std::unique_ptr<Env> env = std::make_unique<DescribedEnv>(description);
  for (const std::string& text : specs) {
    const WrapperSpec spec = parse_wrapper_spec(text);
    env = apply_wrapper(std::move(env), spec);
    if (spec.name == "time_limit") {
      const auto* limit = dynamic_cast<const TimeLimit*>(env.get());
      if (limit != nullptr && (!description.max_episode_steps ||
                               limit->max_episode_steps() < *description.max_episode_steps)) {
        description.max_episode_steps = limit->max_episode_steps();
      }
    }
  }
  // Spaces are shared pointers owned by the wrappers: copy the outermost ones out by aliasing
  // the wrapper stack, which stays alive as long as the description's spaces do.
  const std::shared_ptr<Env> stack(std::move(env));
  description.observation_space = SpacePtr(stack, &stack->observation_space());
  description.action_space = SpacePtr(stack, &stack->action_space());
  description.metadata = stack->metadata();
  return description;
}

std::vector<WrapperSpecHelp> wrapper_spec_help() {
  std::vector<WrapperSpecHelp> help;
  for (const Entry& entry : entries()) {
    help.push_back({entry.name, usage(entry), entry.summary, {}});
    for (const auto& [alias, wrapper] : aliases()) {
      if (wrapper == entry.name) help.back().aliases.push_back(alias);
    }
  }
  return help;
}

}  // namespace pixelgym::wrappers
