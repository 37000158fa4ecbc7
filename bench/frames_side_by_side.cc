// The frames several programs drew, side by side in one PNG, for bench/RESULTS.md.
//
// usage: frames_side_by_side OUT.png SCALE IMAGE...
// Each IMAGE (PNG, or binary PPM as the reference programs in ../shared/peers write them) is
// enlarged SCALE times by repeating pixels (so each source pixel stays visible), and the images are
// placed left to right, tops aligned, 8 pixels apart on a grey background. Gray and RGBA images
// are drawn as RGB. The PNG is complete or absent (render::write_png).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/render/image_io.h"

namespace {

using pixelgym::render::Image;

// Skips whitespace and '#' comments in a PPM header, then reads one unsigned decimal number.
int read_ppm_number(const std::string& bytes, std::size_t& at, const std::string& path) {
  while (at < bytes.size()) {
    if (bytes[at] == '#') {
      while (at < bytes.size() && bytes[at] != '\n') ++at;
    } else if (bytes[at] == ' ' || bytes[at] == '\n' || bytes[at] == '\r' || bytes[at] == '\t') {
      ++at;
    } else {
      break;
    }
  }
  const std::size_t start = at;
  long value = 0;
  while (at < bytes.size() && bytes[at] >= '0' && bytes[at] <= '9' && value < 1000000) {
    value = value * 10 + (bytes[at] - '0');
    ++at;
  }
  if (at == start) {
    throw std::runtime_error(path + ": expected a number in the PPM header at byte " +
                             std::to_string(start));
  }
  return static_cast<int>(value);
}

// A binary PPM (P6, maxval 255), rows top first.
Image read_ppm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::ostringstream contents;
  contents << in.rdbuf();
  const std::string bytes = contents.str();
  if (bytes.compare(0, 2, "P6") != 0) {
    throw std::runtime_error(path + ": expected a binary PPM (P6) or a PNG");
  }
  std::size_t at = 2;
  Image image;
  image.width = read_ppm_number(bytes, at, path);
  image.height = read_ppm_number(bytes, at, path);
  const int maxval = read_ppm_number(bytes, at, path);
  if (maxval != 255) {
    throw std::runtime_error(path + ": expected maxval 255, got " + std::to_string(maxval));
  }
  ++at;  // the one whitespace byte before the pixels
  const std::size_t size =
      static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3;
  if (image.width <= 0 || image.height <= 0 || bytes.size() < at + size) {
    throw std::runtime_error(path + ": expected " + std::to_string(size) + " bytes of " +
                             std::to_string(image.width) + "x" + std::to_string(image.height) +
                             " RGB pixels, the file has " + std::to_string(bytes.size() - at));
  }
  image.channels = 3;
  image.pixels.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                      bytes.begin() + static_cast<std::ptrdiff_t>(at + size));
  return image;
}

Image read_image(const std::string& path) {
  const bool png = path.size() > 4 && path.compare(path.size() - 4, 4, ".png") == 0;
  return png ? pixelgym::render::read_png(path) : read_ppm(path);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s OUT.png SCALE IMAGE...\n", argv[0]);
    return 2;
  }
  const int scale = std::atoi(argv[2]);
  if (scale < 1 || scale > 16) {
    std::fprintf(stderr, "frames_side_by_side: SCALE must be 1 to 16, got %s\n", argv[2]);
    return 2;
  }
  constexpr int kGap = 8;
  constexpr std::uint8_t kBackground = 128;
  try {
    std::vector<Image> images;
    int width = 0;
    int height = 0;
    for (int i = 3; i < argc; ++i) {
      images.push_back(read_image(argv[i]));
      width += images.back().width * scale + (i > 3 ? kGap : 0);
      height = std::max(height, images.back().height * scale);
    }
    std::vector<std::uint8_t> out(static_cast<std::size_t>(width) * height * 3, kBackground);
    int left = 0;
    for (const Image& image : images) {
      for (int y = 0; y < image.height * scale; ++y) {
        for (int x = 0; x < image.width * scale; ++x) {
          const std::uint8_t* source =
              &image.pixels[(static_cast<std::size_t>(y / scale) * image.width + x / scale) *
                            image.channels];
          std::uint8_t* target = &out[(static_cast<std::size_t>(y) * width + left + x) * 3];
          for (int c = 0; c < 3; ++c) target[c] = source[image.channels >= 3 ? c : 0];
        }
      }
      left += image.width * scale + kGap;
    }
    pixelgym::render::write_png(argv[1], {out.data(), height, width, 3});
  } catch (const std::exception& error) {
    std::fprintf(stderr, "frames_side_by_side: %s\n", error.what());
    return 1;
  }
  return 0;
}
