#include "examples/pixelgym/cli.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/suggestions.h"
#include "pixelgym/render/image_io.h"
#include "pixelgym/wrappers/wrapper_spec.h"

namespace pixelgym::cli {

namespace fs = std::filesystem;
namespace {

// Whether `text` is wholly a decimal integer of type T (no sign for unsigned T, no spaces).
template <typename T>
bool parse_integer(const std::string& text, T& value) {
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  return error == std::errc() && stop == end && !text.empty();
}

}  // namespace

CLI::Validator integer_in(int min, int max) {
  const bool unbounded = max == std::numeric_limits<int>::max();
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        int value = 0;
        if (parse_integer(text, value) && value >= min && value <= max) return "";
        return "must be an integer from " + std::to_string(min) + " to " + std::to_string(max) +
               ", got \"" + text + "\"";
      },
      unbounded ? ">= " + std::to_string(min) : std::to_string(min) + " to " + std::to_string(max));
}

CLI::Validator name_in(const std::vector<std::string>& names, const std::string& what) {
  std::string shown;
  for (const std::string& name : names) shown += (shown.empty() ? "{" : ",") + name;
  return CLI::Validator(
      [names, what](std::string& text) -> std::string {
        if (std::find(names.begin(), names.end(), text) != names.end()) return "";
        const std::string suggestion = did_you_mean(text, names);
        return "unknown " + what + " \"" + text + "\"" +
               (suggestion.empty() ? " " : "; " + suggestion + " ") + "(the " + what +
               "s: " + join_names(names) + ")";
      },
      shown + "}");
}

CLI::Option* add_seed_option(CLI::App& command, std::uint64_t& seed,
                             const std::string& description) {
  const CLI::Validator unsigned_64(
      [](std::string& text) -> std::string {
        std::uint64_t value = 0;
        if (parse_integer(text, value)) return "";
        return "must be an integer from 0 to " +
               std::to_string(std::numeric_limits<std::uint64_t>::max()) + ", got \"" + text + "\"";
      },
      "");
  seed = 0;
  return command.add_option("--seed", seed, description)
      ->type_name("UINT64")
      ->capture_default_str()
      ->check(unsigned_64);
}

CLI::Validator png_path() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::string extension = std::filesystem::path(text).extension().string();
        std::transform(extension.begin(), extension.end(), extension.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (extension == ".png") return "";
        return "pixelgym writes PNG only: the file name must end in .png, got \"" + text + "\"";
      },
      "");
}

void add_id_argument(CLI::App& command, std::string& id, const std::string& example) {
  command.add_option("id", id, "Env id, e.g. " + example + " (`pixelgym list` shows them)")
      ->required();
}

void add_set_option(CLI::App& command, std::vector<std::string>& sets) {
  command
      .add_option("--set", sets,
                  "Env kwarg as key=value (repeatable), e.g. obs_mode=rgb for the image Box "
                  "alone as the observation; `pixelgym info ID` lists the keys")
      ->type_name("KEY=VALUE");
}

Params parse_sets(const std::string& id, const std::vector<std::string>& sets) {
  try {
    return parse_kwargs(id, sets);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());  // an unknown id (with the closest), a bad entry
  }
}

void add_wrap_option(CLI::App& command, std::vector<std::string>& wraps) {
  command
      .add_option("--wrap", wraps,
                  "Wrapper as NAME or NAME=ARGS, e.g. resize=64x64 (repeatable, applied in order, "
                  "the first innermost); `pixelgym wrappers` lists them")
      ->type_name("SPEC");
}

void add_env_options(CLI::App& command, EnvArguments& env) {
  add_set_option(command, env.sets);
  add_wrap_option(command, env.wraps);
}

std::unique_ptr<Env> make_env(const std::string& id, const std::vector<std::string>& sets,
                              const std::vector<std::string>& wraps) {
  const Params kwargs = parse_sets(id, sets);
  std::unique_ptr<Env> env;
  try {
    env = make(id, kwargs);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());  // the kwargs: an unknown key, a value out of range
  }
  try {
    return wrappers::apply_wrappers(std::move(env), wraps);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());  // names the spec, the wrapper and the argument
  }
}

EnvDescription describe_env(const std::string& id, const std::vector<std::string>& sets,
                            const std::vector<std::string>& wraps) {
  const Params kwargs = parse_sets(id, sets);
  EnvDescription description;
  try {
    description = describe(id, kwargs);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());  // the kwargs: an unknown key, a value out of range
  }
  try {
    return wrappers::describe_wrapped(std::move(description), wraps);
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());  // names the spec, the wrapper and the argument
  }
}

void check_video_file(const std::string& option, const std::string& path) {
  const fs::path file(path);
  if (fs::is_directory(file)) {
    throw UsageError(option + " " + path + " is a folder; name a video file (FILE.mp4)");
  }
  const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  if (fs::exists(folder) && !fs::is_directory(folder)) {
    throw UsageError(option + " " + path + ": " + folder.string() + " is a file, not a folder");
  }
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) {
    throw std::runtime_error(option + " " + path + ": cannot create the video folder \"" +
                             folder.string() + "\": " + error.message());
  }
  std::string probe = (folder / ".pixelgym-write-check-XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) {
    throw std::runtime_error(option + " " + path + ": cannot create a file in the video folder \"" +
                             folder.string() + "\": " + std::strerror(errno));
  }
  ::close(fd);
  ::unlink(probe.c_str());
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
