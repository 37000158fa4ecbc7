// Angle helpers shared by the tasks.
#pragma once

#include <cmath>

namespace pixelgym {

/// pi, as a double.
constexpr double kPi = 3.14159265358979323846;

/// `angle` wrapped into [-pi, pi).
inline double wrap_angle(double angle) {
  return angle - 2.0 * kPi * std::floor((angle + kPi) / (2.0 * kPi));
}

}  // namespace pixelgym
