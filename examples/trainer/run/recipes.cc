#include "pixelgym/trainer/recipes.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "pixelgym/envs/suggestions.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;

std::string quoted(const std::string& text) { return "\"" + text + "\""; }

std::string read_text(const fs::path& path, const std::string& what) {
  std::ifstream in(path);
  if (!in || fs::is_directory(path)) {
    throw std::invalid_argument(what + ": cannot read " + path.string() +
                                (fs::exists(path) ? "" : " (no such file)"));
  }
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

fs::path recipe_folder(const std::string& algorithm) {
  // Installed, the recipes sit at PIXELGYM_BIN_TO_RECIPES from the program's folder
  // (share/pixelgym/configs beside bin/); in the build tree that folder does not exist and the
  // source tree's serve.
  std::error_code error;
  const fs::path program = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    const fs::path installed =
        (program.parent_path() / PIXELGYM_BIN_TO_RECIPES / algorithm).lexically_normal();
    if (fs::is_directory(installed, error)) return installed;
  }
  return fs::path(PIXELGYM_RECIPES_SOURCE_DIR) / algorithm / "configs";
}

std::vector<std::string> recipe_names(const std::string& algorithm) {
  std::vector<std::string> names;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(recipe_folder(algorithm), error)) {
    if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string config_text(const std::string& value, const std::string& algorithm,
                        const std::vector<std::string>& algorithms) {
  const std::string what = "--config " + value;
  const std::size_t first = value.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && value[first] == '{') return value;
  const bool is_path = value.find('/') != std::string::npos ||
                       (value.size() > 5 && value.compare(value.size() - 5, 5, ".json") == 0);
  if (is_path) {
    // swingup.json for the recipe swingup.
    const std::string stem = fs::path(value).stem().string();
    if (!fs::exists(value) && fs::is_regular_file(recipe_folder(algorithm) / (stem + ".json"))) {
      throw std::invalid_argument(what + ": cannot read " + value +
                                  " (no such file); did you mean the recipe --config " + stem +
                                  "?");
    }
    return read_text(value, what);
  }
  const fs::path recipe = recipe_folder(algorithm) / (value + ".json");
  if (fs::is_regular_file(recipe)) return read_text(recipe, what);

  const std::vector<std::string> names = recipe_names(algorithm);
  std::string message =
      "--config " + quoted(value) + ": " + algorithm + " has no recipe named " + quoted(value);
  std::vector<std::string> others;
  for (const std::string& other : algorithms) {
    if (other != algorithm && fs::is_regular_file(recipe_folder(other) / (value + ".json"))) {
      others.push_back(other);
    }
  }
  if (!others.empty()) {
    message += " (" + join_names(others) + " has one: add --algo " + others.front() + ")";
  }
  const std::string suggestion = did_you_mean(value, names);
  message += "; " + (suggestion.empty() ? "" : suggestion + " ") + algorithm +
             "'s recipes: " + (names.empty() ? "none" : join_names(names)) + " (in " +
             recipe_folder(algorithm).string() +
             "; `pixelgym train --list-configs` shows them). --config also takes a file "
             "(FILE.json, or a path with a '/': ./" +
             value + ") or inline JSON ('{\"gamma\": 0.95}')";
  throw std::invalid_argument(message);
}

nlohmann::json with_setting(nlohmann::json config, const std::string& set) {
  const std::size_t equals = set.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw std::invalid_argument("--set-algo expects KEY=VALUE (e.g. gamma=0.95), got " +
                                quoted(set));
  }
  const std::string key = set.substr(0, equals);
  const std::string text = set.substr(equals + 1);
  nlohmann::json value = nlohmann::json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;  // a word: a string (encoder=mrq)
  nlohmann::json* member = &config;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = key.find('.', begin);
    const std::string name = key.substr(begin, dot - begin);
    if (name.empty()) {
      throw std::invalid_argument("--set-algo " + set + ": expected KEY or KEY.MEMBER (e.g. " +
                                  "policy.cnn=fine), got the key " + quoted(key));
    }
    if (!member->is_object()) {
      const std::string parent =
          begin == 0 ? std::string("the config") : quoted(key.substr(0, begin - 1));
      throw std::invalid_argument("--set-algo " + set + ": " + parent + " is " +
                                  member->type_name() + " " + member->dump() +
                                  ", not an object of settings");
    }
    member = &(*member)[name];
    if (dot == std::string::npos) break;
    if (member->is_null()) *member = nlohmann::json::object();
    begin = dot + 1;
  }
  *member = value;
  return config;
}

}  // namespace pixelgym::trainer
