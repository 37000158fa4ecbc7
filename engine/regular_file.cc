#include "pixelgym/engine/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace pixelgym::engine {
namespace {

// What a file of mode `mode` is, for "is a FIFO, not a regular file".
std::string file_type(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

[[noreturn]] void refuse_type(const std::string& path, mode_t mode) {
  const std::string type = file_type(mode);
  std::string problem =
      type == "not a regular file" ? "is " + type : "is " + type + ", not a regular file";
  struct stat link {};
  if (::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
    std::error_code error;
    const std::filesystem::path target = std::filesystem::canonical(path, error);
    problem = "is a symbolic link to " +
              (error ? std::string("a file that") : target.string() + ", which") + " " + problem;
  }
  throw FileProblem(problem);
}

[[noreturn]] void refuse_size(std::uintmax_t size, const std::string& kind,
                              std::uintmax_t max_bytes) {
  throw FileProblem("is " + describe_size(size) + " (" + std::to_string(size) + " bytes); " + kind +
                    " may be at most " + describe_size(max_bytes) + " (" +
                    std::to_string(max_bytes) + " bytes)");
}

[[noreturn]] void refuse_unreadable(int error) {
  throw FileProblem(std::string("cannot be read (") + std::strerror(error) + ")");
}

void check_stat(const std::string& path, const struct stat& status, const std::string& kind,
                std::uintmax_t max_bytes) {
  if (!S_ISREG(status.st_mode)) refuse_type(path, status.st_mode);
  if (static_cast<std::uintmax_t>(status.st_size) > max_bytes)
    refuse_size(static_cast<std::uintmax_t>(status.st_size), kind, max_bytes);
}

// Closes the descriptor however the read ends.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

void check_regular_file(const std::string& path, const std::string& kind,
                        std::uintmax_t max_bytes) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) refuse_unreadable(errno);
  check_stat(path, status, kind, max_bytes);
}

std::string read_regular_file(const std::string& path, const std::string& kind,
                              std::uintmax_t max_bytes) {
  check_regular_file(path, kind, max_bytes);
  // O_NONBLOCK: should the path have become a FIFO since the check, opening it returns at once
  // (and fstat refuses it) instead of waiting for a writer.
  const Descriptor file(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (file.get() < 0) refuse_unreadable(errno);
  struct stat status {};
  if (::fstat(file.get(), &status) != 0) refuse_unreadable(errno);
  check_stat(path, status, kind, max_bytes);
  std::string text(static_cast<std::size_t>(status.st_size), '\0');
  std::size_t length = 0;
  for (;;) {
    // One byte more than allowed, so that a file that grew since fstat is caught.
    if (length == text.size()) {
      text.resize(std::min<std::uintmax_t>(max_bytes + 1, std::max<std::size_t>(4096, 2 * length)));
    }
    const ssize_t got = ::read(file.get(), &text[length], text.size() - length);
    if (got < 0) {
      if (errno == EINTR) continue;
      refuse_unreadable(errno);
    }
    if (got == 0) break;
    length += static_cast<std::size_t>(got);
  }
  if (length > max_bytes) {
    throw FileProblem("grew past " + describe_size(max_bytes) + " while it was read; " + kind +
                      " may be at most " + describe_size(max_bytes));
  }
  text.resize(length);
  return text;
}

std::string describe_size(std::uintmax_t bytes) {
  constexpr std::uintmax_t kMiB = 1024 * 1024;
  constexpr std::uintmax_t kGiB = 1024 * kMiB;
  char text[64];
  if (bytes >= kGiB) {
    std::snprintf(text, sizeof text, "%.1f GiB", static_cast<double>(bytes) / kGiB);
  } else if (bytes >= kMiB) {
    if (bytes % kMiB == 0) {
      std::snprintf(text, sizeof text, "%ju MiB", bytes / kMiB);
    } else {
      std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / kMiB);
    }
  } else {
    std::snprintf(text, sizeof text, "%ju bytes", bytes);
  }
  return text;
}

}  // namespace pixelgym::engine
