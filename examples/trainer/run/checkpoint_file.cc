#include "pixelgym/trainer/checkpoint_file.h"

#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "pixelgym/trainer/atomic_file.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMagic = "PGYMCKPT";
constexpr std::size_t kMaxNameLength = 255;
// A table larger than this is a corrupt size field, not a checkpoint (4 blobs take ~70 bytes).
constexpr std::uint32_t kMaxTableSize = 1U << 20;
// magic, version, table size
constexpr std::size_t kPrefixSize = 8 + 4 + 4;
// More bytes than any file holds.
constexpr std::uint64_t kMaxSize = std::uint64_t{1} << 62;

std::uint32_t crc32_of(std::string_view bytes, std::uint32_t crc = 0) {
  return static_cast<std::uint32_t>(
      ::crc32_z(crc, reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
}

void put_u32(std::string& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFFU));
}

void put_u64(std::string& out, std::uint64_t value) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFFU));
}

std::uint64_t get_le(std::string_view bytes, std::size_t offset, int size) {
  std::uint64_t value = 0;
  for (int i = 0; i < size; ++i) {
    value |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[offset + i])) << (8 * i);
  }
  return value;
}

std::string hex32(std::uint32_t value) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string text = "0x";
  for (int shift = 28; shift >= 0; shift -= 4) text.push_back(kDigits[(value >> shift) & 0xFU]);
  return text;
}

// The magic as read, printable: "PGYMCKPT", or escaped bytes.
std::string printable(std::string_view bytes) {
  std::string text;
  for (const char c : bytes) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7F && c != '\\' && c != '"') {
      text.push_back(c);
    } else {
      text += "\\x" + hex32(byte).substr(8);
    }
  }
  return "\"" + text + "\"";
}

bool valid_name(const std::string& name) {
  if (name.empty() || name.size() > kMaxNameLength) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '.' || c == '-';
  });
}

// Reads the checkpoint's parts in order, throwing "read_checkpoint: {path}: {problem}".
class Reader {
 public:
  Reader(const fs::path& path, std::string_view bytes) : path_(path), bytes_(bytes) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw std::runtime_error("read_checkpoint: " + path_.string() + ": " + problem +
                             "; refusing to load it");
  }

  // Needs `size` more bytes at the cursor, reading `what`; a shorter file is truncated.
  void need(std::size_t size, const std::string& what) const {
    if (bytes_.size() - offset_ < size) {
      fail("truncated: expected at least " + std::to_string(offset_ + size) + " bytes (" + what +
           "), found " + std::to_string(bytes_.size()));
    }
  }

  std::uint64_t integer(int size, const std::string& what) {
    need(static_cast<std::size_t>(size), what);
    const std::uint64_t value = get_le(bytes_, offset_, size);
    offset_ += static_cast<std::size_t>(size);
    return value;
  }

  std::string_view span(std::size_t size, const std::string& what) {
    need(size, what);
    const std::string_view piece = bytes_.substr(offset_, size);
    offset_ += size;
    return piece;
  }

  std::size_t offset() const { return offset_; }
  std::string_view bytes() const { return bytes_; }

 private:
  const fs::path& path_;
  std::string_view bytes_;
  std::size_t offset_ = 0;
};

}  // namespace

std::string pack_blobs(const CheckpointBlobs& blobs) {
  std::string out;
  const auto put = [&out](std::uint64_t value) {
    for (int b = 0; b < 8; ++b) out.push_back(static_cast<char>((value >> (8 * b)) & 0xFF));
  };
  put(blobs.size());
  for (const auto& [name, bytes] : blobs) {
    put(name.size());
    out += name;
    put(bytes.size());
    out += bytes;
  }
  return out;
}

CheckpointBlobs unpack_blobs(const std::string& bytes, const std::string& source) {
  std::size_t at = 0;
  const auto fail = [&]() -> std::runtime_error {
    return std::runtime_error(source + ": not a packed set of blobs (" +
                              std::to_string(bytes.size()) + " bytes, malformed at byte " +
                              std::to_string(at) + ")");
  };
  const auto get = [&]() {
    if (bytes.size() - at < 8) throw fail();
    std::uint64_t value = 0;
    for (int b = 0; b < 8; ++b) {
      value |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[at + b])) << (8 * b);
    }
    at += 8;
    return value;
  };
  const auto take = [&](std::uint64_t size) {
    if (bytes.size() - at < size) throw fail();
    std::string part = bytes.substr(at, size);
    at += size;
    return part;
  };
  CheckpointBlobs blobs;
  const std::uint64_t count = get();
  for (std::uint64_t i = 0; i < count; ++i) {
    std::string name = take(get());
    blobs[std::move(name)] = take(get());
  }
  if (at != bytes.size()) throw fail();
  return blobs;
}

void write_checkpoint(const fs::path& path, const CheckpointBlobs& blobs) {
  if (blobs.empty()) {
    throw std::invalid_argument("write_checkpoint: " + path.string() +
                                ": expected at least one blob, got none");
  }
  std::string table;
  put_u32(table, static_cast<std::uint32_t>(blobs.size()));
  std::uint32_t data_crc = 0;
  for (const auto& [name, bytes] : blobs) {
    if (!valid_name(name)) {
      throw std::invalid_argument("write_checkpoint: " + path.string() +
                                  ": blob names must be 1 to 255 characters of [A-Za-z0-9_.-], "
                                  "got \"" +
                                  name + "\"");
    }
    put_u32(table, static_cast<std::uint32_t>(name.size()));
    table += name;
    put_u64(table, bytes.size());
    data_crc = crc32_of(bytes, data_crc);
  }
  std::string header(kMagic);
  put_u32(header, kCheckpointFormatVersion);
  put_u32(header, static_cast<std::uint32_t>(table.size()));
  header += table;
  put_u32(header, crc32_of(header));
  std::string trailer;
  put_u32(trailer, data_crc);

  std::vector<std::string_view> pieces;
  pieces.reserve(blobs.size() + 2);
  pieces.emplace_back(header);
  for (const auto& entry : blobs) pieces.emplace_back(entry.second);
  pieces.emplace_back(trailer);
  write_file_atomically(path, pieces, "write_checkpoint");
}

CheckpointBlobs read_checkpoint(const fs::path& path) {
  const std::string file = read_whole_file(path, "read_checkpoint");
  Reader reader(path, file);

  const std::string_view magic = reader.span(kMagic.size(), "the magic");
  if (magic != kMagic) {
    reader.fail("not a pixelgym checkpoint: expected the magic " + printable(kMagic) +
                " at the start, found " + printable(magic));
  }
  const auto version = static_cast<std::uint32_t>(reader.integer(4, "the format version"));
  if (version != kCheckpointFormatVersion) {
    reader.fail("expected format version " + std::to_string(kCheckpointFormatVersion) + ", found " +
                std::to_string(version));
  }
  const auto table_size = static_cast<std::uint32_t>(reader.integer(4, "the table size"));
  if (table_size > kMaxTableSize) {
    reader.fail("expected a blob table of at most " + std::to_string(kMaxTableSize) +
                " bytes, found a size of " + std::to_string(table_size) + " (corrupt header)");
  }
  const std::string_view table = reader.span(table_size, "the blob table");
  const auto stored_header_crc = static_cast<std::uint32_t>(reader.integer(4, "the header CRC"));
  const std::uint32_t header_crc = crc32_of(file.substr(0, kPrefixSize + table_size));
  if (header_crc != stored_header_crc) {
    reader.fail("header checksum mismatch: expected CRC-32 " + hex32(stored_header_crc) +
                " (stored), found " + hex32(header_crc) + " (computed): the header is corrupt");
  }

  // The table passed its checksum, so it is as written; parse it.
  Reader table_reader(path, table);
  const std::uint64_t count = table_reader.integer(4, "the blob count");
  std::vector<std::pair<std::string, std::uint64_t>> entries;
  std::uint64_t data_size = 0;
  for (std::uint64_t i = 0; i < count; ++i) {
    const auto name_size = static_cast<std::size_t>(table_reader.integer(4, "a name length"));
    std::string name(table_reader.span(name_size, "a blob name"));
    const std::uint64_t size = table_reader.integer(8, "a blob size");
    // Saturating: a corrupt size must not wrap the sum around to a plausible one.
    data_size = std::min(data_size + std::min(size, kMaxSize), kMaxSize);
    entries.emplace_back(std::move(name), size);
  }
  if (table_reader.offset() != table.size()) {
    reader.fail("expected a blob table of " + std::to_string(table.size()) + " bytes, its " +
                std::to_string(count) + " entries take " + std::to_string(table_reader.offset()));
  }
  const std::uint64_t expected_size = reader.offset() + data_size + 4;
  if (file.size() != expected_size) {
    reader.fail(std::string(file.size() < expected_size ? "truncated" : "trailing bytes") +
                ": expected " + std::to_string(expected_size) + " bytes (header and " +
                std::to_string(count) + " blobs of " + std::to_string(data_size) +
                " bytes in all, then a CRC), found " + std::to_string(file.size()));
  }
  const std::string_view data = reader.span(static_cast<std::size_t>(data_size), "the blobs");
  const auto stored_data_crc = static_cast<std::uint32_t>(reader.integer(4, "the data CRC"));
  const std::uint32_t data_crc = crc32_of(data);
  if (data_crc != stored_data_crc) {
    reader.fail("checksum mismatch: expected CRC-32 " + hex32(stored_data_crc) +
                " (stored) over the " + std::to_string(data_size) + " bytes of blobs, found " +
                hex32(data_crc) + " (computed): the contents are corrupt");
  }

  CheckpointBlobs blobs;
  std::size_t offset = 0;
  for (auto& [name, size] : entries) {
    blobs[name] = std::string(data.substr(offset, static_cast<std::size_t>(size)));
    offset += static_cast<std::size_t>(size);
  }
  return blobs;
}

std::string checkpoint_file_name(std::int64_t update) {
  if (update < 0) {
    throw std::invalid_argument("checkpoint_file_name: expected an update number >= 0, got " +
                                std::to_string(update));
  }
  std::string digits = std::to_string(update);
  if (digits.size() < 6) digits.insert(0, 6 - digits.size(), '0');
  return "ckpt-" + digits + ".pgck";
}

std::optional<std::int64_t> checkpoint_update(const std::string& file_name) {
  constexpr std::string_view kPrefix = "ckpt-";
  constexpr std::string_view kSuffix = ".pgck";
  if (file_name.size() < kPrefix.size() + 6 + kSuffix.size() ||
      file_name.compare(0, kPrefix.size(), kPrefix) != 0 ||
      file_name.compare(file_name.size() - kSuffix.size(), kSuffix.size(), kSuffix) != 0) {
    return std::nullopt;
  }
  const std::string digits =
      file_name.substr(kPrefix.size(), file_name.size() - kPrefix.size() - kSuffix.size());
  if (digits.size() > 18 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  return std::stoll(digits);
}

std::vector<fs::path> list_checkpoints(const fs::path& folder) {
  std::error_code error;
  fs::directory_iterator entries(folder, error);
  if (error) {
    throw std::runtime_error("list_checkpoints: cannot list " + folder.string() + ": " +
                             error.message());
  }
  std::vector<std::pair<std::int64_t, fs::path>> found;
  for (const fs::directory_entry& entry : entries) {
    const std::optional<std::int64_t> update = checkpoint_update(entry.path().filename().string());
    if (update) found.emplace_back(*update, entry.path());
  }
  std::sort(found.begin(), found.end());
  std::vector<fs::path> paths;
  paths.reserve(found.size());
  for (auto& [update, path] : found) paths.push_back(std::move(path));
  return paths;
}

std::vector<fs::path> prune_checkpoints(const fs::path& folder, std::int64_t keep) {
  if (keep < 0) {
    throw std::invalid_argument("prune_checkpoints: expected keep >= 0, got " +
                                std::to_string(keep));
  }
  std::vector<fs::path> paths = list_checkpoints(folder);
  if (keep == 0 || static_cast<std::int64_t>(paths.size()) <= keep) return {};
  paths.resize(paths.size() - static_cast<std::size_t>(keep));
  for (const fs::path& path : paths) {
    std::error_code error;
    fs::remove(path, error);
    if (error) {
      throw std::runtime_error("prune_checkpoints: cannot delete " + path.string() + ": " +
                               error.message());
    }
  }
  return paths;
}

CheckpointSearch find_latest_checkpoint(const fs::path& folder) {
  const std::vector<fs::path> paths = list_checkpoints(folder);
  CheckpointSearch search;
  for (auto path = paths.rbegin(); path != paths.rend(); ++path) {
    try {
      CheckpointBlobs blobs = read_checkpoint(*path);
      search.latest =
          LoadedCheckpoint{*path, *checkpoint_update(path->filename().string()), std::move(blobs)};
      break;
    } catch (const std::runtime_error& error) {
      // Not swallowed: skipping an invalid checkpoint and reporting why is this lookup's job.
      search.skipped.push_back({*path, error.what()});
    }
  }
  return search;
}

}  // namespace pixelgym::trainer
