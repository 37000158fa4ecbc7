// pixelgym record: episodes of a seeded policy written to .mp4 clips by RecordVideo.
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "envs/rollout.h"
#include "examples/pixelgym/cli.h"
#include "wrappers/record_video.h"

namespace pixelgym::cli {
namespace {

namespace fs = std::filesystem;

struct RecordArguments : EnvArguments {
  std::uint64_t seed = 0;
  int episodes = 1;
  std::string out;
  std::string policy = "random";
};

void declare_record(CLI::App& record, RecordArguments& args) {
  record.description(
      "Run a seeded policy for some episodes and write each as an H.264 .mp4 of render() frames "
      "(RecordVideo); print each file with its frame count and return");
  add_id_argument(record, args.id, "CartPoleSwingup-v0");
  record
      .add_option("--out", args.out,
                  "Folder for one FOLDER/ID-episode-N.mp4 per episode (created if missing), or a "
                  "FILE.mp4 for a single episode. Each file is complete or absent: written under "
                  "a temporary name, checked and renamed")
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
  add_env_options(record, args);
}

// The env that is recorded, before RecordVideo wraps it: every option that shapes the env is
// applied here and only here.
std::unique_ptr<Env> make_recorded_env(const std::string& id, const std::vector<std::string>& sets,
                                       const std::vector<std::string>& wraps) {
  return make_env(id, sets, wraps);
}

bool is_mp4_file(const std::string& out) { return fs::path(out).extension() == ".mp4"; }

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
