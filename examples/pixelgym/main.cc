// pixelgym — the command-line front door: list, info, check, snapshot, rollout, inspect, view.
#include <exception>
#include <iostream>
#include <string>

#include "examples/pixelgym/cli.h"

int main(int argc, char** argv) {
  CLI::App app{
      "pixelgym: pixel-based reinforcement-learning environments (Bullet + OSMesa)\n"
      "behind the Gymnasium API.",
      "pixelgym"};
  app.require_subcommand(1, 1);
  app.fallthrough(false);
  std::vector<pixelgym::cli::Command> commands = pixelgym::cli::add_env_commands(app);
  for (auto* add : {pixelgym::cli::add_engine_commands, pixelgym::cli::add_render_commands}) {
    for (auto& command : add(app)) commands.push_back(std::move(command));
  }

  // CLI11 reports an unknown first word only as "a subcommand is required"; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    std::string names;
    for (const auto& command : commands) {
      known = known || command.app->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + command.app->get_name();
    }
    if (!known) {
      std::cerr << "pixelgym: unknown subcommand \"" << argv[1] << "\" (subcommands: " << names
                << ")\n\n"
                << app.help();
      return pixelgym::cli::kExitUsage;
    }
  }

  try {
    app.parse(argc, argv);
    for (const auto& command : commands) {
      if (command.app->parsed()) return command.run();
    }
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return app.exit(help);
  } catch (const CLI::ParseError& error) {
    std::cerr << "pixelgym: " << error.what() << "\n\n" << app.help();
    return pixelgym::cli::kExitUsage;
  } catch (const pixelgym::cli::UsageError& error) {
    std::cerr << "pixelgym: " << error.what() << "\n\n" << app.help();
    return pixelgym::cli::kExitUsage;
  } catch (const std::exception& error) {
    std::cerr << "pixelgym: error: " << error.what() << "\n";
    return pixelgym::cli::kExitFailure;
  }
  return 0;
}
