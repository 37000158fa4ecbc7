// Pieces shared by the `pixelgym` subcommands.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "envs/array.h"
#include "envs/env.h"
#include "envs/params.h"

namespace pixelgym::cli {

/// Exit codes: 0 success, 1 the command ran and failed (an env error, a failed check), 2 usage.
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

/// Thrown for a malformed command line that CLI11 cannot catch itself (a --set without '=').
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Adds the repeatable `--set key=value` option to `command`.
void add_set_option(CLI::App& command, std::vector<std::string>& sets);

/// Turns `--set key=value` strings into kwargs typed by env `id`'s declared params (a key the env
/// does not declare is passed as a string, so that `make` reports it with the valid keys).
/// Throws UsageError for an entry without '=' and std::invalid_argument for an unreadable value.
Params parse_sets(const std::string& id, const std::vector<std::string>& sets);

/// `make(id, parse_sets(id, sets))`.
std::unique_ptr<Env> make_env(const std::string& id, const std::vector<std::string>& sets);

/// Writes an (H, W, 3) uint8 frame as PNG, creating missing parent folders.
void write_frame_png(const std::string& path, const Array& frame);

/// A subcommand and what runs when the command line chose it (its exit code).
struct Command {
  CLI::App* app;
  std::function<int()> run;
};

/// Adds list, info, check, snapshot and rollout to `app`. The options they parse into live as
/// long as the returned commands.
std::vector<Command> add_env_commands(CLI::App& app);

/// Adds inspect to `app`.
std::vector<Command> add_engine_commands(CLI::App& app);

/// Adds view to `app`.
std::vector<Command> add_render_commands(CLI::App& app);

}  // namespace pixelgym::cli
