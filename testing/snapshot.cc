#include "pixelgym/testing/snapshot.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace pixelgym::testing {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kLabelMask = 0xFFFFFFU;
// Odd, so invertible modulo 2^24; spreads neighbouring labels over the colour cube.
constexpr std::uint32_t kLabelMultiplier = 0x9E3779U;

constexpr std::uint32_t label_inverse() {
  std::uint32_t inverse = kLabelMultiplier;  // Newton: each step doubles the correct low bits
  for (int i = 0; i < 5; ++i) inverse *= 2U - kLabelMultiplier * inverse;
  return inverse & kLabelMask;
}
static_assert(((label_inverse() * kLabelMultiplier) & kLabelMask) == 1U);

std::size_t pixel_count(int height, int width) {
  return static_cast<std::size_t>(height) * static_cast<std::size_t>(width);
}

// The comparison both kinds share. `off(p)`: pixel p differs; `found(a_is_actual, p, q)`: pixel p
// of one image is matched by pixel q of the other. Marks the diff image: red for thick windows,
// blue for displaced pixels (its other pixels are set by the caller).
template <typename Off, typename Found>
void count_thick_and_displaced(int height, int width, const Off& off, const Found& found,
                               ImageDifference& result) {
  const auto index = [width](int row, int col) {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(col);
  };
  for (int row = 0; row + 1 < height; ++row) {
    for (int col = 0; col + 1 < width; ++col) {
      const std::size_t window[4] = {index(row, col), index(row, col + 1), index(row + 1, col),
                                     index(row + 1, col + 1)};
      if (!(off[window[0]] && off[window[1]] && off[window[2]] && off[window[3]])) continue;
      ++result.figures.thick_windows;
      for (std::size_t p : window) {
        result.diff_rgb[p * 3] = 255;
        result.diff_rgb[p * 3 + 1] = 0;
      }
    }
  }
  // Whether pixel (row, col) of one image has a match in the other's 3 x 3 neighbourhood.
  const auto found_near = [&](bool from_actual, int row, int col) {
    for (int r = std::max(0, row - 1); r <= std::min(height - 1, row + 1); ++r) {
      for (int c = std::max(0, col - 1); c <= std::min(width - 1, col + 1); ++c) {
        if (found(from_actual, index(row, col), index(r, c))) return true;
      }
    }
    return false;
  };
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const std::size_t p = index(row, col);
      if (!off[p]) continue;  // the same place matches
      if (found_near(true, row, col) && found_near(false, row, col)) continue;
      ++result.figures.displaced_pixels;
      result.diff_rgb[p * 3 + 1] = 0;
      result.diff_rgb[p * 3 + 2] = 255;
    }
  }
}

int max_displaced(double fraction, std::int64_t pixels) {
  return static_cast<int>(fraction * static_cast<double>(pixels));
}

std::string size_text(int height, int width, int channels) {
  std::string text = std::to_string(width) + "x" + std::to_string(height);
  if (channels == 1) text += " gray";
  if (channels == 4) text += " RGBA";
  if (channels != 1 && channels != 3 && channels != 4)
    text += " with " + std::to_string(channels) + " channels";
  return text;
}

bool update_requested(const SnapshotOptions& options) {
  switch (options.update) {
    case SnapshotOptions::Update::kAlways:
      return true;
    case SnapshotOptions::Update::kNever:
      return false;
    case SnapshotOptions::Update::kFromEnvironment:
      break;
  }
  const char* update = std::getenv("PIXELGYM_UPDATE_GOLDENS");
  return update != nullptr && std::string(update) == "1";
}

fs::path output_dir(const SnapshotOptions& options) {
  if (!options.output_dir.empty()) return fs::absolute(options.output_dir);
  const char* dir = std::getenv("PIXELGYM_SNAPSHOT_OUTPUT_DIR");
  if (dir != nullptr && *dir != '\0') return fs::absolute(dir);
  return fs::absolute("snapshot_output");
}

// Writes `image` as <output dir>/<golden stem><suffix>; returns the path.
std::string write_output(const SnapshotOptions& options, const std::string& golden_path,
                         const std::string& suffix, const render::ImageView& image) {
  const fs::path dir = output_dir(options);
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) {
    throw std::runtime_error("compare_to_golden: cannot create the output folder " + dir.string() +
                             ": " + error.message());
  }
  const std::string path = (dir / (fs::path(golden_path).stem().string() + suffix)).string();
  render::write_png(path, image);
  return path;
}

void write_golden(const std::string& golden_path, const render::ImageView& image) {
  const fs::path parent = fs::path(golden_path).parent_path();
  if (!parent.empty()) {
    std::error_code error;
    fs::create_directories(parent, error);
    if (error) {
      throw std::runtime_error("compare_to_golden: cannot create the golden's folder " +
                               parent.string() + ": " + error.message());
    }
  }
  render::write_png(golden_path, image);
}

// What both compare_to_golden and compare_segmentation_to_golden do before comparing: update,
// or read the golden and check its size. Returns true when the caller should compare `golden`.
bool prepare(SnapshotResult& result, const render::ImageView& stored,
             const SnapshotOptions& options, render::Image& golden) {
  result.height = stored.height;
  result.width = stored.width;
  if (update_requested(options)) {
    write_golden(result.golden_path, stored);
    result.status = SnapshotResult::Status::kUpdated;
    return false;
  }
  std::error_code error;
  if (!fs::exists(result.golden_path, error)) {
    result.status = SnapshotResult::Status::kMissingGolden;
    result.actual_path = write_output(options, result.golden_path, ".actual.png", stored);
    return false;
  }
  try {
    golden = render::read_png(result.golden_path);
  } catch (const std::runtime_error& read_error) {
    result.status = SnapshotResult::Status::kUnreadableGolden;
    result.reason = read_error.what();
    result.actual_path = write_output(options, result.golden_path, ".actual.png", stored);
    return false;
  }
  result.golden_height = golden.height;
  result.golden_width = golden.width;
  result.golden_channels = golden.channels;
  if (golden.height != stored.height || golden.width != stored.width || golden.channels != 3) {
    result.status = SnapshotResult::Status::kSizeMismatch;
    result.actual_path = write_output(options, result.golden_path, ".actual.png", stored);
    return false;
  }
  return true;
}

std::string fixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

std::string percent(double share) { return fixed(share * 100.0, 2) + " %"; }

}  // namespace

SnapshotTolerance SnapshotTolerance::exact() {
  SnapshotTolerance tolerance;
  tolerance.off_by = 0;
  tolerance.max_thick_windows = 0;
  tolerance.neighbour_tolerance = 0;
  tolerance.max_displaced_fraction = 0.0;
  tolerance.max_clipped_mean = 0.0;
  tolerance.max_mean_difference = 0.0;
  tolerance.max_off_fraction = 0.0;
  return tolerance;
}

SegmentationTolerance SegmentationTolerance::exact() {
  SegmentationTolerance tolerance;
  tolerance.max_thick_windows = 0;
  tolerance.max_displaced_fraction = 0.0;
  tolerance.max_disagreement = 0.0;
  return tolerance;
}

ImageDifference difference(const render::ImageView& actual, const render::ImageView& expected,
                           const SnapshotTolerance& tolerance) {
  if (actual.pixels == nullptr || expected.pixels == nullptr || actual.channels != 3 ||
      expected.channels != 3 || actual.height != expected.height ||
      actual.width != expected.width || actual.height <= 0 || actual.width <= 0) {
    throw std::invalid_argument("testing::difference: expected two RGB images of one size, got " +
                                size_text(actual.height, actual.width, actual.channels) + " and " +
                                size_text(expected.height, expected.width, expected.channels));
  }
  const std::uint8_t* a = actual.pixels;
  const std::uint8_t* b = expected.pixels;
  const auto distance = [](const std::uint8_t* x, std::size_t p, const std::uint8_t* y,
                           std::size_t q) {
    int worst = 0;
    for (std::size_t c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(x[p * 3 + c] - y[q * 3 + c]));
    return worst;
  };
  const std::size_t pixels = pixel_count(actual.height, actual.width);
  ImageDifference result;
  result.diff_rgb.resize(pixels * 3);
  std::vector<char> off(pixels);
  double clipped_total = 0.0;
  double total = 0.0;
  for (std::size_t p = 0; p < pixels; ++p) {
    for (std::size_t c = 0; c < 3; ++c) {
      const int d = std::abs(a[p * 3 + c] - b[p * 3 + c]);
      clipped_total += std::min(d, tolerance.off_by);
      total += d;
    }
    const int worst = distance(a, p, b, p);
    off[p] = worst > tolerance.off_by ? 1 : 0;
    result.figures.off_pixels += off[p];
    const auto grey = static_cast<std::uint8_t>(std::min(255, worst * 8));
    for (std::size_t c = 0; c < 3; ++c) result.diff_rgb[p * 3 + c] = grey;
  }
  const auto channels = static_cast<double>(pixels * 3);
  result.figures.clipped_mean = clipped_total / channels;
  result.figures.mean_difference = total / channels;
  result.figures.off_fraction =
      static_cast<double>(result.figures.off_pixels) / static_cast<double>(pixels);
  const auto found = [&](bool from_actual, std::size_t p, std::size_t q) {
    return from_actual ? distance(a, p, b, q) <= tolerance.neighbour_tolerance
                       : distance(b, p, a, q) <= tolerance.neighbour_tolerance;
  };
  count_thick_and_displaced(actual.height, actual.width, off, found, result);
  return result;
}

ImageDifference segmentation_difference(const std::int32_t* actual, const std::int32_t* expected,
                                        int height, int width) {
  if (actual == nullptr || expected == nullptr || height <= 0 || width <= 0) {
    throw std::invalid_argument("testing::segmentation_difference: expected two label images of " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
  const std::size_t pixels = pixel_count(height, width);
  ImageDifference result;
  // Agreeing pixels: their label's colour, dimmed to a quarter; disagreeing ones light grey.
  result.diff_rgb = encode_labels(expected, pixels);
  std::vector<char> off(pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    off[p] = actual[p] != expected[p] ? 1 : 0;
    result.figures.off_pixels += off[p];
    for (std::size_t c = 0; c < 3; ++c) {
      std::uint8_t& v = result.diff_rgb[p * 3 + c];
      v = off[p] ? 200 : static_cast<std::uint8_t>(v / 4);
    }
  }
  result.figures.off_fraction =
      static_cast<double>(result.figures.off_pixels) / static_cast<double>(pixels);
  const auto found = [&](bool from_actual, std::size_t p, std::size_t q) {
    return from_actual ? actual[p] == expected[q] : expected[p] == actual[q];
  };
  count_thick_and_displaced(height, width, off, found, result);
  return result;
}

bool within(const SnapshotFigures& figures, std::int64_t pixels,
            const SnapshotTolerance& tolerance) {
  return figures.thick_windows <= tolerance.max_thick_windows &&
         figures.displaced_pixels <= max_displaced(tolerance.max_displaced_fraction, pixels) &&
         figures.clipped_mean <= tolerance.max_clipped_mean &&
         figures.mean_difference <= tolerance.max_mean_difference &&
         figures.off_fraction <= tolerance.max_off_fraction;
}

bool within(const SnapshotFigures& figures, std::int64_t pixels,
            const SegmentationTolerance& tolerance) {
  return figures.thick_windows <= tolerance.max_thick_windows &&
         figures.displaced_pixels <= max_displaced(tolerance.max_displaced_fraction, pixels) &&
         figures.off_fraction <= tolerance.max_disagreement;
}

std::vector<std::uint8_t> encode_labels(const std::int32_t* labels, std::size_t count) {
  std::vector<std::uint8_t> rgb(count * 3);
  for (std::size_t p = 0; p < count; ++p) {
    const std::int32_t label = labels[p];
    if (label < -1 || label > static_cast<std::int32_t>(kLabelMask) - 1) {
      throw std::invalid_argument("testing::encode_labels: expected labels from -1 to " +
                                  std::to_string(kLabelMask - 1) + ", got " +
                                  std::to_string(label) + " at pixel " + std::to_string(p));
    }
    const std::uint32_t code =
        (static_cast<std::uint32_t>(label + 1) * kLabelMultiplier) & kLabelMask;
    rgb[p * 3] = static_cast<std::uint8_t>(code >> 16);
    rgb[p * 3 + 1] = static_cast<std::uint8_t>(code >> 8);
    rgb[p * 3 + 2] = static_cast<std::uint8_t>(code);
  }
  return rgb;
}

std::vector<std::int32_t> decode_labels(const std::uint8_t* rgb, std::size_t count) {
  std::vector<std::int32_t> labels(count);
  for (std::size_t p = 0; p < count; ++p) {
    const std::uint32_t code = (static_cast<std::uint32_t>(rgb[p * 3]) << 16) |
                               (static_cast<std::uint32_t>(rgb[p * 3 + 1]) << 8) | rgb[p * 3 + 2];
    labels[p] = static_cast<std::int32_t>((code * label_inverse()) & kLabelMask) - 1;
  }
  return labels;
}

SnapshotResult compare_to_golden(const Array& frame, const std::string& golden_path,
                                 const SnapshotTolerance& tolerance,
                                 const SnapshotOptions& options) {
  if (frame.dtype() != DType::kUInt8 || frame.ndim() != 3 || frame.shape()[2] != 3 ||
      frame.shape()[0] <= 0 || frame.shape()[1] <= 0) {
    throw std::invalid_argument("compare_to_golden: expected an (H, W, 3) uint8 frame, got " +
                                frame.to_string());
  }
  return compare_to_golden(
      render::ImageView{frame.data<std::uint8_t>(), static_cast<int>(frame.shape()[0]),
                        static_cast<int>(frame.shape()[1]), 3},
      golden_path, tolerance, options);
}

SnapshotResult compare_to_golden(const render::ImageView& frame, const std::string& golden_path,
                                 const SnapshotTolerance& tolerance,
                                 const SnapshotOptions& options) {
  if (frame.pixels == nullptr || frame.channels != 3 || frame.height <= 0 || frame.width <= 0) {
    throw std::invalid_argument("compare_to_golden: expected a non-empty RGB frame, got " +
                                size_text(frame.height, frame.width, frame.channels));
  }
  SnapshotResult result;
  result.golden_path = golden_path;
  result.tolerance = tolerance;
  render::Image golden;
  if (!prepare(result, frame, options, golden)) return result;
  const ImageDifference diff = difference(frame, golden.view(), tolerance);
  result.figures = diff.figures;
  if (within(diff.figures, static_cast<std::int64_t>(pixel_count(frame.height, frame.width)),
             tolerance)) {
    result.status = SnapshotResult::Status::kMatched;
    return result;
  }
  result.status = SnapshotResult::Status::kDiffered;
  result.actual_path = write_output(options, golden_path, ".actual.png", frame);
  result.diff_path = write_output(options, golden_path, ".diff.png",
                                  {diff.diff_rgb.data(), frame.height, frame.width, 3});
  return result;
}

SnapshotResult compare_segmentation_to_golden(const Array& labels, const std::string& golden_path,
                                              const SegmentationTolerance& tolerance,
                                              const SnapshotOptions& options) {
  const Shape& shape = labels.shape();
  if (labels.dtype() != DType::kInt32 ||
      !(labels.ndim() == 2 || (labels.ndim() == 3 && shape[2] == 1))) {
    throw std::invalid_argument(
        "compare_segmentation_to_golden: expected an (H, W) or (H, W, 1) int32 frame, got " +
        labels.to_string());
  }
  return compare_segmentation_to_golden(labels.data<std::int32_t>(), static_cast<int>(shape[0]),
                                        static_cast<int>(shape[1]), golden_path, tolerance,
                                        options);
}

SnapshotResult compare_segmentation_to_golden(const std::int32_t* labels, int height, int width,
                                              const std::string& golden_path,
                                              const SegmentationTolerance& tolerance,
                                              const SnapshotOptions& options) {
  if (labels == nullptr || height <= 0 || width <= 0) {
    throw std::invalid_argument(
        "compare_segmentation_to_golden: expected a non-empty label image, got " +
        std::to_string(width) + "x" + std::to_string(height));
  }
  const std::size_t pixels = pixel_count(height, width);
  const std::vector<std::uint8_t> encoded = encode_labels(labels, pixels);
  SnapshotResult result;
  result.segmentation = true;
  result.golden_path = golden_path;
  result.segmentation_tolerance = tolerance;
  render::Image golden;
  if (!prepare(result, {encoded.data(), height, width, 3}, options, golden)) return result;
  const std::vector<std::int32_t> expected = decode_labels(golden.pixels.data(), pixels);
  const ImageDifference diff = segmentation_difference(labels, expected.data(), height, width);
  result.figures = diff.figures;
  if (within(diff.figures, static_cast<std::int64_t>(pixels), tolerance)) {
    result.status = SnapshotResult::Status::kMatched;
    return result;
  }
  result.status = SnapshotResult::Status::kDiffered;
  result.actual_path =
      write_output(options, golden_path, ".actual.png", {encoded.data(), height, width, 3});
  result.diff_path =
      write_output(options, golden_path, ".diff.png", {diff.diff_rgb.data(), height, width, 3});
  return result;
}

std::string SnapshotResult::message() const {
  const std::string kind = segmentation ? "segmentation frame" : "frame";
  const std::string frame_size = size_text(height, width, 3);
  const std::string update_hint =
      "PIXELGYM_UPDATE_GOLDENS=1 (or SnapshotOptions::update = kAlways) writes it from the " +
      kind + "; look at the PNG before committing it";
  const auto pixels = static_cast<std::int64_t>(pixel_count(height, width));
  std::ostringstream out;
  const auto figures_text = [&] {
    std::ostringstream text;
    if (segmentation) {
      const SegmentationTolerance& t = segmentation_tolerance;
      text << figures.thick_windows << " 2x2 windows of differing labels (limit "
           << t.max_thick_windows << "), " << figures.displaced_pixels
           << " pixels whose label is absent from the other image's 3x3 neighbourhood (limit "
           << max_displaced(t.max_displaced_fraction, pixels) << "), " << figures.off_pixels
           << " pixels with another label, " << percent(figures.off_fraction) << " (limit "
           << percent(t.max_disagreement) << ")";
      return text.str();
    }
    const SnapshotTolerance& t = tolerance;
    text << figures.thick_windows << " 2x2 windows of pixels off by more than " << t.off_by
         << " (limit " << t.max_thick_windows << "), " << figures.displaced_pixels
         << " pixels with no match within " << t.neighbour_tolerance
         << " in the other image's 3x3 neighbourhood (limit "
         << max_displaced(t.max_displaced_fraction, pixels) << "), mean difference "
         << fixed(figures.clipped_mean, 3) << " with each channel clipped at " << t.off_by
         << " (limit " << t.max_clipped_mean << "); mean absolute difference "
         << fixed(figures.mean_difference, 3);
    if (std::isfinite(t.max_mean_difference)) text << " (limit " << t.max_mean_difference << ")";
    text << ", " << figures.off_pixels << " pixels (" << percent(figures.off_fraction)
         << ") off by more than " << t.off_by;
    if (t.max_off_fraction < 1.0) text << " (limit " << percent(t.max_off_fraction) << ")";
    return text.str();
  };
  switch (status) {
    case Status::kMatched:
      out << golden_path << ": the " << kind << " matches (" << figures_text() << ")";
      break;
    case Status::kUpdated:
      out << "wrote golden " << golden_path << " from the " << kind << " (" << frame_size
          << "): look at it before committing it";
      break;
    case Status::kMissingGolden:
      out << "no golden " << golden_path << "; the " << kind << " (" << frame_size << ") is in "
          << actual_path << ". " << update_hint << ".";
      break;
    case Status::kUnreadableGolden:
      out << "golden " << golden_path << " cannot be read (" << reason << "); the " << kind
          << " is in " << actual_path << ". " << update_hint << ".";
      break;
    case Status::kSizeMismatch:
      out << "golden " << golden_path << " is "
          << size_text(golden_height, golden_width, golden_channels) << ", the " << kind << " "
          << frame_size << ": expected the same size (the " << kind << " is in " << actual_path
          << "; if the new size is intended, " << update_hint << ")";
      break;
    case Status::kDiffered:
      out << "the " << kind << " differs from golden " << golden_path << ": " << figures_text()
          << ". Actual: " << actual_path << "; diff: " << diff_path
          << (segmentation ? " (agreeing labels dimmed, other labels light grey, "
                           : " (grey |difference| x 8, ")
          << "red 2x2 windows all off, blue displaced pixels). If the change is intended, "
          << update_hint << ".";
      break;
  }
  return out.str();
}

}  // namespace pixelgym::testing
