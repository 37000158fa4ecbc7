// Running the built `pixelgym` binary from a test, as a user or a script does (PIXELGYM_CLI is
// its path, a compile definition of the test).
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace pixelgym::testing {

struct CliRun {
  int exit_code;       // -1 when the process did not exit normally (a crash)
  std::string output;  // stdout and stderr
};

/// Runs `command_line` through the shell, its stderr with its stdout.
inline CliRun run_program(const std::string& command_line) {
  const std::string command = command_line + " 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "popen failed"};
  std::string output;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) output += buffer.data();
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

/// Runs `pixelgym ARGUMENTS` through the shell, with `environment` ("NAME=value ...") set for it.
inline CliRun run_cli(const std::string& arguments, const std::string& environment = "") {
  return run_program(environment + " " + std::string(PIXELGYM_CLI) + " " + arguments);
}

}  // namespace pixelgym::testing
