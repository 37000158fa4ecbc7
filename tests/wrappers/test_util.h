// Helpers shared by the image wrapper tests.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>

#include "pixelgym/envs/env.h"

namespace pixelgym::testing {

/// Runs `make` and expects std::invalid_argument whose message contains every one of `parts`.
inline void expect_invalid(const std::function<void()>& make,
                           std::initializer_list<std::string> parts) {
  try {
    make();
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& error) {
    for (const std::string& part : parts) EXPECT_THAT(error.what(), ::testing::HasSubstr(part));
  }
}

/// reset_into then one step_into through the buffer path; returns the step's observation.
inline Value reset_and_step(Env& env) {
  ResetResult reset;
  reset.obs = env.observation_space().zeros();
  env.reset_into(reset, /*seed=*/3);
  StepResult step;
  step.obs = env.observation_space().zeros();
  env.step_into(env.action_space().zeros(), step);
  return step.obs;
}

}  // namespace pixelgym::testing
