// Input files (URDFs, meshes) are regular files of bounded size: a FIFO, a device or a file of
// gigabytes is refused before it is read, with a message saying what it is.
#pragma once

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace pixelgym::engine {

/// A file that is not a regular file, is larger than allowed or cannot be read. The message is
/// the problem alone ("is a FIFO, not a regular file"), for the caller to prefix with what the
/// file is and its path.
class FileProblem : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Checks that `path`, its symbolic links followed, names a regular file of at most `max_bytes`.
/// Throws FileProblem when it does not: it cannot be read ("cannot be read (No such file or
/// directory)"), it is another kind of file ("is a FIFO, not a regular file", naming where a
/// symbolic link led), or it is larger ("is 2.8 GiB (3000000000 bytes); `kind` may be at most
/// 32 MiB (33554432 bytes)"). Opens
/// nothing: opening a FIFO blocks until a writer comes.
void check_regular_file(const std::string& path, const std::string& kind,
                        std::uintmax_t max_bytes = std::numeric_limits<std::uintmax_t>::max());

/// The contents of `path`, checked as check_regular_file does, again on the file once opened (the
/// path may have changed in between), and read to at most `max_bytes`: a file that grows while it
/// is read is refused too. Throws FileProblem.
std::string read_regular_file(const std::string& path, const std::string& kind,
                              std::uintmax_t max_bytes);

/// `bytes` for a message: "812 bytes", "40.0 MiB", "3.0 GiB".
std::string describe_size(std::uintmax_t bytes);

}  // namespace pixelgym::engine
