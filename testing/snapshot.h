// Snapshot (golden-image) tests: compare a rendered frame with a PNG kept in the repository, the
// way pixelgym's own tests check every env's first observation. No GoogleTest here; the
// GoogleTest adapter (EXPECT_MATCHES_GOLDEN) is testing/gtest.h.
//
//   const testing::SnapshotResult result =
//       testing::compare_to_golden(env->render(), "tests/golden/cartpole.png");
//   if (!result) std::cerr << result.message() << "\n";  // the figures, the actual and diff PNGs
//
// Goldens are (re)written instead of compared when PIXELGYM_UPDATE_GOLDENS=1 is set (or with
// SnapshotOptions::update); look at each PNG before committing it. On a failed comparison the
// frame and a diff image are written to the output folder: SnapshotOptions::output_dir, else
// $PIXELGYM_SNAPSHOT_OUTPUT_DIR, else `snapshot_output/` in the current folder (ctest runs a test
// in its build folder, so CI finds them there), as <golden name>.actual.png and .diff.png.
//
// THE DEFAULT TOLERANCE (SnapshotTolerance{}), which pixelgym's own golden tests use.
//
// On one machine and Mesa build frames are identical bytes. The criterion must still admit
// another Mesa build, whose differences are of two kinds: shading rounded a level or two apart,
// and edges rasterized one pixel over (a pixel centre that falls on the other side of an edge) —
// for a straight edge that can be a whole row, such as the horizon. It must not admit a moved
// object: at 84 x 84 a pole or a link is one or two pixels wide and moves a few pixels for a few
// hundredths of a radian. A frame passes when all three hold ("off" means some channel differs by
// more than `off_by`, 8):
//
//  1. Thick changes: at most 4 windows of 2 x 2 pixels that are all off. A rasterization
//     difference moves an edge by at most one pixel, which changes a line one pixel wide. An
//     object moved by two pixels or more, or a one-pixel-wide part (a pole or a link at 84 x 84)
//     moved by one, changes a band at least two pixels wide (old and new place side by side).
//  2. Displaced pixels: at most 0.2 % of the pixels (14 at 84 x 84) whose colour appears nowhere
//     in the other image's 3 x 3 neighbourhood of the same place, within 32 per channel, looked
//     for both ways. An edge one pixel over finds its colour next door; an object somewhere else
//     (a thin pole flipped upright, where the thick test sees two separate one-pixel lines) does
//     not.
//  3. Shading: the mean absolute difference over all channels, each clipped at 8, at most 1.5 —
//     every channel a level apart passes (with edges one pixel over, up to about 1.1); a light
//     or colour changed by two levels everywhere does not. (Clipping keeps the few edge pixels
//     that flip between sky and floor, off by up to 120, from counting as a shading change: the
//     unclipped mean was the old criterion, and one horizon row moved by softpipe put it at 1.4.)
//
// What it admits: any edge one pixel over — so a wide object moved by about a pixel, whose edges
// each move by one, passes (the cart body moved 0.05 m, one pixel, changes only a one-pixel column
// at each side; the cart-pole frame fails because the pole on it, one pixel wide, moves too);
// shading within about a level everywhere; a few isolated pixels.
//
// How the criterion was chosen (softpipe against llvmpipe, planted mutants): docs/design-notes.md,
// "Snapshot tests".
//
// The diff image: grey is |difference| x 8, red marks the 2 x 2 windows all off, blue the
// displaced pixels (magenta both).
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "pixelgym/envs/array.h"
#include "pixelgym/render/image_io.h"

namespace pixelgym::testing {

/// When a frame matches a colour golden; the defaults are the criterion documented above.
struct SnapshotTolerance {
  /// A pixel is "off" when some channel differs by more than this.
  int off_by = 8;
  /// Most 2 x 2 windows whose four pixels are all off.
  int max_thick_windows = 4;
  /// A pixel's colour is "found" in the other image's 3 x 3 neighbourhood within this, per channel.
  int neighbour_tolerance = 32;
  /// Most pixels not found (displaced), as a share of all pixels (rounded down to a count).
  double max_displaced_fraction = 0.002;
  /// Most mean absolute difference over all channels, each clipped at `off_by`.
  double max_clipped_mean = 1.5;
  /// Most mean absolute difference over all channels, unclipped. Not bounded by default.
  double max_mean_difference = std::numeric_limits<double>::infinity();
  /// Most share of pixels off. Not bounded by default (1.0).
  double max_off_fraction = 1.0;

  /// Byte for byte: no pixel may differ at all.
  static SnapshotTolerance exact();
};

/// When a segmentation frame matches its golden. Labels either agree or not, so "off" is a
/// different label; a thick change is a 2 x 2 window of differing labels (an object moved), a
/// displaced pixel one whose label is absent from the other image's 3 x 3 neighbourhood, looked
/// for both ways; and the share of pixels whose label differs (label disagreement) is bounded.
/// The defaults admit what the colour default admits (edges one pixel over: a whole row of an
/// 84 x 84 frame is 1.2 %), and catch what it catches (a moved object).
/// SegmentationTolerance::exact() demands every label equal.
struct SegmentationTolerance {
  /// Most 2 x 2 windows whose four labels all differ.
  int max_thick_windows = 4;
  /// Most pixels whose label is absent from the other image's 3 x 3 neighbourhood, as a share of
  /// all pixels (rounded down to a count).
  double max_displaced_fraction = 0.002;
  /// Most share of pixels whose label differs.
  double max_disagreement = 0.02;

  /// Every label equal: all three bounds 0.
  static SegmentationTolerance exact();
};

/// What to do with the golden and where to put the images of a failure.
struct SnapshotOptions {
  /// When the golden is written instead of compared.
  enum class Update {
    kFromEnvironment,  ///< rewrite the golden when PIXELGYM_UPDATE_GOLDENS=1, else compare
    kNever,            ///< always compare
    kAlways,           ///< always (re)write the golden
  };
  /// Whether to compare with the golden or (re)write it.
  Update update = Update::kFromEnvironment;
  /// Where <golden name>.actual.png and .diff.png go on a failure; empty: the environment
  /// variable PIXELGYM_SNAPSHOT_OUTPUT_DIR, else "snapshot_output" in the current folder.
  std::string output_dir;
};

/// The figures of one comparison. For segmentation, `thick_windows` and `displaced_pixels` count
/// as above with "off" meaning a different label, `off_fraction` is the label disagreement, and
/// the means are 0.
struct SnapshotFigures {
  /// 2 x 2 windows whose four pixels are all off.
  int thick_windows = 0;
  /// Pixels not found in the other image's 3 x 3 neighbourhood (both ways).
  int displaced_pixels = 0;
  /// Mean absolute difference over all channels, each clipped at `off_by`.
  double clipped_mean = 0.0;
  /// Mean absolute difference over all channels.
  double mean_difference = 0.0;
  /// Pixels off (some channel differs by more than `off_by`; a different label), and their share.
  int off_pixels = 0;
  double off_fraction = 0.0;
};

/// A comparison's figures and its diff image (RGB, the frame's size; see the top of this file).
struct ImageDifference {
  SnapshotFigures figures;
  /// height x width x 3 bytes.
  std::vector<std::uint8_t> diff_rgb;
};

/// Compares two RGB images of the same size; `tolerance` sets what counts as off and as found
/// (off_by, neighbour_tolerance), not whether they match (see `within`). Throws
/// std::invalid_argument for null pixels, a channel count other than 3, or sizes that differ
/// or are not positive.
ImageDifference difference(const render::ImageView& actual, const render::ImageView& expected,
                           const SnapshotTolerance& tolerance = {});
/// Compares two label images of `height` x `width`. Throws std::invalid_argument for null
/// pointers or a size that is not positive, and as encode_labels for a label of `expected`
/// outside [-1, 2^24 - 2].
ImageDifference segmentation_difference(const std::int32_t* actual, const std::int32_t* expected,
                                        int height, int width);

/// Whether `figures`, of an image of `pixels` pixels, are within `tolerance`.
bool within(const SnapshotFigures& figures, std::int64_t pixels,
            const SnapshotTolerance& tolerance);
/// The same for a segmentation comparison.
bool within(const SnapshotFigures& figures, std::int64_t pixels,
            const SegmentationTolerance& tolerance);

/// The outcome of compare_to_golden: converts to true when the frame matched (or the golden was
/// written).
struct SnapshotResult {
  /// What happened.
  enum class Status {
    kMatched,           ///< within the tolerance
    kDiffered,          ///< compared, and outside the tolerance
    kMissingGolden,     ///< no file at the golden's path
    kSizeMismatch,      ///< the golden has another size or number of channels
    kUnreadableGolden,  ///< the golden is not a PNG that can be read
    kUpdated,           ///< the golden was (re)written from the frame
  };
  Status status = Status::kMatched;
  /// True for a segmentation comparison.
  bool segmentation = false;
  /// The golden's path, as given.
  std::string golden_path;
  /// Where the frame and the diff image were written (empty when not written).
  std::string actual_path;
  std::string diff_path;
  /// The frame's and the golden's size (the golden's 0 when it was not read).
  int height = 0, width = 0, channels = 3;
  int golden_height = 0, golden_width = 0, golden_channels = 0;
  /// The comparison's figures (zero unless it compared: kMatched or kDiffered).
  SnapshotFigures figures;
  /// The tolerance compared against (one of them, as `segmentation` says).
  SnapshotTolerance tolerance;
  SegmentationTolerance segmentation_tolerance;
  /// For kUnreadableGolden: why.
  std::string reason;

  /// True for kMatched and kUpdated.
  bool matched() const { return status == Status::kMatched || status == Status::kUpdated; }
  explicit operator bool() const { return matched(); }
  /// One paragraph: what happened, the figures against their limits, the files written, and how
  /// to create or update the golden.
  std::string message() const;
};

/// Compares an RGB frame with the PNG at `golden_path` (see the top of this file). The frame is an
/// (H, W, 3) uint8 Array (what render() and a "pixels" observation are); throws
/// std::invalid_argument for anything else, and std::runtime_error when an image cannot be
/// written. A missing, unreadable or differently sized golden is a failed result, not a throw.
SnapshotResult compare_to_golden(const Array& frame, const std::string& golden_path,
                                 const SnapshotTolerance& tolerance = {},
                                 const SnapshotOptions& options = {});
/// The same for a frame given as a view: it must have pixels, 3 channels and a positive size,
/// else std::invalid_argument.
SnapshotResult compare_to_golden(const render::ImageView& frame, const std::string& golden_path,
                                 const SnapshotTolerance& tolerance = {},
                                 const SnapshotOptions& options = {});

/// Compares a segmentation frame (int32 labels, as render::RenderTargets::segmentation writes:
/// 0 sky, -1 floor, an instance's segmentation_id elsewhere) with its golden. The frame is an
/// (H, W) or (H, W, 1) int32 Array, or a pointer to height x width labels. Labels from -1 to
/// 2^24 - 2 are stored in an RGB PNG (see encode_labels); the golden's PNG shows each label in
/// a colour of its own. The diff image: labels that agree dimmed to a quarter of their colour,
/// disagreeing pixels light grey, with the thick windows and displaced pixels marked in red and
/// blue as in the colour diff image.
SnapshotResult compare_segmentation_to_golden(const Array& labels, const std::string& golden_path,
                                              const SegmentationTolerance& tolerance = {},
                                              const SnapshotOptions& options = {});
SnapshotResult compare_segmentation_to_golden(const std::int32_t* labels, int height, int width,
                                              const std::string& golden_path,
                                              const SegmentationTolerance& tolerance = {},
                                              const SnapshotOptions& options = {});

/// The RGB image a segmentation golden stores: label + 1 (0 for the floor's -1), times an odd
/// constant modulo 2^24 so that neighbouring labels get distinct colours, as 0xRRGGBB. Throws
/// std::invalid_argument for a label outside [-1, 2^24 - 2].
std::vector<std::uint8_t> encode_labels(const std::int32_t* labels, std::size_t count);
/// The inverse of encode_labels.
std::vector<std::int32_t> decode_labels(const std::uint8_t* rgb, std::size_t count);

}  // namespace pixelgym::testing
