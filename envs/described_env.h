// DescribedEnv: a stand-in env with the spaces and metadata of a description, for checking
// wrappers against an env without making it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/registry.h"

namespace pixelgym {

/// An env with the spaces and metadata of `description` (Registry::describe) and nothing else:
/// wrappers read the spaces and metadata of the env they wrap in their constructors, so a wrapper
/// stack built over a DescribedEnv shows the wrapped spaces, or throws as it would over the real
/// env, without a world or a GL context. reset, step and render throw std::logic_error.
class DescribedEnv final : public Env {
 public:
  /// Keeps `description`, whose observation_space and action_space must not be null (not
  /// checked).
  explicit DescribedEnv(EnvDescription description);

  const Space& observation_space() const override { return *description_.observation_space; }
  const Space& action_space() const override { return *description_.action_space; }
  const Metadata& metadata() const override { return description_.metadata; }

 protected:
  std::string type_name() const override { return "DescribedEnv"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;
  Array do_render() override;

 private:
  const EnvDescription description_;
};

}  // namespace pixelgym
