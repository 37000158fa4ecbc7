#include "pixelgym/trainer/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& what, const char* verb, const fs::path& path,
                       const std::string& reason) {
  throw std::runtime_error(what + ": cannot " + verb + " " + path.string() + ": " + reason);
}

// Closes a file descriptor when it goes out of scope (unless released).
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  // Closes now; returns close's result (errno set on failure).
  int close() {
    const int result = ::close(fd_);
    fd_ = -1;
    return result;
  }

 private:
  int fd_;
};

// Flushes a folder's entries (a rename in it) to disk. File systems that cannot fsync a folder
// answer EINVAL; that is not an error here.
void sync_folder(const fs::path& folder, const std::string& what, const fs::path& path) {
  FileDescriptor fd(::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0)
    fail(what, "write", path,
         std::string("cannot open its folder to fsync it: ") + std::strerror(errno));
  if (::fsync(fd.get()) != 0 && errno != EINVAL) {
    fail(what, "write", path, std::string("cannot fsync its folder: ") + std::strerror(errno));
  }
}

}  // namespace

std::string temporary_file_prefix(const std::string& final_name) {
  return "." + final_name + ".tmp.";
}

void write_file_atomically(const fs::path& path, const std::vector<std::string_view>& pieces,
                           const std::string& what) {
  static std::atomic<unsigned> counter{0};
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  struct stat status {};
  if (::stat(path.c_str(), &status) == 0 && !S_ISREG(status.st_mode)) {
    fail(what, "write", path,
         "it exists and is not a regular file (files are written under a temporary name in the "
         "same folder, then renamed to the path)");
  }
  const std::string prefix = temporary_file_prefix(path.filename().string());
  fs::path temporary;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temporary = folder / (prefix + std::to_string(::getpid()) + "." + std::to_string(counter++));
    fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) fail(what, "write", path, std::strerror(errno));
  }
  if (fd < 0) fail(what, "write", path, "no free temporary name beside it");
  FileDescriptor file(fd);
  const auto give_up = [&](const std::string& step, int error) {
    if (file.get() >= 0) file.close();
    ::unlink(temporary.c_str());
    fail(what, "write", path, step + std::strerror(error));
  };
  for (const std::string_view piece : pieces) {
    std::size_t written = 0;
    while (written < piece.size()) {
      const ssize_t n = ::write(file.get(), piece.data() + written, piece.size() - written);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) give_up("", n < 0 ? errno : ENOSPC);
      written += static_cast<std::size_t>(n);
    }
  }
  if (::fsync(file.get()) != 0 && errno != EINVAL) give_up("", errno);
  if (file.close() != 0) give_up("", errno);
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    give_up("cannot rename the finished temporary file into place: ", errno);
  }
  sync_folder(folder, what, path);
}

std::string read_whole_file(const fs::path& path, const std::string& what) {
  FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.get() < 0) fail(what, "read", path, std::strerror(errno));
  struct stat status {};
  if (::fstat(file.get(), &status) != 0) fail(what, "read", path, std::strerror(errno));
  if (!S_ISREG(status.st_mode)) fail(what, "read", path, "not a regular file");
  std::string bytes;
  bytes.resize(static_cast<std::size_t>(status.st_size));
  std::size_t done = 0;
  while (true) {
    if (done == bytes.size()) bytes.resize(bytes.size() + 4096);  // the file may have grown
    const ssize_t n = ::read(file.get(), bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(what, "read", path, std::strerror(errno));
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace pixelgym::trainer
