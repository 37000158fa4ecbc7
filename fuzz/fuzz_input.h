// What the fuzz targets share: reading an input a piece at a time, and handing it to code that
// reads files.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

namespace pixelgym::fuzz {

/// An input consumed from the front: bytes, small integers, and the rest.
class FuzzInput {
 public:
  FuzzInput(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool empty() const { return size_ == 0; }
  /// The next byte, 0 when none is left.
  std::uint8_t byte() {
    if (size_ == 0) return 0;
    --size_;
    return *data_++;
  }
  /// A number in [0, count) from the next byte (count >= 1).
  std::size_t pick(std::size_t count) { return byte() % count; }
  /// The next `n` bytes (fewer when fewer are left).
  std::string bytes(std::size_t n) {
    n = n < size_ ? n : size_;
    std::string out(reinterpret_cast<const char*>(data_), n);
    data_ += n;
    size_ -= n;
    return out;
  }
  /// The next 8 bytes as a double (zero-filled when fewer are left): any bit pattern, NaN and
  /// infinities included.
  double any_double() {
    const std::string raw = bytes(sizeof(double));
    double value = 0;
    std::memcpy(&value, raw.data(), raw.size());
    return value;
  }
  /// Up to the next '\n' (consumed, not returned), or the rest.
  std::string line() {
    const void* end = std::memchr(data_, '\n', size_);
    if (end == nullptr) return rest();
    const auto n = static_cast<std::size_t>(static_cast<const std::uint8_t*>(end) - data_);
    std::string out = bytes(n);
    byte();
    return out;
  }
  std::string rest() { return bytes(size_); }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
};

/// Writes `bytes` to a file named `name` in a folder of this process's own (made once, under the
/// temporary folder) and returns its path, for code that reads files. The same path is rewritten
/// for every input.
inline std::string write_input_file(const std::string& bytes, const std::string& name) {
  static const std::filesystem::path folder = [] {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "pixelgym-fuzz-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) std::abort();
    return std::filesystem::path(pattern);
  }();
  const std::filesystem::path path = folder / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) std::abort();
  return path.string();
}

}  // namespace pixelgym::fuzz
