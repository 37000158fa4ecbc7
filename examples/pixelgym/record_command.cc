// pixelgym record: episodes of a seeded policy written to .mp4 clips by RecordVideo.
#include <algorithm>
#include <charconv>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "examples/pixelgym/cli.h"
#include "pixelgym/envs/rollout.h"
#include "pixelgym/wrappers/record_video.h"

namespace pixelgym::cli {
namespace {

namespace fs = std::filesystem;

struct RecordArguments : EnvArguments {
  std::uint64_t seed = 0;
  int episodes = 1;
  std::string out;
  std::string policy = "random";
  bool overwrite = false;
};

void declare_record(CLI::App& record, RecordArguments& args) {
  record.description(
      "Run a seeded policy for some episodes and write each as an H.264 .mp4 of render() frames "
      "(RecordVideo); print each file with its frame count and return");
  add_id_argument(record, args.id, "CartPoleSwingup-v1");
  record
      .add_option("--out", args.out,
                  "Folder for one FOLDER/ID-episode-N.mp4 per episode (created if missing), or a "
                  "FILE.mp4 for a single episode. Each file is complete or absent: written under "
                  "a temporary name, checked and renamed. Clips already there are not replaced "
                  "unless --overwrite is given")
      ->required()
      ->type_name("FOLDER|FILE.mp4");
  add_checked_option(record, "--episodes", args.episodes, "Episodes to record, one clip each",
                     integer_in(1));
  add_seed_option(record, args.seed,
                  "Seed for the first reset and the policy's actions (later episodes continue "
                  "the env's generator)");
  add_checked_option(record, "--policy", args.policy,
                     "Policy choosing the actions: random (uniform over the action space)",
                     CLI::IsMember({"random"}));
  record.add_flag("--overwrite", args.overwrite,
                  "Replace the clips of this run that exist already (FOLDER/ID-episode-N.mp4 for "
                  "N below --episodes, or FILE.mp4); without it, record refuses them before any "
                  "episode runs (exit 2) and leaves every file as it was");
  add_env_options(record, args);
}

// The env that is recorded, before RecordVideo wraps it: every option that shapes the env is
// applied here and only here.
std::unique_ptr<Env> make_recorded_env(const std::string& id, const std::vector<std::string>& sets,
                                       const std::vector<std::string>& wraps) {
  return make_env(id, sets, wraps);
}

bool is_mp4_file(const std::string& out) { return fs::path(out).extension() == ".mp4"; }

// Whether something (a file, a folder, a link, even a dangling one) has the name `path`.
bool name_taken(const fs::path& path) {
  std::error_code error;
  return fs::exists(fs::symlink_status(path, error));
}

// The clips "{id}-episode-{N}.mp4" for N below `episodes` that `folder` holds already, by episode.
std::vector<std::string> existing_clips(const fs::path& folder, const std::string& id,
                                        int episodes) {
  std::vector<std::pair<long long, std::string>> found;
  const std::string prefix = id + "-episode-";
  const std::string suffix = ".mp4";
  std::error_code error;
  // Listed rather than probed one name per episode: --episodes may be in the millions.
  for (fs::directory_iterator entry(folder, error), end; !error && entry != end;
       entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    if (name.size() <= prefix.size() + suffix.size() ||
        name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    const std::string number =
        name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    long long episode = 0;
    const auto [stop, parse_error] =
        std::from_chars(number.data(), number.data() + number.size(), episode);
    if (parse_error == std::errc() && stop == number.data() + number.size() &&
        std::to_string(episode) == number && episode < episodes) {
      found.emplace_back(episode, name);
    }
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> names;
  for (auto& clip : found) names.push_back(std::move(clip.second));
  return names;
}

// Refuses, before any work, to replace clips that exist already unless --overwrite was given.
void check_no_overwrite(const RecordArguments& args, bool one_file) {
  if (args.overwrite) return;
  if (one_file) {
    if (name_taken(args.out)) {
      throw UsageError("--out " + args.out +
                       " exists already; pass --overwrite to replace it, or name another file");
    }
    return;
  }
  const std::vector<std::string> names = existing_clips(args.out, args.id, args.episodes);
  if (names.empty()) return;
  constexpr std::size_t kNamed = 5;
  std::string listed;
  for (std::size_t i = 0; i < names.size() && i < kNamed; ++i) {
    listed += (i == 0 ? "" : ", ") + names[i];
  }
  if (names.size() > kNamed) listed += " and " + std::to_string(names.size() - kNamed) + " more";
  throw UsageError("--out " + args.out + " already holds " + std::to_string(names.size()) +
                   (names.size() == 1 ? " file" : " files") + " that this run would write (" +
                   listed + "); pass --overwrite to replace " +
                   (names.size() == 1 ? "it" : "them") + ", or give another folder");
}

int run_record(const RecordArguments& args) {
  const bool one_file = is_mp4_file(args.out);
  if (one_file && args.episodes != 1) {
    throw UsageError("--out " + args.out + " is one clip, but --episodes is " +
                     std::to_string(args.episodes) +
                     ": give a folder to --out to record several episodes");
  }
  if (one_file && fs::path(args.out).filename() == ".mp4") {
    throw UsageError("--out " + args.out + ": the clip needs a name before .mp4");
  }
  // Before any episode runs: a path that cannot take the clip is found now, not after them.
  if (one_file) check_video_file("--out", args.out);
  check_no_overwrite(args, one_file);
  std::unique_ptr<Env> env = make_recorded_env(args.id, args.sets, args.wraps);
  // A folder: one clip per episode, "{folder}/{id}-episode-{N}.mp4". One file: the clip is
  // started by hand before the first reset, under the file's own name.
  const fs::path folder = one_file ? fs::path(args.out).parent_path() : fs::path(args.out);
  const auto never = [](std::int64_t) { return false; };
  const auto always = [](std::int64_t) { return true; };
  auto recorder = std::make_unique<wrappers::RecordVideo>(
      std::move(env), folder.empty() ? fs::path(".") : folder,
      one_file ? wrappers::EpisodeTrigger(never) : wrappers::EpisodeTrigger(always), nullptr, 0,
      args.id);
  if (one_file) recorder->start_recording(fs::path(args.out).stem().string());

  RandomRollout random(*recorder, args.seed);  // resets: the first clip starts
  for (int episode = 0; episode < args.episodes; ++episode) {
    // The episode's last frame is recorded; the next episode's reset starts the next clip.
    const EpisodeSummary& summary = random.finish_episode(/*reset_when_done=*/false);
    const std::optional<wrappers::VideoClip> clip = recorder->stop_recording();
    if (!clip)
      throw std::runtime_error("record: episode " + std::to_string(episode) + " was not recorded");
    // One file is shown as it was given ("clip.mp4", not "./clip.mp4").
    std::cout << "wrote " << (one_file ? args.out : clip->path.string())
              << " frames=" << clip->frames << " return=" << summary.episode_return << "\n";
  }
  recorder->close();
  return 0;
}

}  // namespace

std::vector<Command> add_record_commands(CLI::App& app) {
  return {add_command(app, "record", declare_record, run_record)};
}

}  // namespace pixelgym::cli
