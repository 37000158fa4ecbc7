// RunningStatistics: the running mean and variance that NormalizeObservation and NormalizeReward
// keep (Gymnasium's RunningMeanStd), and their checkpoint form.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pixelgym/envs/value.h"

namespace pixelgym::wrappers {

/// Element-wise running mean and (population) variance of a stream of samples, as Gymnasium's
/// `RunningMeanStd`: it starts from mean 0, variance 1 and a pseudo-count of kInitialCount
/// (1e-4), and each sample x is merged in with the parallel-variance update of Chan et al.
/// (count' = count + 1, delta = x - mean, mean' = mean + delta / count',
/// var' = (var * count + delta^2 * count / count') / count'). After n samples the mean is
/// sum(x) / (n + 1e-4) and the variance that of the samples pooled with the prior, which differs
/// from the plain sample statistics by about 1e-4 / n relative.
struct RunningStatistics {
  /// The prior's pseudo-count (Gymnasium's epsilon of RunningMeanStd).
  static constexpr double kInitialCount = 1e-4;

  /// The running mean of each element.
  std::vector<double> mean;
  /// The running population variance of each element (same size as `mean`).
  std::vector<double> var;
  /// Samples merged so far plus kInitialCount.
  double count = kInitialCount;

  /// The starting statistics of `size` elements: mean 0, variance 1, count 1e-4.
  static RunningStatistics initial(std::size_t size);

  /// Merges one sample of mean.size() elements, given element by element as doubles by `sample`
  /// (called with 0 .. size-1). Allocates nothing.
  template <typename Sample>
  void update(const Sample& sample) {
    const double total = count + 1.0;
    for (std::size_t i = 0; i < mean.size(); ++i) {
      const double delta = sample(i) - mean[i];
      mean[i] += delta / total;
      var[i] = (var[i] * count + delta * delta * count / total) / total;
    }
    count = total;
  }

  /// Merges a batch of `rows` samples at once, as RunningMeanStd.update(x) with x of shape
  /// (rows, size): the batch's own mean and population variance, then the merge of Chan et al.
  /// (delta = batch_mean - mean, total = count + rows, mean' = mean + delta * rows / total,
  /// var' = (var * count + batch_var * rows + delta^2 * count * rows / total) / total). `sample`
  /// is called with (row, element), rows 0 .. rows-1 and elements 0 .. size-1, several times per
  /// entry. A batch of one row gives exactly (bit for bit) what `update` gives; a batch of n rows
  /// what n updates give up to rounding (finite samples). No rows: nothing changes. Allocates
  /// nothing.
  template <typename Batch>
  void update_batch(std::size_t rows, const Batch& sample) {
    if (rows == 0) return;
    const auto batch_count = static_cast<double>(rows);
    const double total = count + batch_count;
    for (std::size_t i = 0; i < mean.size(); ++i) {
      double sum = 0.0;
      for (std::size_t row = 0; row < rows; ++row) sum += sample(row, i);
      const double batch_mean = sum / batch_count;
      double squares = 0.0;
      for (std::size_t row = 0; row < rows; ++row) {
        const double deviation = sample(row, i) - batch_mean;
        squares += deviation * deviation;
      }
      const double batch_var = squares / batch_count;
      const double delta = batch_mean - mean[i];
      mean[i] += delta * batch_count / total;
      var[i] =
          (var[i] * count + batch_var * batch_count + delta * delta * count * batch_count / total) /
          total;
    }
    count = total;
  }

  /// Why these statistics cannot stand for `size` elements ("var[3] is -1, must be >= 0"), or ""
  /// when they can: mean and var of `size` entries, every entry finite, var >= 0, count finite
  /// and > 0.
  std::string invalid_reason(std::size_t size) const;

  /// The checkpoint form: Dict{"mean": float64 (size,), "var": float64 (size,), "count": float64
  /// ()}, exact (the doubles are stored as they are).
  Value to_value() const;
  /// The inverse of to_value. Throws std::invalid_argument naming `context` when `value` is not
  /// laid out so (keys, dtypes, shapes) or its statistics are invalid for `size` elements.
  static RunningStatistics from_value(const Value& value, std::size_t size,
                                      const std::string& context);
};

}  // namespace pixelgym::wrappers
