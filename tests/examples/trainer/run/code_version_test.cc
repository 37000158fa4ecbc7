#include "pixelgym/trainer/code_version.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/examples/trainer/run/test_folders.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using test_folders::fresh_folder;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;

int run(const std::string& command) { return std::system((command + " >/dev/null 2>&1").c_str()); }

// Runs code_version.cmake on `source` and returns the C++ it generated.
std::string generate(const fs::path& source, const fs::path& output) {
  EXPECT_EQ(run(std::string(PIXELGYM_CMAKE) + " -DSOURCE_DIR=" + source.string() +
                " -DOUTPUT=" + output.string() + " -P " + PIXELGYM_CODE_VERSION_SCRIPT),
            0);
  std::ifstream in(output);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// An empty folder under the system's temporary folder (outside the pixelgym checkout).
fs::path scratch(const std::string& name) {
  const fs::path folder = fs::temp_directory_path() /
                          ("pixelgym_code_version_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

std::string git(const fs::path& repo, const std::string& arguments) {
  return "git -C " + repo.string() + " -c user.name=test -c user.email=test@example.com " +
         arguments;
}

// This binary was built from the pixelgym checkout: a 40-digit commit and a known dirty flag.
TEST(CodeVersionTest, TheBuildRecordsThisCheckoutsCommit) {
  const CodeVersion version = build_code_version();
  EXPECT_THAT(version.commit, MatchesRegex("[0-9a-f]{40}"));
  EXPECT_TRUE(version.dirty.has_value());
  EXPECT_EQ(version.note, "");
  const nlohmann::json json = code_version_json(version);
  EXPECT_EQ(json["commit"], version.commit);
  EXPECT_EQ(json["dirty"], *version.dirty);
  EXPECT_EQ(json["recorded"], "at build time");
  EXPECT_FALSE(json.contains("note"));
}

// A folder outside any repository (an unpacked release tarball, say).
TEST(CodeVersionTest, NotAGitCheckoutIsSaidAndLeavesTheCommitUnknown) {
  const fs::path plain = scratch("plain");
  if (run(git(plain, "rev-parse --show-toplevel")) == 0) {
    GTEST_SKIP() << plain << " is inside a git repository";
  }
  EXPECT_THAT(
      generate(plain, fresh_folder("code_version_plain") / "out.cc"),
      HasSubstr("{\"\", std::nullopt, R\"pgcv(not a git checkout: " + plain.string() + ")pgcv\"}"));
  fs::remove_all(plain);
}

TEST(CodeVersionTest, CleanAndDirtyCheckoutsAndUntrackedFiles) {
  const fs::path repo = scratch("repo");
  ASSERT_EQ(run(git(repo, "init -q")), 0);
  std::ofstream(repo / "a.txt") << "one\n";
  ASSERT_EQ(run(git(repo, "add a.txt")), 0);
  ASSERT_EQ(run(git(repo, "commit -q -m first")), 0);
  const fs::path output = fresh_folder("code_version_repo") / "out.cc";

  // One commit, nothing changed.
  std::string text = generate(repo, output);
  EXPECT_THAT(text,
              MatchesRegex("(.|\n)*\\{\"[0-9a-f]{40}\", false, R\"pgcv\\(\\)pgcv\"\\}(.|\n)*"));
  // An untracked file (a run folder, say) does not make it dirty.
  std::ofstream(repo / "untracked.txt") << "x\n";
  EXPECT_THAT(generate(repo, output), HasSubstr("\", false, R\"pgcv()pgcv\"}"));
  // A modified tracked file does.
  std::ofstream(repo / "a.txt") << "two\n";
  EXPECT_THAT(generate(repo, output), HasSubstr("\", true, R\"pgcv()pgcv\"}"));
  fs::remove_all(repo);
}

TEST(CodeVersionTest, ARepositoryWithoutCommitsIsSaid) {
  const fs::path repo = scratch("empty_repo");
  ASSERT_EQ(run(git(repo, "init -q")), 0);
  EXPECT_THAT(generate(repo, fresh_folder("code_version_empty") / "out.cc"),
              HasSubstr("{\"\", std::nullopt, R\"pgcv(a git checkout without commits: "));
  fs::remove_all(repo);
}

TEST(CodeVersionTest, UnknownVersionIsNullInJson) {
  const nlohmann::json json = code_version_json({"", std::nullopt, "not a git checkout: /x"});
  EXPECT_TRUE(json["commit"].is_null());
  EXPECT_TRUE(json["dirty"].is_null());
  EXPECT_EQ(json["note"], "not a git checkout: /x");
}

}  // namespace
}  // namespace pixelgym::trainer
