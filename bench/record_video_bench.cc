// RecordVideo's cost per recorded frame: a step + render() with every frame encoded to an H.264
// .mp4 (the clip finished, read back and renamed inside the timing), against the same step +
// render() without RecordVideo. Medians over repeats.
//
// usage: record_video_bench [ENV_ID [SIZE [FRAMES [REPEATS]]]]
//        defaults: CartPoleSwingup-v0 256 300 5 (obs_mode=state, so render() is the only frame)
// prints: id=... size=WxH frames=N repeats=R codec=avc1 step_render_ms=... recorded_ms=...
//         record_ms_per_frame=... recorded_over_bare=... bytes_per_frame=...
// (milliseconds per frame; record_ms_per_frame = recorded_ms - step_render_ms, RecordVideo's own
// cost: colour conversion, H.264 encoding, and the clip's finish amortized over its frames)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/wrappers/record_video.h"

namespace {

using pixelgym::Env;
using pixelgym::Rng;
using pixelgym::Value;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// One episode's first `frames` frames: reset(0) and render(), then seeded random steps, each
// followed by render() when `render_too` (RecordVideo renders inside its own step). Returns the
// milliseconds taken, or a negative number when the episode ends first.
double run_frames(Env& env, int frames, bool render_too) {
  Rng rng(0);
  const auto start = Clock::now();
  env.reset(std::uint64_t{0});
  if (render_too) env.render();
  for (int i = 1; i < frames; ++i) {
    const auto result = env.step(env.action_space().sample(rng));
    if (render_too) env.render();
    if (result.terminated || result.truncated) return -1.0;
  }
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string id = argc > 1 ? argv[1] : "CartPoleSwingup-v0";
  const int size = argc > 2 ? std::atoi(argv[2]) : 256;
  const int frames = argc > 3 ? std::atoi(argv[3]) : 300;
  const int repeats = argc > 4 ? std::atoi(argv[4]) : 5;
  if (size < 2 || frames < 2 || repeats < 1) {
    std::fprintf(stderr, "usage: %s [ENV_ID [SIZE [FRAMES [REPEATS]]]]\n", argv[0]);
    return 2;
  }
  const pixelgym::Params kwargs = {
      {"obs_mode", "state"}, {"render_width", size}, {"render_height", size}};
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / "pixelgym-record-video-bench";
  std::filesystem::remove_all(folder);

  std::vector<double> render_ms;
  std::vector<double> record_ms;
  std::string codec;
  double bytes_per_frame = 0.0;
  for (int repeat = 0; repeat < repeats; ++repeat) {
    auto bare = pixelgym::make(id, kwargs);
    run_frames(*bare, 20, true);  // warm up: GL context, shaders, caches
    const double bare_ms = run_frames(*bare, frames, true);

    auto inner = pixelgym::make(id, kwargs);
    run_frames(*inner, 20, true);
    pixelgym::wrappers::RecordVideo recorded(std::move(inner), folder,
                                             [](std::int64_t) { return true; });
    const auto start = Clock::now();
    const double steps_ms = run_frames(recorded, frames, false);
    const auto clip = recorded.stop_recording();  // encoder flushed, read back, renamed
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    if (bare_ms < 0 || steps_ms < 0) {
      std::fprintf(stderr, "record_video_bench: %s's episode is shorter than %d frames\n",
                   id.c_str(), frames);
      return 1;
    }
    if (!clip || clip->frames != frames) {
      std::fprintf(stderr, "record_video_bench: the clip was not written\n");
      return 1;
    }
    render_ms.push_back(bare_ms / frames);
    record_ms.push_back(ms / frames);
    codec = clip->codec;
    bytes_per_frame = static_cast<double>(std::filesystem::file_size(clip->path)) / frames;
    std::filesystem::remove(clip->path);
  }
  std::filesystem::remove_all(folder);

  const double render = median(render_ms);
  const double record = median(record_ms);
  std::printf(
      "id=%s size=%dx%d frames=%d repeats=%d codec=%s step_render_ms=%.3f recorded_ms=%.3f "
      "record_ms_per_frame=%.3f recorded_over_bare=%.2f bytes_per_frame=%.0f\n",
      id.c_str(), size, size, frames, repeats, codec.c_str(), render, record, record - render,
      record / render, bytes_per_frame);
  return 0;
}
