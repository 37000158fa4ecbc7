#include "pixelgym/envs/registry.h"

#include <algorithm>
#include <cctype>
#include <regex>
#include <stdexcept>

#include "pixelgym/envs/suggestions.h"
#include "pixelgym/envs/time_limit.h"

namespace pixelgym {
namespace {

constexpr const char* kMaxEpisodeStepsKey = "max_episode_steps";

// `ids` (sorted) with the versions of each name newest first, so that a suggestion among ids
// equally close names CartPoleSwingup-v1 before -v0.
std::vector<std::string> newest_versions_first(std::vector<std::string> ids) {
  const auto split = [](const std::string& id) -> std::pair<std::string, long> {
    const std::size_t at = id.rfind("-v");
    if (at == std::string::npos || at + 2 == id.size() ||
        id.find_first_not_of("0123456789", at + 2) != std::string::npos) {
      return {id, 0};
    }
    return {id.substr(0, at), std::stol(id.substr(at + 2))};
  };
  std::stable_sort(ids.begin(), ids.end(), [&](const std::string& a, const std::string& b) {
    const auto [name_a, version_a] = split(a);
    const auto [name_b, version_b] = split(b);
    return name_a != name_b ? name_a < name_b : version_a > version_b;
  });
  return ids;
}

// Gymnasium's make takes render_mode; here every env renders off-screen into "rgb_array" frames,
// its only mode. "rgb_array" is accepted (and dropped) unless the env declares a render_mode
// kwarg of its own; any other mode ("human": a window) is refused naming the one offered.
Params without_render_mode(const EnvSpec& spec, const Params& kwargs, const std::string& id) {
  const auto found = kwargs.find("render_mode");
  const bool declared = std::any_of(spec.params.begin(), spec.params.end(),
                                    [](const ParamSpec& p) { return p.name == "render_mode"; });
  if (found == kwargs.end() || declared) return kwargs;
  if (found->second.type() != ParamType::kString || found->second.as_string() != "rgb_array") {
    throw std::invalid_argument(
        id +
        ": render_mode must be \"rgb_array\", the only render mode (pixelgym renders "
        "off-screen, headless: render() returns (H, W, 3) uint8 frames), got " +
        found->second.to_string() +
        "; to watch episodes, record a video (`pixelgym record`, wrappers::RecordVideo)");
  }
  Params rest = kwargs;
  rest.erase("render_mode");
  return rest;
}

}  // namespace

void Registry::register_env(EnvSpec spec) {
  // Gymnasium's ids allow hyphens in the name (a variant: CartPoleSwingup-distracting-v1).
  static const std::regex kIdPattern("[A-Za-z][A-Za-z0-9_]*(-[A-Za-z][A-Za-z0-9_]*)*-v[0-9]+");
  if (!std::regex_match(spec.id, kIdPattern)) {
    throw std::invalid_argument("register_env: id \"" + spec.id +
                                "\" is not of the form Name-vN (e.g. CartPoleSwingup-v0, or "
                                "CartPoleSwingup-distracting-v1 for a variant)");
  }
  if (!spec.factory) throw std::invalid_argument("register_env: " + spec.id + " has no factory");
  for (const ParamSpec& param : spec.params) {
    if (param.name == kMaxEpisodeStepsKey) {
      throw std::invalid_argument("register_env: " + spec.id +
                                  ": the kwarg name max_episode_steps is reserved for make()");
    }
  }
  if (spec.max_episode_steps && *spec.max_episode_steps <= 0) {
    throw std::invalid_argument("register_env: " + spec.id +
                                ": max_episode_steps must be positive");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& existing : specs_) {
    if (existing->id == spec.id) {
      throw std::invalid_argument("register_env: " + spec.id + " is already registered");
    }
  }
  specs_.push_back(std::make_shared<const EnvSpec>(std::move(spec)));
}

std::shared_ptr<const EnvSpec> Registry::spec(const std::string& id) const {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& spec : specs_) {
      if (spec->id == id) return spec;
    }
  }
  std::string message = "unknown env id \"" + id + "\"";
  const std::vector<std::string> all = registered_ids();
  const std::string suggestion = did_you_mean(id, newest_versions_first(all));
  if (all.empty()) {
    message += "; no envs are registered";
  } else if (!suggestion.empty()) {
    message +=
        "; " + suggestion + " (`pixelgym list` shows all " + std::to_string(all.size()) + ")";
  } else {
    message += "; registered ids: " + join_names(all);
  }
  throw std::invalid_argument(message);
}

Registry::Resolved Registry::resolve(const std::string& id, const Params& kwargs) const {
  Resolved out;
  out.spec = spec(id);
  std::vector<ParamSpec> accepted = out.spec->params;
  accepted.push_back({kMaxEpisodeStepsKey,
                      Param(out.spec->max_episode_steps ? *out.spec->max_episode_steps : 0),
                      "steps before TimeLimit truncates the episode; 0 for no limit"});
  out.kwargs = resolve_params(accepted, without_render_mode(*out.spec, kwargs, id), id);
  const std::int64_t max_episode_steps = out.kwargs.at(kMaxEpisodeStepsKey).as_int();
  if (max_episode_steps < 0) {
    throw std::invalid_argument(id +
                                ": kwarg \"max_episode_steps\" must be >= 0 (0: no limit), got " +
                                std::to_string(max_episode_steps));
  }
  out.kwargs.erase(kMaxEpisodeStepsKey);
  if (kwargs.count(kMaxEpisodeStepsKey) != 0) {
    out.max_episode_steps = max_episode_steps;  // the caller's choice wins
  } else if (out.spec->describe) {
    const std::optional<std::int64_t> limit = out.spec->describe(out.kwargs).max_episode_steps;
    out.max_episode_steps = limit.value_or(0);
  } else {
    out.max_episode_steps = max_episode_steps;
  }
  return out;
}

EnvDescription Registry::describe(const std::string& id, const Params& kwargs) const {
  const Resolved resolved = resolve(id, kwargs);
  EnvDescription description;
  if (resolved.spec->describe) {
    description = resolved.spec->describe(resolved.kwargs);
  } else {
    // No describe: build the env and keep it alive behind its spaces (aliasing pointers).
    std::shared_ptr<Env> env = resolved.spec->factory(resolved.kwargs, MakeOptions{});
    if (env == nullptr) throw std::runtime_error(id + ": the registered factory returned null");
    description.observation_space = SpacePtr(env, &env->observation_space());
    description.action_space = SpacePtr(env, &env->action_space());
    description.metadata = env->metadata();
  }
  description.max_episode_steps.reset();
  if (resolved.max_episode_steps > 0) description.max_episode_steps = resolved.max_episode_steps;
  return description;
}

std::unique_ptr<Env> Registry::make(const std::string& id, const Params& kwargs,
                                    const MakeOptions& options) const {
  const Resolved resolved = resolve(id, kwargs);
  std::unique_ptr<Env> env = resolved.spec->factory(resolved.kwargs, options);
  if (env == nullptr) throw std::runtime_error(id + ": the registered factory returned null");
  // The made env's spec says what it was made with (as gymnasium's env.spec does).
  auto made = std::make_shared<EnvSpec>(*resolved.spec);
  made->kwargs = resolved.kwargs;
  made->max_episode_steps.reset();
  if (resolved.max_episode_steps > 0) made->max_episode_steps = resolved.max_episode_steps;
  env->set_spec(made);
  if (resolved.max_episode_steps > 0) {
    env = std::make_unique<TimeLimit>(std::move(env), resolved.max_episode_steps);
  }
  return env;
}

std::vector<std::string> Registry::registered_ids() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> ids;
  for (const auto& spec : specs_) ids.push_back(spec->id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::vector<std::string> Registry::closest_ids(const std::string& id, std::size_t count) const {
  return closest_names(id, newest_versions_first(registered_ids()), count);
}

Params Registry::parse_kwargs(const std::string& id,
                              const std::vector<std::string>& entries) const {
  const std::shared_ptr<const EnvSpec> found = spec(id);
  // One rule for spaces: none around a key or a number or bool (a string keeps them all).
  const auto spaced = [](const std::string& s) {
    return !s.empty() && (std::isspace(static_cast<unsigned char>(s.front())) != 0 ||
                          std::isspace(static_cast<unsigned char>(s.back())) != 0);
  };
  const auto trimmed = [](const std::string& s) {
    const std::size_t first = s.find_first_not_of(" \t\n\r\f\v");
    if (first == std::string::npos) return std::string();
    return s.substr(first, s.find_last_not_of(" \t\n\r\f\v") - first + 1);
  };
  Params params;
  for (const std::string& entry : entries) {
    const std::size_t equals = entry.find('=');
    if (equals == std::string::npos || equals == 0) {
      throw std::invalid_argument("--set expects key=value, got \"" + entry + "\"");
    }
    const std::string key = entry.substr(0, equals);
    const std::string text = entry.substr(equals + 1);
    if (spaced(key)) {
      throw std::invalid_argument("--set \"" + entry + "\": the key has spaces around it; write " +
                                  trimmed(key) + "=" + text);
    }
    const auto declared = std::find_if(found->params.begin(), found->params.end(),
                                       [&](const ParamSpec& p) { return p.name == key; });
    const ParamType type = key == "max_episode_steps"        ? ParamType::kInt
                           : declared != found->params.end() ? declared->type()
                                                             : ParamType::kString;
    if (type != ParamType::kString && spaced(text)) {
      throw std::invalid_argument(id + ": --set " + key + ": \"" + text +
                                  "\" has spaces around it; write " + key + "=" + trimmed(text));
    }
    try {
      params.insert_or_assign(key, parse_param(type, text));
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(id + ": --set " + key + ": " + error.what());
    }
  }
  return params;
}

}  // namespace pixelgym
