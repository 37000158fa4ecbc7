// Checkpoint files: a named set of byte blobs ("model", "optimizer", "rng", ...), written
// atomically and read back only when whole and intact. The trainer serializes its tensors and
// states to bytes; this file knows nothing of what the bytes mean.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace pixelgym::trainer {

/// A checkpoint's contents: blob name -> bytes. Names are 1 to 255 bytes of [A-Za-z0-9_.-].
using CheckpointBlobs = std::map<std::string, std::string>;

/// The format version write_checkpoint writes and read_checkpoint accepts.
inline constexpr std::uint32_t kCheckpointFormatVersion = 1;

/// Writes `blobs` to `path` atomically (see write_file_atomically: a temporary file in the same
/// folder, every write checked, fsync of file and folder, rename): `path` holds the previous
/// checkpoint or the whole new one, whenever the process is killed.
///
/// Layout, integers little-endian: the magic "PGYMCKPT"; u32 format version; u32 table size in
/// bytes; the table (u32 blob count, then per blob: u32 name length, the name, u64 size); u32
/// CRC-32 of everything before it; the blobs' bytes in table order; u32 CRC-32 of those bytes.
///
/// Throws std::invalid_argument for an empty set or a malformed name, std::runtime_error
/// "write_checkpoint: cannot write {path}: {reason}" when the file cannot be written.
void write_checkpoint(const std::filesystem::path& path, const CheckpointBlobs& blobs);

/// `blobs` as one string (u64 count, then per blob u64 name length, name, u64 size, bytes;
/// little-endian), to send between processes, and back. unpack_blobs throws std::runtime_error
/// naming `source` for bytes that are not such a string.
std::string pack_blobs(const CheckpointBlobs& blobs);
CheckpointBlobs unpack_blobs(const std::string& bytes, const std::string& source);
/// Reads a checkpoint written by write_checkpoint, all or nothing. Throws std::runtime_error
/// "read_checkpoint: {path}: ..." naming what was expected and what was found when the file
/// cannot be read, is shorter than its table says (truncated), longer (trailing bytes), has a
/// wrong magic or format version, or fails either checksum.
CheckpointBlobs read_checkpoint(const std::filesystem::path& path);

/// The file name of the checkpoint taken after `update` updates: "ckpt-000120.pgck" (at least six
/// digits). Throws std::invalid_argument for a negative update.
std::string checkpoint_file_name(std::int64_t update);

/// The update number of a checkpoint file name ("ckpt-000120.pgck" -> 120), or nullopt for any
/// other name (temporary files, other files of a run folder).
std::optional<std::int64_t> checkpoint_update(const std::string& file_name);

/// A checkpoint file that find_latest_checkpoint passed over, and why.
struct SkippedCheckpoint {
  std::filesystem::path path;
  std::string reason;  // read_checkpoint's message
};

/// A valid checkpoint, read.
struct LoadedCheckpoint {
  std::filesystem::path path;
  std::int64_t update = 0;
  CheckpointBlobs blobs;
};

/// What find_latest_checkpoint found in a folder.
struct CheckpointSearch {
  std::optional<LoadedCheckpoint> latest;  // nullopt: no valid checkpoint
  std::vector<SkippedCheckpoint> skipped;  // invalid checkpoint files newer than `latest`
};

/// Reads the checkpoint with the highest update number in `folder` that read_checkpoint accepts;
/// newer invalid ones are listed in `skipped` (the caller reports them), temporary files and other
/// names are ignored. Throws std::runtime_error naming the folder when it cannot be listed.
CheckpointSearch find_latest_checkpoint(const std::filesystem::path& folder);

/// The checkpoint files of `folder` (by name only, not read), lowest update first.
std::vector<std::filesystem::path> list_checkpoints(const std::filesystem::path& folder);

/// Deletes the checkpoint files of `folder` but the `keep` with the highest update numbers (by
/// name, not read; keep 0 deletes none) and returns the deleted paths, lowest update first. The
/// trainer calls it right after writing a checkpoint, so the newest kept is that one, valid;
/// keeping more than one leaves find_latest_checkpoint something older should a file be damaged
/// later. Throws std::invalid_argument for a negative `keep`, std::runtime_error naming the folder
/// or the file when it cannot be listed or a file cannot be deleted.
std::vector<std::filesystem::path> prune_checkpoints(const std::filesystem::path& folder,
                                                     std::int64_t keep);

}  // namespace pixelgym::trainer
