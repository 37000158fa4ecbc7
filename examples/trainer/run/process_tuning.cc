#include "pixelgym/trainer/process_tuning.h"

#include <dlfcn.h>
#include <malloc.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

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

double CpuAvailability::free_cores() const {
  const double elsewhere = std::max(0, online - cores);
  return std::clamp(static_cast<double>(cores) - std::max(0.0, load - elsewhere), 0.0,
                    static_cast<double>(cores));
}

CpuAvailability cpu_availability() {
  CpuAvailability cpus;
  cpu_set_t set;
  CPU_ZERO(&set);
  cpus.cores = sched_getaffinity(0, sizeof(set), &set) == 0 ? CPU_COUNT(&set) : 1;
  cpus.online = std::max(static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)), cpus.cores);
  const char* fake = std::getenv("PIXELGYM_LOADAVG");
  if (fake != nullptr) {
    char* end = nullptr;
    const double value = std::strtod(fake, &end);
    if (end != fake && std::isfinite(value) && value >= 0.0) {
      cpus.load = value;
      return cpus;
    }
  }
  std::ifstream("/proc/loadavg") >> cpus.load;
  return cpus;
}

std::string busy_cores_warning(int threads, bool given, const CpuAvailability& cpus) {
  const double free = cpus.free_cores();
  const int fit = std::max(1, static_cast<int>(std::lround(free)));
  if (threads <= fit) return "";
  std::ostringstream text;
  text.precision(1);
  text << std::fixed << "warning: torch_threads=" << threads
       << (given ? " (--torch-threads)" : " (the default: one per core)") << ", but about " << free
       << " of the " << cpus.cores << " cores this process may use are free (load average "
       << std::setprecision(2) << cpus.load << " over the last minute, " << cpus.online
       << " CPUs online): threads that wait for busy cores make every update slower, up to "
          "several times slower than one thread. Give --torch-threads "
       << fit
       << " (the free cores), or train when the machine is less busy; config.json records "
          "the count and a resume keeps it";
  return text.str();
}

}  // namespace pixelgym::trainer
