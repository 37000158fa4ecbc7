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

#if defined(__SSE2__)
// One blended row's columns for 3 or 4 channels: a pixel's channels in the lanes of one
// register, so each tap is one load of `channels` consecutive floats (the 4th lane of a 3-channel
// load reads the next pixel's red and is dropped; the row buffer has a float of padding), one
// multiply by the tap's weight and one add. Each pixel is stored as 4 bytes, the 4th of a
// 3-channel pixel overwritten by the next one; the row's last pixel as exactly `channels` bytes.
// kTaps: the taps known at compile time, or 0 for `taps`.
template <int kTaps>
void blend_pixel_columns(const float* __restrict in, const int* __restrict first,
                         const float* __restrict weights, int taps, int channels, int width,
                         std::uint8_t* __restrict out) {
  const int count = kTaps > 0 ? kTaps : taps;
  for (int x = 0; x < width; ++x) {
    const float* source = in + static_cast<std::ptrdiff_t>(first[x]) * channels;
    const float* w = weights + static_cast<std::ptrdiff_t>(x) * count;
    __m128 sum = _mm_mul_ps(_mm_set1_ps(w[0]), _mm_loadu_ps(source));
    for (int j = 1; j < count; ++j) {
      sum = _mm_add_ps(sum, _mm_mul_ps(_mm_set1_ps(w[j]), _mm_loadu_ps(source + j * channels)));
    }
    const __m128i rounded = _mm_cvtps_epi32(sum);  // nearest, ties to even
    const __m128i bytes = _mm_packus_epi16(_mm_packs_epi32(rounded, rounded), rounded);
    const int packed = _mm_cvtsi128_si32(bytes);
    std::uint8_t* pixel = out + static_cast<std::ptrdiff_t>(x) * channels;
    if (channels == 4 || x + 1 < width) {
      std::memcpy(pixel, &packed, 4);
    } else {
      std::memcpy(pixel, &packed, 3);
    }
  }
}
#endif

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
  // One float of padding: the 4-lane load of a 3-channel row's last pixel reads one past it.
  blended_.resize(static_cast<std::size_t>(height) * static_cast<std::size_t>(source_width) *
                      static_cast<std::size_t>(channels) +
                  1);
}

void AreaResize::operator()(const std::uint8_t* source, std::uint8_t* target) {
  const std::size_t row = static_cast<std::size_t>(source_width_) * channels_;
  // Rows first: each output row is a weighted sum of `taps` consecutive source rows.
  for (int y = 0; y < height_; ++y) {
    float* __restrict out = blended_.data() + static_cast<std::size_t>(y) * row;
    const std::uint8_t* in = source + static_cast<std::size_t>(rows_.first[y]) * row;
    const float* weights = &rows_.weights[static_cast<std::size_t>(y * rows_.taps)];
    // Two or three taps (shrinks by less than 2x) in one pass, one store per element.
    const float w0 = weights[0];
    if (rows_.taps == 2) {
      const float w1 = weights[1];
      const std::uint8_t* __restrict in1 = in + row;
      for (std::size_t i = 0; i < row; ++i) out[i] = w0 * in[i] + w1 * in1[i];
      continue;
    }
    if (rows_.taps == 3) {
      const float w1 = weights[1];
      const float w2 = weights[2];
      const std::uint8_t* __restrict in1 = in + row;
      const std::uint8_t* __restrict in2 = in + 2 * row;
      for (std::size_t i = 0; i < row; ++i) out[i] = w0 * in[i] + w1 * in1[i] + w2 * in2[i];
      continue;
    }
    for (std::size_t i = 0; i < row; ++i) out[i] = w0 * in[i];
    for (int tap = 1; tap < rows_.taps; ++tap) {
      const std::uint8_t* __restrict next = in + static_cast<std::size_t>(tap) * row;
      const float weight = weights[tap];
      for (std::size_t i = 0; i < row; ++i) out[i] += weight * next[i];
    }
  }
  // Then columns, within each blended row.
  const std::size_t n = static_cast<std::size_t>(width_) * channels_;
#if defined(__SSE2__)
  if (channels_ == 3 || channels_ == 4) {
    const auto pass = columns_.taps == 2   ? &blend_pixel_columns<2>
                      : columns_.taps == 3 ? &blend_pixel_columns<3>
                                           : &blend_pixel_columns<0>;
    for (int y = 0; y < height_; ++y) {
      pass(blended_.data() + static_cast<std::size_t>(y) * row, columns_.first.data(),
           columns_.weights.data(), columns_.taps, channels_, width_,
           target + static_cast<std::size_t>(y) * n);
    }
    return;
  }
#endif
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
