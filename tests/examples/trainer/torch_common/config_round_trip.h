// A check for an algorithm config's JSON form (to_json / from_json): each member, changed alone
// to another valid value, is written, read and written back as it was, so that none is written
// but not read. Shared by the DrQ and DrQ-v2 config tests.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace pixelgym::trainer::testing {

/// `parse` reads JSON into a Config (from_json). Integers go up by one, floats halve, bools
/// flip, the encoder's name changes, and a null (a target entropy's default) becomes -2.
template <typename Config, typename Parse>
void expect_every_member_round_trips(Parse parse) {
  nlohmann::json defaults;
  to_json(defaults, Config{});
  for (const auto& item : defaults.items()) {
    const std::string& key = item.key();
    const nlohmann::json& value = item.value();
    nlohmann::json changed = defaults;
    nlohmann::json& member = changed[key];
    if (value.is_boolean()) {
      member = !value.get<bool>();
    } else if (value.is_number_integer()) {
      member = value.get<std::int64_t>() + 1;
    } else if (value.is_number_float()) {
      member = value.get<double>() * 0.5;
    } else if (value.is_string()) {
      member = value.get<std::string>() == "drqv2" ? "fine" : "drqv2";
    } else {
      member = -2.0;
    }
    nlohmann::json back;
    to_json(back, parse(changed));
    EXPECT_EQ(back.at(key), member) << key;
  }
}

}  // namespace pixelgym::trainer::testing
