#include "pixelgym/render/scene.h"

#include <atomic>
#include <stdexcept>
#include <string>
#include <utility>

namespace pixelgym::render {

std::shared_ptr<const TextureImage> TextureImage::make(Image image) {
  if (image.width <= 0 || image.height <= 0 ||
      (image.channels != 1 && image.channels != 3 && image.channels != 4) ||
      image.pixels.size() != static_cast<std::size_t>(image.width) *
                                 static_cast<std::size_t>(image.height) *
                                 static_cast<std::size_t>(image.channels)) {
    throw std::invalid_argument(
        "TextureImage: expected a non-empty 8-bit image with 1, 3 or 4 channels and width x "
        "height x channels bytes, got " +
        std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
        std::to_string(image.channels) + " with " + std::to_string(image.pixels.size()) + " bytes");
  }
  static std::atomic<std::uint64_t> next_serial{1};
  return std::shared_ptr<const TextureImage>(
      new TextureImage(std::move(image), next_serial.fetch_add(1)));
}

}  // namespace pixelgym::render
