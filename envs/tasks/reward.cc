#include "pixelgym/envs/tasks/reward.h"

#include <cmath>
#include <stdexcept>

namespace pixelgym::reward {

double tolerance(double x, double lower, double upper, double margin, Sigmoid sigmoid,
                 double value_at_margin) {
  if (lower > upper || margin < 0)
    throw std::invalid_argument("tolerance: needs lower <= upper and margin >= 0");
  if (x >= lower && x <= upper) return 1.0;
  if (margin == 0.0) return 0.0;
  const double d = (x < lower ? lower - x : x - upper) / margin;
  switch (sigmoid) {
    case Sigmoid::kGaussian: {
      const double scale = std::sqrt(-2.0 * std::log(value_at_margin));
      return std::exp(-0.5 * (d * scale) * (d * scale));
    }
    case Sigmoid::kQuadratic: {
      const double scale = std::sqrt(1.0 - value_at_margin);
      const double v = 1.0 - (d * scale) * (d * scale);
      return v > 0.0 ? v : 0.0;
    }
    case Sigmoid::kLinear: {
      const double v = 1.0 - d * (1.0 - value_at_margin);
      return v > 0.0 ? v : 0.0;
    }
  }
  return 0.0;
}

}  // namespace pixelgym::reward
