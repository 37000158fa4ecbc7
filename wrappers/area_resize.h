// AreaResize: OpenCV's INTER_AREA shrink of a uint8 image, precomputed for one size pair, with no
// allocation per call and about 4.6x faster than cv::resize for non-integer factors.
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
/// its size pairs). With SSE2, rows blend 2 or 3 taps in one pass, and for 3 or 4 channels a
/// pixel's channels share one register in the column pass (one load per tap); one channel gathers
/// four output elements per register. Measured on this machine, 84x84x3 -> 64x64x3, CPU time per
/// call (perf stat task-clock over 100,000 calls, -O3): cv::resize 42.6 us, AreaResize 9.3 us.
class AreaResize {
 public:
  /// Requires 1 <= height <= source_height, 1 <= width <= source_width and channels >= 1.
  AreaResize(int source_height, int source_width, int height, int width, int channels);

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
  std::vector<float> blended_;  // height x (source_width * channels): rows blended, columns not
};

}  // namespace pixelgym::wrappers
