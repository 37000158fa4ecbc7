// The `pixelgym` tool's command line: every subcommand, help, and the exit codes (cli.h).
#include <algorithm>
#include <cmath>
#include <exception>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "examples/pixelgym/cli.h"
#include "examples/pixelgym/train_commands.h"
#include "pixelgym/envs/suggestions.h"

namespace pixelgym::cli {
namespace {

// An error message, then one line naming where the usage of the subcommand it is about is (the
// chosen subcommand's --help, or the whole tool's when none was chosen); exit code 2. The help
// itself (40 lines for train) would bury the message.
int usage_error(const CLI::App& app, const std::string& message) {
  const auto chosen = app.get_subcommands();
  const bool subcommand = !chosen.empty() && chosen.front()->get_name() != "help";
  std::cerr << "pixelgym: " << message << "\n"
            << (subcommand
                    ? "Run 'pixelgym " + chosen.front()->get_name() + " --help' for the options."
                    : std::string("Run 'pixelgym --help' for the subcommands."))
            << "\n";
  return kExitUsage;
}

// Words other tools and the library's own API use for a subcommand (describe() gives what info
// prints), suggested for an unknown subcommand before the subcommands it is a typo of.
const std::vector<std::pair<std::string, std::string>> kSubcommandSynonyms = {
    {"describe", "info"},   {"show", "info"},           {"spec", "info"},
    {"ls", "list"},         {"envs", "list"},           {"evaluate", "eval"},
    {"test", "check"},      {"validate", "check"},      {"benchmark", "bench"},
    {"render", "snapshot"}, {"screenshot", "snapshot"}, {"video", "record"},
    {"learn", "train"},     {"fit", "train"},           {"plot", "compare"}};

// "unknown subcommand "WORD"; did you mean NAME? (subcommands: ...)".
std::string unknown_subcommand(const std::string& word, const std::vector<Command>& commands) {
  std::vector<std::string> names;
  for (const Command& command : commands) names.push_back(command.app->get_name());
  // A word of another tool is that tool's subcommand, though it may be a typo's distance from
  // another of ours ("test" from list, "video" from view).
  std::string suggestion;
  for (const auto& [synonym, name] : kSubcommandSynonyms) {
    if (synonym == word) suggestion = "did you mean " + name + "?";
  }
  if (suggestion.empty()) suggestion = did_you_mean(word, names);
  return "unknown subcommand \"" + word + "\"" +
         (suggestion.empty() ? " " : "; " + suggestion + " ") +
         "(subcommands: " + join_names(names) + ")";
}

// A bound of CLI11's Range as a person writes it: "0", "1024", "1e9" (std::to_string's "0.000000"
// and "1000000000.000000" otherwise).
std::string bound_text(const std::string& text) {
  double value = 0.0;
  try {
    value = std::stod(text);
  } catch (const std::exception&) {
    return text;
  }
  if (value != std::floor(value) || std::abs(value) >= 1e18) return text;
  std::string digits = std::to_string(static_cast<long long>(value));
  std::size_t zeros = 0;
  while (zeros + 1 < digits.size() && digits[digits.size() - 1 - zeros] == '0') ++zeros;
  if (zeros < 6) return digits;
  return digits.substr(0, digits.size() - zeros) + "e" + std::to_string(zeros);
}

// CLI11's "Could not convert: --steps = x" and Range's "--minutes: Value abc not in range
// 0.000000 to 1000000000.000000" said as the other option errors are: "--steps: expected an
// integer, got "x"", "--minutes: expected a number from 0 to 1e9, got "abc"" (the option's type
// from its type name: INT, FLOAT, UINT64).
std::string option_error_message(const CLI::App& app, const CLI::ParseError& error) {
  const std::string what = error.what();
  std::vector<const CLI::App*> apps = {&app};
  for (const CLI::App* chosen : app.get_subcommands()) apps.push_back(chosen);
  for (const CLI::App* in : apps) {
    for (const CLI::Option* option : in->get_options()) {
      const std::string name = option->get_name();
      const std::string convert = "Could not convert: " + name + " = ";
      const std::string range = name + ": Value ";
      std::string got;
      std::string bounds;
      if (what.rfind(convert, 0) == 0) {
        got = what.substr(convert.size());
      } else if (what.rfind(range, 0) == 0) {
        const std::size_t at = what.find(" not in range ", range.size());
        const std::size_t to = what.find(" to ", at == std::string::npos ? 0 : at + 14);
        if (at == std::string::npos || to == std::string::npos) continue;
        got = what.substr(range.size(), at - range.size());
        bounds = " from " + bound_text(what.substr(at + 14, to - at - 14)) + " to " +
                 bound_text(what.substr(to + 4));
      } else {
        continue;
      }
      std::string type = option->get_type_name();
      type = type.substr(0, type.find(':'));
      const std::string expected = type == "INT" || type == "UINT64" ? "an integer"
                                   : type == "FLOAT"                 ? "a number"
                                                                     : type;
      return name + ": expected " + expected + bounds + ", got \"" + got + "\"";
    }
  }
  return what;
}

// CLI11's "The following arguments were not expected: 3 --minute", with the chosen subcommand's
// options closest to each unknown one: "...; --minute: did you mean --minutes?".
std::string extras_message(const CLI::App& app, const CLI::ExtrasError& error) {
  const auto chosen = app.get_subcommands();
  const CLI::App& command = chosen.empty() ? app : *chosen.front();
  std::vector<std::string> names;
  for (const CLI::Option* option : command.get_options()) {
    if (!option->get_lnames().empty()) names.push_back("--" + option->get_lnames().front());
  }
  std::string message = error.what();
  for (const std::string& extra : app.remaining(true)) {
    if (extra.rfind("--", 0) != 0 || extra.size() < 3) continue;
    const std::string name = extra.substr(0, extra.find('='));
    if (std::find(names.begin(), names.end(), name) != names.end()) continue;
    const std::string suggestion = did_you_mean(name, names);
    if (!suggestion.empty()) message += "; " + name + ": " + suggestion;
  }
  return message;
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
                        return usage_error(app,
                                           "help: " + unknown_subcommand(help_topic, commands));
                      }});

  // CLI11 reports an unknown first word only as "a subcommand is required"; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    for (const auto& command : commands) known = known || command.app->get_name() == argv[1];
    if (!known) return usage_error(app, unknown_subcommand(argv[1], commands));
  }

  try {
    app.parse(argc, argv);
    for (const auto& command : commands) {
      if (command.app->parsed()) return command.run();
    }
  } catch (const CLI::Success& success) {  // --help, --help-all, --version
    return app.exit(success);
  } catch (const CLI::ConversionError& error) {
    return usage_error(app, option_error_message(app, error));
  } catch (const CLI::ValidationError& error) {
    return usage_error(app, option_error_message(app, error));
  } catch (const CLI::ExtrasError& error) {
    return usage_error(app, extras_message(app, error));
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
