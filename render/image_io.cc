#include "pixelgym/render/image_io.h"

#include <fcntl.h>
#include <png.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

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

// A name beside `path` that no other writer uses: the process id and a per-process counter.
std::string temporary_name(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
}

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw std::runtime_error("write_png: cannot write " + path + ": " + reason);
}

const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a pipe";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Writes `bytes` to a new file beside `path` and renames it to `path`, checking every write, the
// fsync and the close: the file under `path` is the whole of `bytes` or what was there before.
void write_file_atomically(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::string target = path;
  struct stat status {};
  if (::stat(path.c_str(), &status) == 0) {
    // A rename replaces the name, not what it names: a device (/dev/full), a folder or a pipe
    // would be replaced by a regular file, or the rename would fail after the work is done.
    if (!S_ISREG(status.st_mode)) {
      fail(path, std::string("it is ") + file_kind(status.st_mode) +
                     ", not a regular file (images are written to a temporary file in the "
                     "same folder, then renamed to the path)");
    }
    // A symbolic link to a file: replace the file it points to, keep the link.
    char resolved[PATH_MAX];
    if (::realpath(path.c_str(), resolved) != nullptr) target = resolved;
  }
  std::string temporary;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temporary = temporary_name(target);
    fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) fail(path, std::strerror(errno));
  }
  if (fd < 0) fail(path, "no free temporary name beside it");
  const auto give_up = [&](const char* step, int error) {
    if (fd >= 0) ::close(fd);
    ::unlink(temporary.c_str());
    fail(path, std::string(step) + std::strerror(error));
  };
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) give_up("", n < 0 ? errno : ENOSPC);
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 && errno != EINVAL) give_up("", errno);
  const int closed = ::close(fd);
  fd = -1;
  if (closed != 0) give_up("", errno);
  if (std::rename(temporary.c_str(), target.c_str()) != 0) {
    give_up("cannot rename the finished temporary file into place: ", errno);
  }
}

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
  // Encoded in memory first, so that nothing is created when encoding fails.
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = png_format(image.channels);
  const png_int_32 stride = image.width * image.channels;
  png_alloc_size_t size = 0;
  if (png_image_write_to_memory(&png, nullptr, &size, 0, image.pixels, stride, nullptr) == 0) {
    fail(path, std::string("cannot encode the PNG: ") + png.message);
  }
  std::vector<std::uint8_t> bytes(size);
  if (png_image_write_to_memory(&png, bytes.data(), &size, 0, image.pixels, stride, nullptr) == 0) {
    fail(path, std::string("cannot encode the PNG: ") + png.message);
  }
  bytes.resize(size);
  write_file_atomically(path, bytes);
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
