// Folders for the run-folder tests: fresh ones under the test output folder, their entries, and
// tmpfs mounts that refuse writes (read-only, full) even to root.
#pragma once

#include <sched.h>
#include <sys/mount.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace pixelgym::trainer::test_folders {

/// An empty folder {test output}/trainer_run/{name}, emptied first if it exists.
inline std::filesystem::path fresh_folder(const std::string& name) {
  const std::filesystem::path folder =
      std::filesystem::path(PIXELGYM_TEST_OUTPUT_DIR) / "trainer_run" / name;
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  return folder;
}

/// The names in `folder`, sorted.
inline std::vector<std::string> entries(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// Mounts a tmpfs with `flags` and `options` on a fresh folder, in a mount namespace of this
/// process's own (nothing outlives the test process). Returns an empty path when mounting is not
/// permitted here (the caller skips).
inline std::filesystem::path mount_tmpfs(const std::string& name, unsigned long flags,
                                         const char* options) {
  const std::filesystem::path folder = fresh_folder(name);
  if (::unshare(CLONE_NEWNS) != 0) return {};
  if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) return {};
  if (::mount("tmpfs", folder.c_str(), "tmpfs", flags, options) != 0) return {};
  return folder;
}

}  // namespace pixelgym::trainer::test_folders
