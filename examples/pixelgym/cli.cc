#include "examples/pixelgym/cli.h"

#include <algorithm>
#include <filesystem>

#include "envs/registry.h"
#include "render/image_io.h"

namespace pixelgym::cli {

void add_set_option(CLI::App& command, std::vector<std::string>& sets) {
  command
      .add_option("--set", sets,
                  "Env kwarg as key=value (repeatable); `pixelgym info ID` lists the keys")
      ->type_name("KEY=VALUE");
}

Params parse_sets(const std::string& id, const std::vector<std::string>& sets) {
  const auto spec = default_registry().spec(id);
  Params params;
  for (const std::string& entry : sets) {
    const std::size_t equals = entry.find('=');
    if (equals == std::string::npos || equals == 0) {
      throw UsageError("--set expects key=value, got \"" + entry + "\"");
    }
    const std::string key = entry.substr(0, equals);
    const std::string text = entry.substr(equals + 1);
    const auto declared = std::find_if(spec->params.begin(), spec->params.end(),
                                       [&](const ParamSpec& p) { return p.name == key; });
    const ParamType type = key == "max_episode_steps"       ? ParamType::kInt
                           : declared != spec->params.end() ? declared->type()
                                                            : ParamType::kString;
    try {
      params.insert_or_assign(key, parse_param(type, text));
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(id + ": --set " + key + ": " + error.what());
    }
  }
  return params;
}

std::unique_ptr<Env> make_env(const std::string& id, const std::vector<std::string>& sets) {
  return make(id, parse_sets(id, sets));
}

void write_frame_png(const std::string& path, const Array& frame) {
  if (frame.dtype() != DType::kUInt8 || frame.ndim() != 3 || frame.shape()[2] != 3) {
    throw std::invalid_argument("expected an (H, W, 3) uint8 frame, got " + frame.to_string());
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) {
    std::error_code error;
    std::filesystem::create_directories(parent, error);
    if (error)
      throw std::runtime_error("cannot create folder " + parent.string() + ": " + error.message());
  }
  render::write_png(path, {frame.data<std::uint8_t>(), static_cast<int>(frame.shape()[0]),
                   static_cast<int>(frame.shape()[1]), 3});
}

}  // namespace pixelgym::cli
