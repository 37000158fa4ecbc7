#include "pixelgym/trainer/run_settings.h"

#include <fstream>
#include <stdexcept>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/wrappers/wrapper_spec.h"

namespace pixelgym::trainer {

using nlohmann::json;

std::uint64_t RunSettings::seed() const { return algorithm_config.at("seed").get<std::uint64_t>(); }

std::int64_t RunSettings::num_envs() const {
  return algorithm_config.at("num_envs").get<std::int64_t>();
}

std::int64_t RunSettings::total_env_steps() const {
  return algorithm_config.at("total_env_steps").get<std::int64_t>();
}

json kwargs_to_json(const Params& kwargs) {
  json out = json::object();
  for (const auto& [key, value] : kwargs) {
    switch (value.type()) {
      case ParamType::kBool:
        out[key] = value.as_bool();
        break;
      case ParamType::kInt:
        out[key] = value.as_int();
        break;
      case ParamType::kFloat:
        out[key] = value.as_float();
        break;
      case ParamType::kString:
        out[key] = value.as_string();
        break;
    }
  }
  return out;
}

Params kwargs_from_json(const json& object) {
  if (!object.is_object()) {
    throw std::invalid_argument(std::string("env_kwargs: an object expected, got ") +
                                object.type_name());
  }
  Params kwargs;
  for (const auto& [key, value] : object.items()) {
    if (value.is_boolean()) {
      kwargs.emplace(key, value.get<bool>());
    } else if (value.is_number_integer()) {
      kwargs.emplace(key, value.get<std::int64_t>());
    } else if (value.is_number_float()) {
      kwargs.emplace(key, value.get<double>());
    } else if (value.is_string()) {
      kwargs.emplace(key, value.get<std::string>());
    } else {
      throw std::invalid_argument("env_kwargs." + key +
                                  ": a boolean, integer, float or string expected, got " +
                                  value.dump());
    }
  }
  return kwargs;
}

json settings_to_json(const RunSettings& settings) {
  json out;
  out["env_id"] = settings.env_id;
  out["env_kwargs"] = kwargs_to_json(settings.env_kwargs);
  out["wrap"] = settings.wraps;
  out["num_threads"] = settings.num_threads;
  out["torch_threads"] = settings.torch_threads;
  out["checkpoint_every"] = settings.checkpoint_every;
  out["keep_checkpoints"] = settings.keep_checkpoints;
  out["minutes"] = settings.minutes;
  out["eval_episodes"] = settings.eval_episodes;
  out["eval_every"] = settings.eval_every;
  out["eval_every_episodes"] = settings.eval_every_episodes;
  out["eval_max_share"] = settings.eval_max_share;
  if (settings.world_size > 1) out["world_size"] = settings.world_size;
  out[settings.algorithm] = settings.algorithm_config;
  return out;
}

RunSettings settings_from_json(const json& in, const std::filesystem::path& where,
                               const AlgorithmFactory& algorithm) {
  try {
    RunSettings settings;
    settings.env_id = in.at("env_id").get<std::string>();
    try {
      settings.env_kwargs =
          in.contains("env_kwargs") || !in.contains("set")
              ? kwargs_from_json(in.at("env_kwargs"))
              : parse_kwargs(settings.env_id, in.at("set").get<std::vector<std::string>>());
    } catch (const std::invalid_argument& error) {
      throw std::runtime_error(where.string() + ": not a pixelgym train config: " + error.what());
    }
    settings.wraps = in.at("wrap").get<std::vector<std::string>>();
    settings.num_threads = in.at("num_threads").get<int>();
    if (in.contains("torch_threads")) settings.torch_threads = in.at("torch_threads").get<int>();
    settings.checkpoint_every = in.at("checkpoint_every").get<std::int64_t>();
    settings.keep_checkpoints =
        in.contains("keep_checkpoints") ? in.at("keep_checkpoints").get<std::int64_t>() : 0;
    settings.minutes = in.at("minutes").get<double>();
    settings.eval_episodes = in.at("eval_episodes").get<std::int64_t>();
    settings.eval_every = in.value("eval_every", std::int64_t{0});
    settings.eval_every_episodes = in.value("eval_every_episodes", std::int64_t{5});
    settings.eval_max_share = in.value("eval_max_share", 0.1);
    settings.world_size = in.value("world_size", 1);
    settings.algorithm = algorithm.name();
    settings.algorithm_config = algorithm.parse_config(in.at(settings.algorithm).dump());
    return settings;
  } catch (const json::exception& e) {
    throw std::runtime_error(where.string() + ": not a pixelgym train config: " + e.what());
  }
}

json read_run_config(const std::filesystem::path& path, const std::string& what) {
  std::ifstream file(path);
  if (!file) {
    throw std::runtime_error(what + ": no " + path.filename().string() + " in " +
                             path.parent_path().string());
  }
  json config;
  try {
    config = json::parse(file);
  } catch (const json::exception& error) {
    throw std::runtime_error(path.string() + ": not valid JSON (" + error.what() +
                             "); it was written whole, so it was changed after: restore it");
  }
  if (!config.is_object()) {
    throw std::runtime_error(path.string() + ": not a pixelgym train config: the file holds " +
                             config.type_name() + ", not an object");
  }
  return config;
}

std::string settings_differences(const RunSettings& run, const RunSettings& checkpoint) {
  json mine = settings_to_json(run);
  json theirs = settings_to_json(checkpoint);
  for (json* settings : {&mine, &theirs}) {
    settings->erase("minutes");
    if (settings->contains(run.algorithm)) (*settings)[run.algorithm].erase("total_env_steps");
  }
  std::string differ;
  const auto note = [&](const std::string& name, const json& a, const json& b) {
    // JSON's equality takes 64 and 64.0 as one number; an env kwarg's type is part of it.
    if (name == "env_kwargs" ? a.dump() == b.dump() : a == b) return;
    differ += (differ.empty() ? "" : "; ") + name + ": config.json has " +
              (a.is_null() ? std::string("none") : a.dump()) + ", the checkpoint " +
              (b.is_null() ? std::string("none") : b.dump());
  };
  const auto value = [](const json& object, const std::string& key) {
    const auto found = object.find(key);
    return found == object.end() ? json() : *found;
  };
  json keys = mine;
  keys.update(theirs);
  for (const auto& item : keys.items()) {
    const json a = value(mine, item.key());
    const json b = value(theirs, item.key());
    if (item.key() == run.algorithm && a.is_object() && b.is_object()) {
      json members = a;
      members.update(b);
      for (const auto& member : members.items()) {
        note(item.key() + "." + member.key(), value(a, member.key()), value(b, member.key()));
      }
    } else {
      note(item.key(), a, b);
    }
  }
  return differ;
}

const AlgorithmFactory& algorithm_of(const json& in, const std::filesystem::path& where,
                                     const AlgorithmFactories& algorithms) {
  if (in.is_discarded()) {
    throw std::runtime_error(where.string() + ": not valid JSON");
  }
  std::string names;
  for (const AlgorithmFactory* algorithm : algorithms) {
    if (in.is_object() && in.contains(algorithm->name())) return *algorithm;
    names += (names.empty() ? "\"" : ", \"") + algorithm->name() + "\"";
  }
  throw std::runtime_error(where.string() +
                           ": not a pixelgym train config: no member names an algorithm (" + names +
                           ")");
}

std::unique_ptr<vector::VectorEnv> make_training_env(const RunSettings& settings) {
  const vector::VectorOptions options{vector::VectorMode::kAsync, settings.num_threads,
                                      vector::AutoresetMode::kSameStep, true};
  return vector::make_vec(settings.env_id, static_cast<int>(settings.num_envs()),
                          settings.env_kwargs, wrappers::wrapping(settings.wraps), options);
}

std::unique_ptr<Env> make_run_env(const RunSettings& settings) {
  return wrappers::apply_wrappers(make(settings.env_id, settings.env_kwargs), settings.wraps);
}

}  // namespace pixelgym::trainer
