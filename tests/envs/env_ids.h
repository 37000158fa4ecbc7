// Tests parametrized over every registered env id (dm_control's suite_test pattern).
#pragma once

#include <gtest/gtest.h>

#include <string>

namespace pixelgym::testing {

/// The test name of an env id: "CartPoleSwingup-v0" -> "CartPoleSwingup_v0" (gtest names allow
/// no '-').
inline std::string env_id_test_name(const ::testing::TestParamInfo<std::string>& param_info) {
  std::string name = param_info.param;
  for (char& c : name) {
    if (c == '-') c = '_';
  }
  return name;
}

}  // namespace pixelgym::testing
