// Wrapper stacks from text: `resize=64x64`, `grayscale`, `frame_stack=4,padding=zero` — the form
// the command line's repeatable `--wrap` and run configs use.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/wrapper.h"

namespace pixelgym::wrappers {

/// One wrapper spec, parsed: `NAME` or `NAME=ARGS`, where ARGS are comma-separated items, each
/// `param=value` or a bare value taken by the wrapper's parameters in their declared order (a
/// bare item that is the name of a boolean parameter sets it to true: `grayscale=keep_dim`).
struct WrapperSpec {
  /// The text as given, for messages.
  std::string text;
  /// The wrapper's name as the spec table lists it ("resize").
  std::string name;
  /// Every argument given, by parameter name, in the order given.
  std::vector<std::pair<std::string, std::string>> arguments;
};

/// Parses `text`; a name may be an alias (WrapperSpecHelp::aliases: "greyscale"), which the
/// result names by the wrapper's name ("grayscale"). Throws std::invalid_argument naming the spec
/// and what is wrong in it: an unknown wrapper (the closest names as "did you mean", then the
/// known ones), an unknown parameter (likewise, the wrapper's), a parameter given twice, more bare
/// values than the wrapper has parameters, a bare number after a size ("resize=64,48": the form
/// HEIGHTxWIDTH is named), an empty item, or a missing required argument. Values are checked when
/// the wrapper is applied.
WrapperSpec parse_wrapper_spec(const std::string& text);

/// Wraps `env` as `spec` says. Throws std::invalid_argument naming the spec, the wrapper, the
/// argument and what it expected when a value does not parse ("size: expected HEIGHTxWIDTH ...,
/// got \"64y64\""), and, prefixed with the spec, what the wrapper's constructor throws (a key that
/// is not an image, a size out of range...).
std::unique_ptr<Env> apply_wrapper(std::unique_ptr<Env> env, const WrapperSpec& spec);

/// Parses each of `specs` and applies them in order: the first wraps `env`, the last is outermost.
/// Throws as parse_wrapper_spec and apply_wrapper do.
std::unique_ptr<Env> apply_wrappers(std::unique_ptr<Env> env,
                                    const std::vector<std::string>& specs);

/// The EnvWrapping of `specs` (what vector::make_vec applies to each env it makes): parses them
/// now, throwing as parse_wrapper_spec, and applies them in order to each env it is given,
/// throwing as apply_wrapper. Empty (null) for no specs.
EnvWrapping wrapping(const std::vector<std::string>& specs);

/// What an env described by `description` (Registry::describe) looks like under `specs`, without
/// making it: the wrappers are built over a stand-in env that has the described spaces and
/// metadata and refuses reset, step and render. The spaces and metadata are the wrapped ones; a
/// `time_limit` spec lowers max_episode_steps to its own when smaller. Throws as apply_wrappers.
EnvDescription describe_wrapped(EnvDescription description, const std::vector<std::string>& specs);

/// One wrapper the text form knows: its name, the form with its parameters, and what it does.
struct WrapperSpecHelp {
  /// The name a spec starts with ("resize").
  std::string name;
  /// The form with its parameters: "resize=HxW[,key=pixels]".
  std::string usage;
  /// The wrapper class and what it does: "ResizeObservation: ...".
  std::string summary;
  /// Other names a spec may start with for this wrapper, the docs' words for it ("greyscale").
  std::vector<std::string> aliases;
};

/// Every wrapper the text form knows, in the order `--help` lists them.
std::vector<WrapperSpecHelp> wrapper_spec_help();

}  // namespace pixelgym::wrappers
