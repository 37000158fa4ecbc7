// AreaResize: OpenCV's INTER_AREA shrink of a uint8 image, precomputed for one size pair, with no
// allocation per call, and faster than cv::resize for non-integer factors.
#pragma once

#include <cstdint>
#include <vector>

namespace pixelgym::wrappers {

/// Shrinks (H, W, C) uint8 images to (h, w, C) by area averaging: each output pixel is the mean
/// of the source area it covers, source pixels cut by its edges weighted by the part inside —
/// OpenCV's INTER_AREA, with OpenCV's own per-axis weights (computeResizeAreaTab's 1e-3 rule for
/// slivers included).
///
/// Why not cv::resize: for a non-integer factor (84 -> 64) OpenCV sums each source row
/// horizontally first, scattering 2-3 weighted taps per output channel over all H source rows,
/// then blends rows; it also builds its weight tables and a buffer on every call. Here the tables
/// and buffers are built once, and the rows are blended first (h output rows, contiguous and
/// vectorized), so the scattered horizontal pass runs over h rows instead of H. The sums are the
/// same but in another order, so a value can differ from OpenCV's by one level where a float sum
/// lands on .5 (tests/wrappers/area_resize_test.cc measures how often: 16 of 217,040 elements over
/// its size pairs; 50 with the AVX2 kernel, whose FMAs round once where a multiply and an add
/// round twice). Two kernels, chosen at construction:
///  - AVX2 + FMA where the CPU has them (checked at run time; the build targets baseline x86-64):
///    blocks of 8 output rows kept element by element, so each register holds one output element
///    of 8 rows whatever the channel count, 8 x 8 transposes in and out, taps unrolled for the
///    common 2 and 3.
///  - portable (SSE2 on x86-64): rows blend 2 or 3 taps in one pass; for 3 or 4 channels a
///    pixel's channels share one register in the column pass; one channel gathers four output
///    elements per register.
/// The two can differ by one level on a few elements, so pixels are identical on one machine, not
/// across CPUs with and without AVX2. Speeds: docs/design-notes.md, "Wrappers".
class AreaResize {
 public:
  /// Requires 1 <= height <= source_height, 1 <= width <= source_width and channels >= 1, else
  /// throws std::invalid_argument. `allow_avx2` false keeps to the portable kernel (for tests
  /// comparing the two).
  AreaResize(int source_height, int source_width, int height, int width, int channels,
             bool allow_avx2 = true);

  /// True when the AVX2 + FMA kernel runs (the CPU has both, and it was allowed).
  bool uses_avx2() const { return use_avx2_; }

  /// Writes the shrunk `source` (source_height x source_width x channels, row-major) to
  /// `target` (height x width x channels). Allocates nothing.
  void operator()(const std::uint8_t* source, std::uint8_t* target);

 private:
  // Per output index along one axis: the first source index and `taps` weights (zero-padded).
  struct Axis {
    int taps = 0;
    std::vector<int> first;
    std::vector<float> weights;  // output index * taps + tap
  };
  static Axis axis(int source, int target);

  int source_width_;
  int height_;
  int width_;
  int channels_;
  Axis rows_;
  Axis columns_;
  std::vector<int> element_first_;      // per output element of a row: its first source element
  std::vector<float> element_weights_;  // per output element of a row: its column weights
  bool use_avx2_ = false;
  std::vector<float> block_;    // AVX2: 8 rows blended, element by element (k * 8 + row)
  std::vector<float> blended_;  // height x (source_width * channels): rows blended, columns not
};

}  // namespace pixelgym::wrappers
