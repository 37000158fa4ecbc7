// pixelgym — the command-line front door: list, info, check, snapshot, rollout, bench, inspect,
// view, record, train, eval, compare, help. It does not load LibTorch: train and eval, once their
// command lines parsed, replace this process by pixelgym-train (trainer_main.cc).
#include "examples/pixelgym/cli.h"
#include "examples/pixelgym/train_commands.h"

int main(int argc, char** argv) {
  return pixelgym::cli::run_tool(argc, argv, pixelgym::cli::exec_trainer(argv));
}
