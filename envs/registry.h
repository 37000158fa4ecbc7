// Registry: env ids to factories — make(), register_env(), registered_ids() (gymnasium.make).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/params.h"
#include "pixelgym/envs/render_resources.h"

namespace pixelgym {

/// What an env made with some kwargs offers, known without making it: no Bullet world and no GL
/// context are built to answer (`pixelgym info` prints it).
struct EnvDescription {
  /// The spaces of the env as `make` returns it (TimeLimit changes neither).
  SpacePtr observation_space;
  SpacePtr action_space;
  /// The step at which `make` truncates (TimeLimit), in env steps; std::nullopt for no limit.
  std::optional<std::int64_t> max_episode_steps;
  /// The camera names a pixel task accepts as its "camera" kwarg, default first; empty otherwise.
  std::vector<std::string> cameras;
  /// The env's metadata (render modes, render_fps, render_shape).
  Metadata metadata;
};

/// How to make one registered env.
struct EnvSpec {
  /// "Name-vN": changing a task's dynamics, reward or observation bumps N.
  std::string id;
  /// One line for `pixelgym list`.
  std::string description;
  /// The kwargs the env accepts, with types, defaults and docs (its Config's fields).
  std::vector<ParamSpec> params;
  /// When set, `make` wraps the env in TimeLimit with this many steps (with default kwargs;
  /// `describe` may give another limit for other kwargs, e.g. a pixel task's action_repeat).
  /// On the spec of an env that `make` returned: the limit that env truncates at.
  std::optional<std::int64_t> max_episode_steps;
  /// On the spec of an env that `make` returned: the kwargs it was made with, resolved (every
  /// declared key present, max_episode_steps excluded). Empty in the registry.
  Params kwargs;
  /// Builds the env from kwargs already resolved against `params` (every key present, typed),
  /// with the resources `options` shares (MakeOptions::render null: its own).
  std::function<std::unique_ptr<Env>(const Params& kwargs, const MakeOptions& options)> factory;
  /// Optional: what the envs that one thread steps share to render (see RenderResources), for
  /// worker thread `worker` of a vector env (make_vec: its envs draw with copy `worker` of Mesa),
  /// their GL contexts shared when `share_contexts`. Unset for envs that share nothing.
  std::function<std::shared_ptr<RenderResources>(int worker, bool share_contexts)>
      make_render_resources;
  /// Describes the env `factory` would build from the same kwargs without building it. Optional:
  /// when unset, Registry::describe builds the env to read its spaces.
  std::function<EnvDescription(const Params& kwargs)> describe;
};

/// A set of env specs. The process-wide default one (used by the free functions below) holds
/// the built-in envs; tests build their own. Thread-safe.
class Registry {
 public:
  /// Adds `spec`. Throws std::invalid_argument for an id not of the form Name-vN, an id already
  /// registered, a missing factory, a param named "max_episode_steps" (reserved for make), or a
  /// max_episode_steps that is set and not positive.
  void register_env(EnvSpec spec);

  /// Builds env `id` with `kwargs`, wrapped in TimeLimit when the spec (or the reserved kwarg
  /// "max_episode_steps", 0 for no limit) sets a limit. Throws std::invalid_argument for an
  /// unknown id (naming the closest registered ids, or all of them when none is close), an
  /// unknown kwarg (listing the valid ones with types and defaults), a kwarg of the wrong type or
  /// a negative max_episode_steps; std::runtime_error when the factory returns null; and what the
  /// factory throws. `options` are passed to the factory (see MakeOptions).
  std::unique_ptr<Env> make(const std::string& id, const Params& kwargs = {},
                            const MakeOptions& options = {}) const;

  /// What `make(id, kwargs)` would return — spaces, time limit, cameras, metadata — computed
  /// from the spec alone when it has a `describe` (no world, no GL context). Throws like `make`.
  EnvDescription describe(const std::string& id, const Params& kwargs = {}) const;

  /// The spec registered as `id`; throws like `make` for an unknown id.
  std::shared_ptr<const EnvSpec> spec(const std::string& id) const;

  /// Env `id`'s kwargs from KEY=VALUE text (the command line's `--set`; the "set" of a run
  /// config written before kwargs were kept typed), each value read as the type `id` declares
  /// for its key (parse_param; max_episode_steps an int; an undeclared key a string, which make
  /// then refuses, listing the valid keys). A later entry for a key replaces an earlier one.
  /// Throws std::invalid_argument for an unknown id (as `make`), an entry that is not
  /// key=value, spaces around a key or around a value that is not a string, or a value that
  /// does not read as its type, naming the entry.
  Params parse_kwargs(const std::string& id, const std::vector<std::string>& entries) const;

  /// Every registered id, sorted.
  std::vector<std::string> registered_ids() const;

  /// Up to `count` registered ids within a typo's edit distance of `id` (at most a third of its
  /// length, at least 2; case-insensitive), closest first. An unknown id with none of these gets
  /// the list of every registered id in its error instead.
  std::vector<std::string> closest_ids(const std::string& id, std::size_t count = 3) const;

 private:
  /// The spec, the kwargs resolved against it, and the time limit they give (0: none).
  struct Resolved {
    std::shared_ptr<const EnvSpec> spec;
    Params kwargs;
    std::int64_t max_episode_steps = 0;
  };
  Resolved resolve(const std::string& id, const Params& kwargs) const;

  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<const EnvSpec>> specs_;
};

// The process-wide registry, holding the built-in envs, and the free functions over it. They are
// defined in pixelgym::tasks (envs/tasks/builtin.cc), the library of the built-in envs: link it to
// use them. A program of its own envs alone can keep to pixelgym::envs with a Registry of its
// own.

/// The process-wide registry, holding the built-in envs.
Registry& default_registry();

/// `default_registry().make(id, kwargs, options)`.
std::unique_ptr<Env> make(const std::string& id, const Params& kwargs = {},
                          const MakeOptions& options = {});
/// `default_registry().describe(id, kwargs)`.
EnvDescription describe(const std::string& id, const Params& kwargs = {});
/// `default_registry().register_env(spec)`.
void register_env(EnvSpec spec);
/// `default_registry().registered_ids()`.
std::vector<std::string> registered_ids();
/// `default_registry().parse_kwargs(id, entries)`.
Params parse_kwargs(const std::string& id, const std::vector<std::string>& entries);

}  // namespace pixelgym
