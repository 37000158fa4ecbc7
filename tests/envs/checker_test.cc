#include "pixelgym/envs/checker.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/envs/probe_env.h"

namespace pixelgym {
namespace {

using testing::Fault;
using testing::ProbeEnv;

std::vector<std::string> failed_names(const CheckReport& report) {
  std::vector<std::string> names;
  for (const CheckResult& result : report.failures()) names.push_back(result.name);
  return names;
}

TEST(CheckerTest, HealthyEnvPassesEveryCheck) {
  ProbeEnv env;
  const CheckReport report = check_env(env);
  EXPECT_TRUE(report.passed()) << ::testing::PrintToString(failed_names(report));
  EXPECT_EQ(report.results.size(), 12U);
  EXPECT_TRUE(env.closed());
}

struct FaultCase {
  Fault fault;
  std::string check;   // the check that must catch it
  std::string reason;  // a phrase its reason must contain
  friend void PrintTo(const FaultCase& c, std::ostream* out) { *out << c.check; }
};

class CheckerFaultTest : public ::testing::TestWithParam<FaultCase> {};

TEST_P(CheckerFaultTest, TheMatchingCheckFailsWithAReason) {
  ProbeEnv env(GetParam().fault);
  const CheckReport report = check_env(env);
  EXPECT_FALSE(report.passed());
  bool found = false;
  for (const CheckResult& result : report.failures()) {
    if (result.name == GetParam().check) {
      found = true;
      EXPECT_THAT(result.reason, ::testing::HasSubstr(GetParam().reason));
    }
  }
  EXPECT_TRUE(found) << "check " << GetParam().check
                     << " did not fail; failed: " << ::testing::PrintToString(failed_names(report));
}

INSTANTIATE_TEST_SUITE_P(
    EveryCheck, CheckerFaultTest,
    ::testing::Values(
        FaultCase{Fault::kObservationSpaceSamplesOutside, "observation_space",
                  "not in its own space"},
        FaultCase{Fault::kActionSpaceSamplesOutside, "action_space", "not in its own space"},
        FaultCase{Fault::kResetObservationWrongDtype, "reset", "dtype float64, expected float32"},
        FaultCase{Fault::kResetIgnoresSeed, "reset_seed", "twice gave"},
        FaultCase{Fault::kUnseededResetReseeds, "reset_unseeded", "not reseed it"},
        FaultCase{Fault::kNanReward, "step", "is not finite"},
        FaultCase{Fault::kStepObservationOutside, "step", "is outside [-10.0, 10.0]"},
        FaultCase{Fault::kNondeterministicStep, "step_determinism", "observations differ"},
        FaultCase{Fault::kAliasedObservation, "observation_aliasing", "share memory"},
        FaultCase{Fault::kReplacesBuffer, "buffer_path", "instead of writing into them"},
        FaultCase{Fault::kBadRender, "render", "(8, 8, 4)"},
        FaultCase{Fault::kZeroRenderFps, "metadata", "render_fps must be > 0, got 0"},
        FaultCase{Fault::kCloseThrows, "close", "close failed"}),
    [](const ::testing::TestParamInfo<FaultCase>& param_info) {
      return std::to_string(param_info.index) + "_" + param_info.param.check;
    });

TEST(CheckerTest, ReportsEveryFailureNotOnlyTheFirst) {
  // Nondeterministic steps break both determinism checks of resets and steps at once.
  ProbeEnv env(Fault::kResetIgnoresSeed);
  const std::vector<std::string> failed = failed_names(check_env(env));
  EXPECT_THAT(failed,
              ::testing::IsSupersetOf({"reset_seed", "reset_unseeded", "step_determinism"}));
}

}  // namespace
}  // namespace pixelgym
