#include "examples/trainer/run/process_tuning.h"

#include <dlfcn.h>
#include <malloc.h>

#include <cstdlib>

namespace pixelgym::trainer {

void tune_process_for_training() {
  if (std::getenv("MALLOC_MMAP_MAX_") == nullptr) mallopt(M_MMAP_MAX, 0);
  if (std::getenv("MALLOC_TRIM_THRESHOLD_") == nullptr) mallopt(M_TRIM_THRESHOLD, 1 << 30);
  if (std::getenv("MALLOC_TOP_PAD_") == nullptr) mallopt(M_TOP_PAD, 256 << 20);
  if (std::getenv("OPENBLAS_NUM_THREADS") == nullptr) {
    // Looked up at run time: OpenBLAS is LibTorch's BLAS only where it is installed (the
    // reference BLAS has no threads to set).
    using SetThreads = void (*)(int);
    if (auto* set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) {
      set(1);
    }
  }
}

}  // namespace pixelgym::trainer
