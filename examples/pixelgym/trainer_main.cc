// pixelgym-train — the `pixelgym` tool with train and eval run in this process, on LibTorch.
// pixelgym starts it for those two (main.cc); it takes every subcommand pixelgym takes.
#include "examples/pixelgym/cli.h"
#include "examples/pixelgym/train_commands.h"

int main(int argc, char** argv) {
  return pixelgym::cli::run_tool(argc, argv, pixelgym::cli::in_process_trainer());
}
