// Pieces shared by the `pixelgym` subcommands.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/env.h"
#include "pixelgym/envs/params.h"
#include "pixelgym/envs/registry.h"

namespace pixelgym::cli {

/// Exit codes: 0 success; 1 the command ran and failed (an env error, a failed check, a file that
/// cannot be read or written); 2 a usage error (a malformed command line, an unknown subcommand,
/// env id or kwarg, a value out of range, an env config that `make` refuses).
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

/// Thrown for a command line that parses but cannot be used (an unknown env id, a --set without
/// '=', a kwarg the env refuses): main prints it with a line naming the subcommand's --help, and
/// exits 2.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Accepts a whole decimal integer in [min, max] (for an int option); otherwise the option fails
/// with "must be an integer from MIN to MAX, got "TEXT"". Help shows the range.
CLI::Validator integer_in(int min, int max = std::numeric_limits<int>::max());

/// Accepts one of `names` (help shows {a,b}); otherwise the option fails with "unknown {what}
/// \"TEXT\"; did you mean NAME? (the {what}s: a, b)", "did you mean" only when one is close.
CLI::Validator name_in(const std::vector<std::string>& names, const std::string& what);

/// Adds `--seed N` (default 0, any unsigned 64-bit integer; "-1" is refused, not wrapped around).
CLI::Option* add_seed_option(CLI::App& command, std::uint64_t& seed,
                             const std::string& description);

/// Accepts a path ending in ".png" (any case): pixelgym writes PNG only.
CLI::Validator png_path();

/// The env a subcommand works on: its id, and the --set and --wrap options that shape it.
struct EnvArguments {
  std::string id;
  std::vector<std::string> sets;   // KEY=VALUE
  std::vector<std::string> wraps;  // wrapper specs, the first innermost
};

/// Adds the required positional `id`: "Env id, e.g. {example} (`pixelgym list` shows them)".
void add_id_argument(CLI::App& command, std::string& id, const std::string& example);

/// Adds option `name`, its default shown in help and its value checked by `check`.
template <typename T>
CLI::Option* add_checked_option(CLI::App& command, const std::string& name, T& value,
                                const std::string& description, const CLI::Validator& check) {
  return command.add_option(name, value, description)->capture_default_str()->check(check);
}

/// Adds the repeatable `--set key=value` option to `command`.
void add_set_option(CLI::App& command, std::vector<std::string>& sets);

/// Turns `--set key=value` strings into kwargs typed by env `id`'s declared params (a key the env
/// does not declare is passed as a string, so that `make` reports it with the valid keys).
/// Throws UsageError for an unknown id, an entry without '=' or an unreadable value.
Params parse_sets(const std::string& id, const std::vector<std::string>& sets);

/// Adds the repeatable `--wrap NAME[=ARGS]` option to `command` (wrapper specs, applied in order;
/// `pixelgym wrappers` lists them).
void add_wrap_option(CLI::App& command, std::vector<std::string>& wraps);

/// Adds --set then --wrap (add_set_option, add_wrap_option) into `env`.
void add_env_options(CLI::App& command, EnvArguments& env);

/// `make(id, parse_sets(id, sets))` wrapped by each of `wraps` in order (the first innermost); a
/// config `make` refuses or a wrapper spec that does not apply (std::invalid_argument: an unknown
/// kwarg, a value out of range, a wrapper argument that does not parse, a key that is not an
/// image) is rethrown as UsageError.
std::unique_ptr<Env> make_env(const std::string& id, const std::vector<std::string>& sets,
                              const std::vector<std::string>& wraps = {});

/// What `make_env(id, sets, wraps)` would build, from the spec and Registry::describe alone (no
/// env, Bullet world or GL context): throws UsageError for what make_env refuses as one (an
/// unknown id or kwarg, a value out of range, a wrapper spec that does not apply).
EnvDescription describe_env(const std::string& id, const std::vector<std::string>& sets,
                            const std::vector<std::string>& wraps = {});

/// Checks, before any work, that a video file can be written at `path` (what `option` named):
/// throws UsageError when `path` is a folder or its parent is a file, std::runtime_error naming the
/// folder and the OS's reason when the folder cannot be created or a file cannot be created in it.
/// Creates the folder when missing (as RecordVideo would).
void check_video_file(const std::string& option, const std::string& path);

/// Writes an (H, W, 3) uint8 frame as PNG, creating missing parent folders.
void write_frame_png(const std::string& path, const Array& frame);

/// A subcommand and what runs when the command line chose it (its exit code).
struct Command {
  CLI::App* app;
  std::function<int()> run;
};

/// Adds subcommand `name` to `app` whose options parse into an `Arguments` of its own, living as
/// long as the returned Command: `declare` gives the subcommand its description and options,
/// and choosing it runs `run` (a callable taking `const Arguments&`) on what was parsed (its exit
/// code).
template <typename Arguments, typename Run>
Command add_command(CLI::App& app, const std::string& name,
                    void (*declare)(CLI::App& command, Arguments& args), Run run) {
  auto args = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(name);
  declare(*command, *args);
  return {command, [args, run] { return run(*args); }};
}

/// Adds list, wrappers, info, check, snapshot, rollout and bench to `app`. Each subcommand parses
/// into options of its own, which live as long as the returned commands.
std::vector<Command> add_env_commands(CLI::App& app);

/// Adds inspect to `app`.
std::vector<Command> add_engine_commands(CLI::App& app);

/// Adds view to `app`.
std::vector<Command> add_render_commands(CLI::App& app);

/// Adds record (episodes to .mp4 through wrappers::RecordVideo) to `app`.
std::vector<Command> add_record_commands(CLI::App& app);

struct Trainer;

/// The `pixelgym` tool: parses the command line and runs the subcommand it chose, train and eval
/// through `trainer` (train_commands.h, which also adds compare); returns the exit code. The main()
/// of pixelgym and of pixelgym-train.
int run_tool(int argc, char** argv, const Trainer& trainer);

}  // namespace pixelgym::cli
