// Recipes: the trainer's named configs (examples/trainer/ALGO/configs/NAME.json, installed as
// share/pixelgym/configs/ALGO/NAME.json), and what `train --config` and `--set-algo` make of
// their text.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace pixelgym::trainer {

/// The folder of `algorithm`'s recipes: installed (`cmake --install`, the Debian package), the
/// share/pixelgym/configs/ALGO of the prefix the running program was installed to, found from
/// the program's own folder (bin/); in the build tree, the source's examples/trainer/ALGO/configs.
std::filesystem::path recipe_folder(const std::string& algorithm);

/// The names of `algorithm`'s recipes (their file names without .json), sorted; empty when it
/// has none.
std::vector<std::string> recipe_names(const std::string& algorithm);

/// The JSON text that `train --config VALUE` gives `algorithm`: VALUE itself when it is inline
/// JSON (its first non-space character is '{'); the file's text when it names a file (it has a
/// '/' or ends in .json); otherwise the text of the recipe of that name. Throws
/// std::invalid_argument naming VALUE for a file that cannot be read, and for an unknown recipe
/// naming the closest ("did you mean") and every recipe of `algorithm`, the algorithms that do
/// have one of that name among `algorithms`, and the form of a file path.
std::string config_text(const std::string& value, const std::string& algorithm,
                        const std::vector<std::string>& algorithms);

/// `config` (a JSON object of an algorithm's settings, any subset) with `set` applied: `set` is
/// KEY=VALUE, where KEY names a member (a.b for member b of object member a: policy.cnn) and
/// VALUE is JSON (0.95, true, [64, 64], "fine") or, when it does not parse as JSON, a string
/// (fine). Throws std::invalid_argument naming `set` when it has no '=' or an empty key, or
/// when KEY goes through a member that is not an object. Whether the member exists and takes
/// such a value is for the algorithm's parse_config to say.
nlohmann::json with_setting(nlohmann::json config, const std::string& set);

}  // namespace pixelgym::trainer
