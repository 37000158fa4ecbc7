// The process settings CPU training runs with (pixelgym train and eval, ppo_bench), and how busy
// the machine's cores are.
#pragma once

#include <string>

namespace pixelgym::trainer {

/// Sets up the process for training on a CPU: glibc keeps freed memory in the process (no
/// mmap'd blocks, no trimming of the heap's top), and OpenBLAS runs on one thread (torch's
/// intra-op threads are the parallelism). Why, with the measurements: docs/design-notes.md,
/// Trainer. Not applied when the user set the corresponding environment variables
/// (MALLOC_MMAP_MAX_, MALLOC_TRIM_THRESHOLD_, MALLOC_TOP_PAD_, OPENBLAS_NUM_THREADS). Call it
/// first, before torch runs anything.
void tune_process_for_training();

/// The cores a process may compute on, and how busy the machine is.
struct CpuAvailability {
  int cores = 1;      // this process's CPUs (sched_getaffinity)
  int online = 1;     // the machine's CPUs online
  double load = 0.0;  // runnable tasks, averaged over the last minute (/proc/loadavg)
  /// The cores of this process left free by the load: cores - (load - (online - cores)),
  /// within [0, cores] (the load beyond the CPUs outside this process's set counts against it).
  double free_cores() const;
};

/// This process's cores and the machine's load. PIXELGYM_LOADAVG, when set to a number, stands
/// in for /proc/loadavg's first figure (tests fake a busy or an idle machine with it).
CpuAvailability cpu_availability();

/// "" when `threads` compute threads fit the free cores of `cpus` (at most max(1, free cores
/// rounded)); else a warning (one line, no newline) naming the threads, the cores, the load and
/// the free cores, and what to do. `given`: --torch-threads set them (else the default, one per
/// core).
std::string busy_cores_warning(int threads, bool given, const CpuAvailability& cpus);

}  // namespace pixelgym::trainer
