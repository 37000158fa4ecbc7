// Files that are complete or absent: written under a temporary name beside the final one, then
// renamed into place.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace pixelgym::trainer {

/// The prefix of every temporary file write_file_atomically creates in a folder: the final name
/// is `{folder}/{name}`, the temporary one `{folder}/.{name}.tmp.{pid}.{counter}`. Such files are
/// what a process killed mid-write leaves behind; nothing reads them.
std::string temporary_file_prefix(const std::string& final_name);

/// Writes the concatenation of `pieces` to `path` atomically: to a new temporary file in the same
/// folder (see temporary_file_prefix), checking every write, then fsync of the file, close, rename
/// onto `path` and fsync of the folder, so that `path` names either its previous content or all
/// of the new bytes, even when the process is killed at any point (after a crash of the machine,
/// too, on file systems that honour fsync). On failure the temporary file is removed and `path`
/// is untouched. The folder must exist. Throws std::runtime_error "{what}: cannot write {path}:
/// {reason}" with the OS error ("No space left on device", "Read-only file system", ...).
void write_file_atomically(const std::filesystem::path& path,
                           const std::vector<std::string_view>& pieces, const std::string& what);

/// Reads the whole of a regular file. Throws std::runtime_error "{what}: cannot read {path}:
/// {reason}".
std::string read_whole_file(const std::filesystem::path& path, const std::string& what);

}  // namespace pixelgym::trainer
