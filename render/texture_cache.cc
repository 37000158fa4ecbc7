#include "pixelgym/render/texture_cache.h"

#include <cstdint>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "pixelgym/render/image_io.h"

namespace pixelgym::render {

TextureCache::TextureCache() : white_(make_texture()) {
  glBindTexture(GL_TEXTURE_2D, white_.get());
  const unsigned char white[4] = {255, 255, 255, 255};
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, white);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
}

void TextureCache::bind_name(GLuint name) {
  if (bound_ == name) return;
  glBindTexture(GL_TEXTURE_2D, name);
  bound_ = name;
}

void TextureCache::bind_white() { bind_name(white_.get()); }

void TextureCache::bind(const std::string& path) {
  auto found = by_path_.find(path);
  if (found != by_path_.end()) {
    bind_name(found->second.get());
    return;
  }
  Image image;
  try {
    image = read_png(path);
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(std::string("Renderer: texture cannot be used: ") + error.what());
  }
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(image.width) *
                                 static_cast<std::size_t>(image.height) * 4);
  for (std::size_t p = 0; p < rgba.size() / 4; ++p) {
    const std::uint8_t* source = image.pixels.data() + p * static_cast<std::size_t>(image.channels);
    for (std::size_t c = 0; c < 3; ++c)
      rgba[p * 4 + c] = image.channels >= 3 ? source[c] : source[0];
    rgba[p * 4 + 3] = image.channels == 4 ? source[3] : 255;
  }
  GlTexture texture = make_texture();
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture.get());
  bound_ = texture.get();
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               rgba.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  by_path_.emplace(path, std::move(texture));
}

void TextureCache::bind_image(const std::shared_ptr<const TextureImage>& image, int unit) {
  auto found = by_serial_.find(image->serial());
  if (found == by_serial_.end()) {
    // Images come and go with the envs' variation (a background per episode): drop the uploads
    // of those no longer held anywhere before adding one.
    constexpr std::size_t kKeptBeforePurge = 32;
    if (by_serial_.size() >= kKeptBeforePurge) {
      for (auto it = by_serial_.begin(); it != by_serial_.end();) {
        it = it->second.image.expired() ? by_serial_.erase(it) : std::next(it);
      }
    }
    const Image& pixels = image->image();
    std::vector<std::uint8_t> rgb(static_cast<std::size_t>(pixels.width) *
                                  static_cast<std::size_t>(pixels.height) * 3);
    for (std::size_t p = 0; p < rgb.size() / 3; ++p) {
      const std::uint8_t* source =
          pixels.pixels.data() + p * static_cast<std::size_t>(pixels.channels);
      for (std::size_t c = 0; c < 3; ++c)
        rgb[p * 3 + c] = pixels.channels >= 3 ? source[c] : source[0];
    }
    GlTexture texture = make_texture();
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, texture.get());
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, pixels.width, pixels.height, 0, GL_RGB,
                 GL_UNSIGNED_BYTE, rgb.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_MIRRORED_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_MIRRORED_REPEAT);
    found = by_serial_.emplace(image->serial(), Uploaded{image, std::move(texture)}).first;
  }
  glActiveTexture(GL_TEXTURE0 + unit);
  glBindTexture(GL_TEXTURE_2D, found->second.texture.get());
  glActiveTexture(GL_TEXTURE0);
  if (unit == 0) bound_ = found->second.texture.get();
}

}  // namespace pixelgym::render
