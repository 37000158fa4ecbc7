// The process settings CPU training runs with (pixelgym train and eval, ppo_bench).
#pragma once

namespace pixelgym::trainer {

/// Sets up the process for training on a CPU: glibc keeps freed memory in the process (no
/// mmap'd blocks, no trimming of the heap's top), and OpenBLAS runs on one thread (torch's
/// intra-op threads are the parallelism). Why, with the measurements: docs/design-notes.md,
/// Trainer. Not applied when the user set the corresponding environment variables
/// (MALLOC_MMAP_MAX_, MALLOC_TRIM_THRESHOLD_, MALLOC_TOP_PAD_, OPENBLAS_NUM_THREADS). Call it
/// first, before torch runs anything.
void tune_process_for_training();

}  // namespace pixelgym::trainer
