// Shaped rewards in [0, 1], as dm_control's suite uses them.
#pragma once

namespace pixelgym::reward {

/// How a reward falls off outside its bounds.
enum class Sigmoid { kGaussian, kQuadratic, kLinear };

/// 1 when `x` lies in [lower, upper]; outside, it falls with the distance d to the nearest bound
/// so that it equals `value_at_margin` at d = margin (and, for the gaussian, keeps falling; the
/// quadratic and linear reach 0 there and stay). margin = 0 gives a step.
double tolerance(double x, double lower, double upper, double margin = 0.0,
                 Sigmoid sigmoid = Sigmoid::kGaussian, double value_at_margin = 0.1);

}  // namespace pixelgym::reward
