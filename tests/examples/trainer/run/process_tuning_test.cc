#include "pixelgym/trainer/process_tuning.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>

namespace pixelgym::trainer {
namespace {

using ::testing::HasSubstr;

// The cores left free: this process's cores less the load that the CPUs outside its set do not
// absorb, within [0, cores].
TEST(ProcessTuningTest, FreeCoresAreTheCoresTheLoadLeaves) {
  EXPECT_DOUBLE_EQ((CpuAvailability{8, 8, 0.0}.free_cores()), 8.0);
  EXPECT_DOUBLE_EQ((CpuAvailability{8, 8, 6.5}.free_cores()), 1.5);
  EXPECT_DOUBLE_EQ((CpuAvailability{8, 8, 20.0}.free_cores()), 0.0);
  // 4 of 16 CPUs: a load of 12 can run outside them.
  EXPECT_DOUBLE_EQ((CpuAvailability{4, 16, 12.0}.free_cores()), 4.0);
  EXPECT_DOUBLE_EQ((CpuAvailability{4, 16, 15.0}.free_cores()), 1.0);
}

// Threads above the free cores (at least one) are warned of, naming the threads, the cores, the
// load and the count to give; threads that fit are not.
TEST(ProcessTuningTest, ThreadsAboveTheFreeCoresAreWarnedOf) {
  const CpuAvailability busy{8, 8, 6.5};  // 1.5 free: 2 fit
  EXPECT_EQ(busy_cores_warning(2, false, busy), "");
  const std::string warning = busy_cores_warning(3, false, busy);
  EXPECT_THAT(warning, HasSubstr("warning: torch_threads=3 (the default: one per core), but about "
                                 "1.5 of the 8 cores this process may use are free (load average "
                                 "6.50 over the last minute, 8 CPUs online)"));
  EXPECT_THAT(warning, HasSubstr("Give --torch-threads 2 (the free cores)"));
  EXPECT_THAT(busy_cores_warning(8, true, busy), HasSubstr("torch_threads=8 (--torch-threads)"));
  // One thread is never too many.
  EXPECT_EQ(busy_cores_warning(1, true, CpuAvailability{2, 2, 50.0}), "");
  EXPECT_EQ(busy_cores_warning(8, false, CpuAvailability{8, 8, 0.2}), "");
}

// PIXELGYM_LOADAVG stands in for /proc/loadavg (a number only).
TEST(ProcessTuningTest, TheLoadCanBeFaked) {
  ::setenv("PIXELGYM_LOADAVG", "12.5", 1);
  EXPECT_DOUBLE_EQ(cpu_availability().load, 12.5);
  ::setenv("PIXELGYM_LOADAVG", "busy", 1);
  const CpuAvailability measured = cpu_availability();
  EXPECT_GE(measured.load, 0.0);
  EXPECT_NE(measured.load, 12.5);
  ::unsetenv("PIXELGYM_LOADAVG");
  EXPECT_GE(cpu_availability().cores, 1);
  EXPECT_GE(cpu_availability().online, cpu_availability().cores);
}

}  // namespace
}  // namespace pixelgym::trainer
