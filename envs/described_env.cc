#include "pixelgym/envs/described_env.h"

#include <stdexcept>
#include <utility>

namespace pixelgym {
namespace {

[[noreturn]] void refuse() {
  throw std::logic_error("DescribedEnv: the stand-in env only describes spaces");
}

}  // namespace

DescribedEnv::DescribedEnv(EnvDescription description) : description_(std::move(description)) {}

void DescribedEnv::do_reset(std::optional<std::uint64_t> /*seed*/, const Options& /*options*/,
                            ResetResult& /*out*/) {
  refuse();
}

void DescribedEnv::do_step(const Value& /*action*/, StepResult& /*out*/) { refuse(); }

Array DescribedEnv::do_render() { refuse(); }

}  // namespace pixelgym
