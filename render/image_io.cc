#include "render/image_io.h"

#include <png.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace pixelgym::render {
namespace {

png_uint_32 png_format(int channels) {
  switch (channels) {
    case 1:
      return PNG_FORMAT_GRAY;
    case 3:
      return PNG_FORMAT_RGB;
    case 4:
      return PNG_FORMAT_RGBA;
    default:
      return 0;
  }
}

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

}  // namespace

void write_png(const std::string& path, const ImageView& image) {
  if (image.pixels == nullptr || image.height <= 0 || image.width <= 0 ||
      (image.channels != 1 && image.channels != 3 && image.channels != 4)) {
    throw std::invalid_argument("write_png: " + path +
                                ": expected a non-empty image with 1, 3 or 4 "
                                "channels, got " +
                                std::to_string(image.height) + "x" + std::to_string(image.width) +
                                "x" + std::to_string(image.channels));
  }
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(temporary.c_str(), "wb"));
  if (file == nullptr) {
    throw std::runtime_error("write_png: cannot write " + path + ": " + std::strerror(errno));
  }
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = png_format(image.channels);
  const bool written = png_image_write_to_stdio(&png, file.get(), 0, image.pixels,
                                                image.width * image.channels, nullptr) != 0;
  const bool flushed =
      written && std::fflush(file.get()) == 0 && ::fsync(::fileno(file.get())) == 0;
  const int saved_errno = errno;
  const bool closed = std::fclose(file.release()) == 0;
  if (!written || !flushed || !closed) {
    std::remove(temporary.c_str());
    throw std::runtime_error("write_png: cannot write " + path + ": " +
                             (written ? std::strerror(saved_errno) : png.message));
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int rename_errno = errno;
    std::remove(temporary.c_str());
    throw std::runtime_error("write_png: cannot move the finished file to " + path + ": " +
                             std::strerror(rename_errno));
  }
}

Image read_png(const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&png, path.c_str()) == 0) {
    throw std::runtime_error("read_png: cannot read " + path + ": " + png.message);
  }
  Image image;
  const bool has_color = (png.format & PNG_FORMAT_FLAG_COLOR) != 0;
  const bool has_alpha = (png.format & PNG_FORMAT_FLAG_ALPHA) != 0;
  image.channels = has_color ? (has_alpha ? 4 : 3) : (has_alpha ? 4 : 1);
  png.format = png_format(image.channels);
  image.height = static_cast<int>(png.height);
  image.width = static_cast<int>(png.width);
  image.pixels.resize(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, image.pixels.data(), 0, nullptr) == 0) {
    const std::string reason = png.message;
    png_image_free(&png);
    throw std::runtime_error("read_png: cannot decode " + path + ": " + reason);
  }
  return image;
}

}  // namespace pixelgym::render
