// PNG files for rendered images: snapshots, golden images, diff images.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pixelgym::render {

/// Interleaved 8-bit pixels, row 0 at the top; `channels` is 1 (gray), 3 (RGB) or 4 (RGBA).
struct ImageView {
  /// height x width x channels bytes, not owned: they must outlive the view.
  const std::uint8_t* pixels = nullptr;
  /// Rows and columns, in pixels.
  int height = 0;
  int width = 0;
  int channels = 3;
};

/// An image read from a file, owning its pixels (layout as ImageView's).
struct Image {
  int height = 0;
  int width = 0;
  int channels = 3;
  /// height x width x channels bytes.
  std::vector<std::uint8_t> pixels;
  /// A view of `pixels`, valid while this image lives and its pixels are not reallocated.
  ImageView view() const { return {pixels.data(), height, width, channels}; }
};

/// Writes `image` as a PNG. The file is complete or absent: the PNG is encoded in memory, written
/// beside `path` under a temporary name (every write, the fsync and the close checked) and renamed
/// into place, so a failure leaves whatever was under `path` before, and no temporary file. `path`
/// must be a regular file or absent (a symbolic link to a file: the file is replaced); a device
/// such as /dev/full, a folder or a pipe is refused. Throws std::invalid_argument for a malformed
/// view and std::runtime_error naming the path and the reason (the OS error: "No space left on
/// device", "Read-only file system", ...) when it cannot be written.
void write_png(const std::string& path, const ImageView& image);

/// Reads a PNG as 8-bit gray, RGB or RGBA (palette and 16-bit files are converted). Throws
/// std::runtime_error naming the path and the reason.
Image read_png(const std::string& path);

}  // namespace pixelgym::render
