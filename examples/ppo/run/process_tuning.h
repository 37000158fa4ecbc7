// The process settings CPU training runs with (pixelgym train and eval, ppo_bench).
#pragma once

namespace pixelgym::ppo {

/// Sets up the process for training on a CPU; measured with `pixelgym train CartPoleBalance-v0
/// --set obs_mode=pixels --set width=64 --set height=64 --wrap frame_stack=3` on the 2-core VM:
/// - glibc returns large freed blocks to the system (mmap'd ones at once, the heap's top past
///   128 KiB), so torch's per-minibatch tensors were faulted in afresh every time: 22-35 s of
///   system time per 52 s and 170 env steps/s. Keeping freed memory in the process (no mmap'd
///   blocks, no trimming) gives 950 env steps/s with 1.6 s of system time.
/// - OpenBLAS's own threads (one per core) wait for work by yielding the core, on top of torch's
///   intra-op threads: the same speed with 1 thread, and 20 s less CPU per 50 s.
/// Not applied when the user set the corresponding environment variables (MALLOC_MMAP_MAX_,
/// MALLOC_TRIM_THRESHOLD_, MALLOC_TOP_PAD_, OPENBLAS_NUM_THREADS). Call it first, before torch
/// runs anything.
void tune_process_for_training();

}  // namespace pixelgym::ppo
