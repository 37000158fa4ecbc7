// The version of the code a run was trained with: the git commit and dirty flag of the source
// tree, as of the build of the binary.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace pixelgym::trainer {

/// A source tree's version. Recorded at build time (code_version.cmake runs on every build, and
/// rewrites a generated source only when the answer changes) rather than at configure time (stale
/// after the next commit) or at run time (it would describe the tree as it is when the binary
/// runs, which may differ from what was compiled). Limitation: edits made after the last build
/// are not in the binary and not in the answer either; uncommitted changes show only as
/// `dirty`, not what they were. Untracked files do not count as dirty.
struct CodeVersion {
  std::string commit;         // 40 hex digits; empty when unknown (see `note`)
  std::optional<bool> dirty;  // tracked files differed from `commit`; nullopt when unknown
  std::string note;           // why the commit is unknown ("not a git checkout: ..."), or empty
};

/// The version of the source tree this binary was built from.
CodeVersion build_code_version();

/// {"commit": "..." or null, "dirty": true/false or null, "recorded": "at build time", "note": ...
/// (only when there is one)}.
nlohmann::json code_version_json(const CodeVersion& version);

}  // namespace pixelgym::trainer
