// The `pixelgym` tool's command line: every subcommand, help, and the exit codes (cli.h).
#include <exception>
#include <iostream>
#include <string>

#include "examples/pixelgym/cli.h"
#include "examples/pixelgym/train_commands.h"

namespace pixelgym::cli {
namespace {

// An error message, then the usage of the subcommand it is about (CLI11's help() shows the chosen
// subcommand's, or the whole tool's when none was chosen); exit code 2.
int usage_error(const CLI::App& app, const std::string& message) {
  std::cerr << "pixelgym: " << message << "\n\n" << app.help();
  return kExitUsage;
}

// The whole tool's help, even while a subcommand (`help`) is chosen.
std::string tool_help(const CLI::App& app) {
  return app.get_formatter()->make_help(&app, app.get_name(), CLI::AppFormatMode::Normal);
}

}  // namespace

int run_tool(int argc, char** argv, const Trainer& trainer) {
  CLI::App app{
      "pixelgym: pixel-based reinforcement-learning environments (Bullet + OSMesa)\n"
      "behind the Gymnasium API.",
      "pixelgym"};
  app.require_subcommand(1, 1);
  app.fallthrough(false);
  app.set_version_flag("--version", std::string("pixelgym ") + PIXELGYM_VERSION,
                       "Print the version and exit");
  std::vector<Command> commands = add_env_commands(app);
  for (auto* add : {add_engine_commands, add_render_commands, add_record_commands}) {
    for (auto& command : add(app)) commands.push_back(std::move(command));
  }
  for (auto& command : add_train_commands(app, trainer)) commands.push_back(std::move(command));

  // `pixelgym help [SUBCOMMAND]`: the same text as --help.
  std::string help_topic;
  CLI::App* help = app.add_subcommand("help", "Show this help, or a subcommand's: help SUBCOMMAND");
  help->add_option("subcommand", help_topic, "Subcommand to explain");
  commands.push_back({help, [&app, &help_topic, &commands] {
                        if (help_topic.empty()) {
                          std::cout << tool_help(app);
                          return 0;
                        }
                        for (const Command& command : commands) {
                          if (command.app->get_name() == help_topic) {
                            std::cout << command.app->help(app.get_name());
                            return 0;
                          }
                        }
                        std::cerr << "pixelgym: help: unknown subcommand \"" << help_topic
                                  << "\"\n\n"
                                  << tool_help(app);
                        return kExitUsage;
                      }});

  // CLI11 reports an unknown first word only as "a subcommand is required"; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    std::string names;
    for (const auto& command : commands) {
      known = known || command.app->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + command.app->get_name();
    }
    if (!known) {
      return usage_error(
          app, std::string("unknown subcommand \"") + argv[1] + "\" (subcommands: " + names + ")");
    }
  }

  try {
    app.parse(argc, argv);
    for (const auto& command : commands) {
      if (command.app->parsed()) return command.run();
    }
  } catch (const CLI::Success& success) {  // --help, --help-all, --version
    return app.exit(success);
  } catch (const CLI::ParseError& error) {
    return usage_error(app, error.what());
  } catch (const UsageError& error) {
    return usage_error(app, error.what());
  } catch (const std::exception& error) {
    std::cerr << "pixelgym: error: " << error.what() << "\n";
    return kExitFailure;
  }
  return 0;
}

}  // namespace pixelgym::cli
