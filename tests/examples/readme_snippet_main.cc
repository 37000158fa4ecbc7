// main() for the programs made from README.md's C++ blocks: runs the block (each block is the
// body of readme_snippet(), its leading #include and using lines at file scope), then says it
// reached the end. An exception or a crash ends the program without that line and with a non-zero
// status, which run_expecting.cmake fails on.
#include <cstdio>

void readme_snippet();

int main() {
  readme_snippet();
  std::printf("README snippet ran to the end\n");
  return 0;
}
