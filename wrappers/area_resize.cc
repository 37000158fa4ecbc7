#include "wrappers/area_resize.h"

#include <algorithm>
#if defined(__SSE__)
#include <emmintrin.h>
#endif
#include <cmath>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>

namespace pixelgym::wrappers {
namespace {

// OpenCV's saturate_cast<uchar>(float): round to nearest, ties to even (cvRound), then clamp.
// std::lrint is a library call here; the SSE conversion rounds the same way (the default MXCSR
// mode) and is one instruction.
inline std::uint8_t to_uint8(float value) {
#if defined(__SSE__)
  const int rounded = _mm_cvt_ss2si(_mm_set_ss(value));
#else
  const long rounded = std::lrint(value);
#endif
  return static_cast<std::uint8_t>(rounded < 0 ? 0 : rounded > 255 ? 255 : rounded);
}

// One blended row's columns: out[i] = sum over taps j of weights[j * n + i] *
// in[from[i] + j * stride], for each output element i (kTaps known at compile time; 0 = `taps`).
// With SSE, four output elements at a time: their source values are gathered into one register
// per tap, multiplied and summed in four lanes, rounded as cvRound does, packed to bytes.
template <int kTaps>
void blend_columns(const float* __restrict in, const int* __restrict from,
                   const float* __restrict weights, int stride, int taps, std::size_t n,
                   std::uint8_t* __restrict out) {
  const int count = kTaps > 0 ? kTaps : taps;
  std::size_t i = 0;
#if defined(__SSE2__)
  for (; i + 4 <= n; i += 4) {
    const float* s0 = in + from[i];
    const float* s1 = in + from[i + 1];
    const float* s2 = in + from[i + 2];
    const float* s3 = in + from[i + 3];
    __m128 sum = _mm_mul_ps(_mm_loadu_ps(weights + i), _mm_setr_ps(*s0, *s1, *s2, *s3));
    for (int j = 1; j < count; ++j) {
      const int at = j * stride;
      sum = _mm_add_ps(sum, _mm_mul_ps(_mm_loadu_ps(weights + static_cast<std::size_t>(j) * n + i),
                                       _mm_setr_ps(s0[at], s1[at], s2[at], s3[at])));
    }
    const __m128i rounded = _mm_cvtps_epi32(sum);  // nearest, ties to even
    const __m128i bytes = _mm_packus_epi16(_mm_packs_epi32(rounded, rounded), rounded);
    const int packed = _mm_cvtsi128_si32(bytes);
    std::memcpy(out + i, &packed, 4);
  }
#endif
  for (; i < n; ++i) {
    const float* source = in + from[i];
    float sum = weights[i] * source[0];
    for (int j = 1; j < count; ++j)
      sum += weights[static_cast<std::size_t>(j) * n + i] * source[j * stride];
    out[i] = to_uint8(sum);
  }
}

}  // namespace

AreaResize::Axis AreaResize::axis(int source, int target) {
  // OpenCV's computeResizeAreaTab: output index d covers [d * scale, (d + 1) * scale).
  const double scale = static_cast<double>(source) / target;
  std::vector<std::vector<std::pair<int, float>>> taps(static_cast<std::size_t>(target));
  for (int d = 0; d < target; ++d) {
    auto& out = taps[static_cast<std::size_t>(d)];
    const double begin = d * scale;
    const double end = begin + scale;
    const double cell = std::min(scale, source - begin);
    int first = static_cast<int>(std::ceil(begin));
    int last = std::min(static_cast<int>(std::floor(end)), source - 1);
    first = std::min(first, last);
    if (first - begin > 1e-3)
      out.emplace_back(first - 1, static_cast<float>((first - begin) / cell));
    for (int s = first; s < last; ++s) out.emplace_back(s, static_cast<float>(1.0 / cell));
    if (end - last > 1e-3) {
      out.emplace_back(last, static_cast<float>(std::min(std::min(end - last, 1.0), cell) / cell));
    }
  }
  Axis axis;
  for (const auto& out : taps) axis.taps = std::max(axis.taps, static_cast<int>(out.size()));
  axis.first.resize(static_cast<std::size_t>(target));
  axis.weights.assign(static_cast<std::size_t>(target) * static_cast<std::size_t>(axis.taps), 0.0f);
  for (int d = 0; d < target; ++d) {
    const auto& out = taps[static_cast<std::size_t>(d)];
    // Every output reads `taps` consecutive sources; where that would run past the last source,
    // start earlier and put zero weights in front.
    const int first = std::min(out.front().first, source - axis.taps);
    axis.first[static_cast<std::size_t>(d)] = first;
    for (const auto& [s, weight] : out) {
      axis.weights[static_cast<std::size_t>(d * axis.taps + (s - first))] = weight;
    }
  }
  return axis;
}

AreaResize::AreaResize(int source_height, int source_width, int height, int width, int channels)
    : source_width_(source_width), height_(height), width_(width), channels_(channels) {
  if (height < 1 || width < 1 || height > source_height || width > source_width || channels < 1) {
    throw std::invalid_argument("AreaResize: expected a shrink to at least 1x1, got " +
                                std::to_string(source_height) + "x" + std::to_string(source_width) +
                                " -> " + std::to_string(height) + "x" + std::to_string(width) +
                                " with " + std::to_string(channels) + " channels");
  }
  rows_ = axis(source_height, height);
  columns_ = axis(source_width, width);
  // The column weights expanded per output element (x, c), so the column pass is one flat loop.
  // Weights by tap, then element: element_weights_[tap * (width * channels) + x * channels + c].
  const std::size_t elements = static_cast<std::size_t>(width) * channels;
  element_weights_.resize(elements * static_cast<std::size_t>(columns_.taps));
  for (int x = 0; x < width; ++x) {
    for (int c = 0; c < channels; ++c) {
      element_first_.push_back(columns_.first[static_cast<std::size_t>(x)] * channels + c);
      for (int tap = 0; tap < columns_.taps; ++tap) {
        element_weights_[static_cast<std::size_t>(tap) * elements +
                         static_cast<std::size_t>(x * channels + c)] =
            columns_.weights[static_cast<std::size_t>(x * columns_.taps + tap)];
      }
    }
  }
  blended_.resize(static_cast<std::size_t>(height) * static_cast<std::size_t>(source_width) *
                  static_cast<std::size_t>(channels));
}

void AreaResize::operator()(const std::uint8_t* source, std::uint8_t* target) {
  const std::size_t row = static_cast<std::size_t>(source_width_) * channels_;
  // Rows first: each output row is a weighted sum of `taps` consecutive source rows.
  for (int y = 0; y < height_; ++y) {
    float* __restrict out = blended_.data() + static_cast<std::size_t>(y) * row;
    const std::uint8_t* in = source + static_cast<std::size_t>(rows_.first[y]) * row;
    const float* weights = &rows_.weights[static_cast<std::size_t>(y * rows_.taps)];
    for (std::size_t i = 0; i < row; ++i) out[i] = weights[0] * in[i];
    for (int tap = 1; tap < rows_.taps; ++tap) {
      const std::uint8_t* __restrict next = in + static_cast<std::size_t>(tap) * row;
      const float weight = weights[tap];
      for (std::size_t i = 0; i < row; ++i) out[i] += weight * next[i];
    }
  }
  // Then columns, within each blended row.
  const std::size_t n = static_cast<std::size_t>(width_) * channels_;
  for (int y = 0; y < height_; ++y) {
    const float* in = blended_.data() + static_cast<std::size_t>(y) * row;
    std::uint8_t* out = target + static_cast<std::size_t>(y) * n;
    const int* from = element_first_.data();
    const float* weights = element_weights_.data();
    switch (columns_.taps) {
      case 1:
        blend_columns<1>(in, from, weights, channels_, 1, n, out);
        break;
      case 2:
        blend_columns<2>(in, from, weights, channels_, 2, n, out);
        break;
      case 3:
        blend_columns<3>(in, from, weights, channels_, 3, n, out);
        break;
      default:
        blend_columns<0>(in, from, weights, channels_, columns_.taps, n, out);
    }
  }
}

}  // namespace pixelgym::wrappers
