#include "pixelgym/wrappers/area_resize.h"

// An AVX2 + FMA kernel, compiled for x86-64 with GCC or Clang (function target attributes) and
// chosen at run time when the CPU has both; elsewhere the portable (SSE2 or plain) one runs.
#if defined(__x86_64__) && defined(__GNUC__)
#define PIXELGYM_AREA_RESIZE_AVX2 1
#endif

#include <algorithm>
#if defined(__SSE__)
#include <emmintrin.h>
#endif
#if defined(PIXELGYM_AREA_RESIZE_AVX2)
#include <immintrin.h>
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

#if defined(PIXELGYM_AREA_RESIZE_AVX2)
// The AVX2 + FMA kernel, chosen at run time where the CPU has both (the build targets baseline
// x86-64). It works on blocks of 8 output rows held "row-major by element": block[k * 8 + r] is
// blended row r's element k. Rows are blended 8 elements at a time per row, then an 8 x 8
// transpose stores them by element; the column pass then computes one output element for all 8
// rows in one register (one broadcast weight and one load per tap, FMA), and a second transpose
// turns 8 such registers back into 8 bytes for each of the 8 rows. Every register lane does
// useful work, whatever the channel count.
__attribute__((target("avx2,fma"))) inline void transpose8(__m256 (&r)[8]) {
  const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]);
  const __m256 t1 = _mm256_unpackhi_ps(r[0], r[1]);
  const __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]);
  const __m256 t3 = _mm256_unpackhi_ps(r[2], r[3]);
  const __m256 t4 = _mm256_unpacklo_ps(r[4], r[5]);
  const __m256 t5 = _mm256_unpackhi_ps(r[4], r[5]);
  const __m256 t6 = _mm256_unpacklo_ps(r[6], r[7]);
  const __m256 t7 = _mm256_unpackhi_ps(r[6], r[7]);
  const __m256 s0 = _mm256_shuffle_ps(t0, t2, 0x44);
  const __m256 s1 = _mm256_shuffle_ps(t0, t2, 0xEE);
  const __m256 s2 = _mm256_shuffle_ps(t1, t3, 0x44);
  const __m256 s3 = _mm256_shuffle_ps(t1, t3, 0xEE);
  const __m256 s4 = _mm256_shuffle_ps(t4, t6, 0x44);
  const __m256 s5 = _mm256_shuffle_ps(t4, t6, 0xEE);
  const __m256 s6 = _mm256_shuffle_ps(t5, t7, 0x44);
  const __m256 s7 = _mm256_shuffle_ps(t5, t7, 0xEE);
  r[0] = _mm256_permute2f128_ps(s0, s4, 0x20);
  r[1] = _mm256_permute2f128_ps(s1, s5, 0x20);
  r[2] = _mm256_permute2f128_ps(s2, s6, 0x20);
  r[3] = _mm256_permute2f128_ps(s3, s7, 0x20);
  r[4] = _mm256_permute2f128_ps(s0, s4, 0x31);
  r[5] = _mm256_permute2f128_ps(s1, s5, 0x31);
  r[6] = _mm256_permute2f128_ps(s2, s6, 0x31);
  r[7] = _mm256_permute2f128_ps(s3, s7, 0x31);
}

__attribute__((target("avx2,fma"))) inline __m256 load8_bytes(const std::uint8_t* bytes) {
  return _mm256_cvtepi32_ps(
      _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(bytes))));
}

struct AxisView {
  int taps;
  const int* first;
  const float* weights;  // output index * taps + tap
};

// kRowTaps, kColumnTaps: the taps known at compile time (unrolled), or 0 for the run-time counts.
template <int kRowTaps, int kColumnTaps>
__attribute__((target("avx2,fma"))) void area_resize_avx2(
    const std::uint8_t* source, std::uint8_t* target, std::size_t row, int height, std::size_t n,
    AxisView rows, const int* element_first, const float* element_weights, int column_taps,
    int channels, float* block) {
  const int row_taps = kRowTaps > 0 ? kRowTaps : rows.taps;
  if (kColumnTaps > 0) column_taps = kColumnTaps;
  const std::size_t stride = static_cast<std::size_t>(channels) * 8;  // one source pixel in block
  for (int y0 = 0; y0 < height; y0 += 8) {
    // Rows past the last are computed as the last one and not stored.
    int ys[8];
    for (int r = 0; r < 8; ++r) ys[r] = std::min(y0 + r, height - 1);
    const int rows_here = std::min(8, height - y0);
    std::size_t k = 0;
    for (; k + 8 <= row; k += 8) {
      __m256 v[8];
      for (int r = 0; r < 8; ++r) {
        const float* w = rows.weights + static_cast<std::ptrdiff_t>(ys[r]) * row_taps;
        const std::uint8_t* in = source + static_cast<std::size_t>(rows.first[ys[r]]) * row + k;
        __m256 sum = _mm256_mul_ps(_mm256_set1_ps(w[0]), load8_bytes(in));
        for (int t = 1; t < row_taps; ++t) {
          sum = _mm256_fmadd_ps(_mm256_set1_ps(w[t]), load8_bytes(in + t * row), sum);
        }
        v[r] = sum;
      }
      transpose8(v);
      for (int j = 0; j < 8; ++j) _mm256_storeu_ps(block + (k + j) * 8, v[j]);
    }
    for (; k < row; ++k) {
      for (int r = 0; r < 8; ++r) {
        const float* w = rows.weights + static_cast<std::ptrdiff_t>(ys[r]) * row_taps;
        const std::uint8_t* in = source + static_cast<std::size_t>(rows.first[ys[r]]) * row + k;
        float sum = w[0] * in[0];
        for (int t = 1; t < row_taps; ++t) sum += w[t] * in[t * row];
        block[k * 8 + r] = sum;
      }
    }
    std::uint8_t* out = target + static_cast<std::size_t>(y0) * n;
    std::size_t e = 0;
    for (; e + 8 <= n; e += 8) {
      __m256 v[8];
      for (int j = 0; j < 8; ++j) {
        const float* from = block + static_cast<std::size_t>(element_first[e + j]) * 8;
        __m256 sum = _mm256_mul_ps(_mm256_set1_ps(element_weights[e + j]), _mm256_loadu_ps(from));
        for (int t = 1; t < column_taps; ++t) {
          sum = _mm256_fmadd_ps(_mm256_set1_ps(element_weights[t * n + e + j]),
                                _mm256_loadu_ps(from + t * stride), sum);
        }
        v[j] = sum;
      }
      transpose8(v);  // v[r]: row r's elements e .. e + 7
      for (int r = 0; r < rows_here; ++r) {
        const __m256i rounded = _mm256_cvtps_epi32(v[r]);  // nearest, ties to even
        const __m128i words =
            _mm_packs_epi32(_mm256_castsi256_si128(rounded), _mm256_extracti128_si256(rounded, 1));
        _mm_storel_epi64(reinterpret_cast<__m128i*>(out + r * n + e),
                         _mm_packus_epi16(words, words));
      }
    }
    for (; e < n; ++e) {
      const float* from = block + static_cast<std::size_t>(element_first[e]) * 8;
      for (int r = 0; r < rows_here; ++r) {
        float sum = element_weights[e] * from[r];
        for (int t = 1; t < column_taps; ++t) {
          sum += element_weights[t * n + e] * from[t * stride + r];
        }
        out[r * n + e] = to_uint8(sum);
      }
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

AreaResize::AreaResize(int source_height, int source_width, int height, int width, int channels,
                       bool allow_avx2)
    : source_width_(source_width), height_(height), width_(width), channels_(channels) {
#if defined(PIXELGYM_AREA_RESIZE_AVX2)
  __builtin_cpu_init();  // needed where this runs before main (a static AreaResize)
  use_avx2_ = allow_avx2 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  (void)allow_avx2;
#endif
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
  if (use_avx2_) {
    block_.resize(static_cast<std::size_t>(source_width) * static_cast<std::size_t>(channels) * 8);

    return;
  }
  // One float of padding: the 4-lane load of a 3-channel row's last pixel reads one past it.
  blended_.resize(static_cast<std::size_t>(height) * static_cast<std::size_t>(source_width) *
                      static_cast<std::size_t>(channels) +
                  1);
}

void AreaResize::operator()(const std::uint8_t* source, std::uint8_t* target) {
  const std::size_t row = static_cast<std::size_t>(source_width_) * channels_;
#if defined(PIXELGYM_AREA_RESIZE_AVX2)
  if (use_avx2_) {
    const auto kernel = rows_.taps == 3 && columns_.taps == 3   ? &area_resize_avx2<3, 3>
                        : rows_.taps == 2 && columns_.taps == 2 ? &area_resize_avx2<2, 2>
                        : rows_.taps == 3 && columns_.taps == 2 ? &area_resize_avx2<3, 2>
                        : rows_.taps == 2 && columns_.taps == 3 ? &area_resize_avx2<2, 3>
                                                                : &area_resize_avx2<0, 0>;
    kernel(source, target, row, height_, static_cast<std::size_t>(width_) * channels_,
           AxisView{rows_.taps, rows_.first.data(), rows_.weights.data()}, element_first_.data(),
           element_weights_.data(), columns_.taps, channels_, block_.data());
    return;
  }
#endif
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
