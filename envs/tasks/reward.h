// Shaped rewards in [0, 1], as dm_control's suite uses them.
#pragma once

namespace pixelgym::reward {

/// How a reward falls off outside its bounds, with s = d / margin (see `tolerance`) and v =
/// value_at_margin: kGaussian exp(-s^2 ln(1 / v)), never 0; kQuadratic 1 - (1 - v) s^2 and
/// kLinear 1 - (1 - v) s, each 0 from where it reaches 0 on.
enum class Sigmoid { kGaussian, kQuadratic, kLinear };

/// 1 when `x` lies in [lower, upper]; outside, it falls with the distance d to the nearest bound
/// so that it equals `value_at_margin` at d = margin and keeps falling beyond: the gaussian
/// towards 0, the quadratic to 0 at d = margin / sqrt(1 - value_at_margin) and the linear at
/// d = margin / (1 - value_at_margin), both 0 from there on. margin = 0 gives a step (0 outside).
/// `value_at_margin` should lie in (0, 1) for the gaussian and in [0, 1) for the others (not
/// checked). Throws std::invalid_argument when
/// lower > upper or margin < 0.
double tolerance(double x, double lower, double upper, double margin = 0.0,
                 Sigmoid sigmoid = Sigmoid::kGaussian, double value_at_margin = 0.1);

}  // namespace pixelgym::reward
