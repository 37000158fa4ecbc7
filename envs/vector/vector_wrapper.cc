#include "pixelgym/envs/vector/vector_wrapper.h"

#include <stdexcept>
#include <utility>

#include "pixelgym/envs/vector/batch_space.h"

namespace pixelgym::vector {
namespace {

// True when every array of `a` is a view of the same memory, dtype and shape as the matching
// one of `b` (the same structure). Allocates nothing.
bool same_views(const Value& a, const Value& b) {
  if (a.is_array() && b.is_array()) {
    const Array& x = a.array();
    const Array& y = b.array();
    return x.raw_data() == y.raw_data() && x.dtype() == y.dtype() && x.shape() == y.shape();
  }
  if (a.is_dict() && b.is_dict()) {
    const ValueDict& x = a.dict();
    const ValueDict& y = b.dict();
    if (x.keys() != y.keys()) return false;
    for (std::size_t k = 0; k < x.size(); ++k) {
      if (!same_views(x.values()[k], y.values()[k])) return false;
    }
    return true;
  }
  if (a.is_tuple() && b.is_tuple()) {
    const ValueTuple& x = a.tuple();
    const ValueTuple& y = b.tuple();
    if (x.size() != y.size()) return false;
    for (std::size_t k = 0; k < x.size(); ++k) {
      if (!same_views(x.at(k), y.at(k))) return false;
    }
    return true;
  }
  return false;
}

}  // namespace

VectorWrapper::VectorWrapper(std::unique_ptr<VectorEnv> env)
    : owned_(std::move(env)), env_(owned_.get()) {
  if (env_ == nullptr) throw std::invalid_argument("VectorWrapper: the vector env to wrap is null");
}

VectorWrapper::VectorWrapper(VectorEnv& env) : env_(&env) {}

VectorWrapper::~VectorWrapper() = default;

const Space& VectorWrapper::single_observation_space() const {
  if (single_observation_space_ != nullptr) return *single_observation_space_;
  return env_->single_observation_space();
}

const Space& VectorWrapper::observation_space() const {
  if (observation_space_ != nullptr) return *observation_space_;
  return env_->observation_space();
}

std::string VectorWrapper::name() const { return type_name() + "<" + env_->name() + ">"; }

const VectorResetResult& VectorWrapper::do_reset(std::optional<std::uint64_t> seed,
                                                 const Options& options, const Array* reset_mask) {
  return reset_inner(seed, options, reset_mask);
}

const VectorStepResult& VectorWrapper::do_step(const Value& actions) { return step_inner(actions); }

const VectorResetResult& VectorWrapper::reset_inner(std::optional<std::uint64_t> seed,
                                                    const Options& options,
                                                    const Array* reset_mask) {
  return reset_mask != nullptr ? env_->reset(seed, options, *reset_mask)
                               : env_->reset(seed, options);
}

void VectorWrapper::set_single_observation_space(SpacePtr space) {
  observation_space_ = batch_space(*space, num_envs());
  single_observation_space_ = std::move(space);
}

void VectorWrapper::view(const Value& from, Value& to) {
  if (!same_views(from, to)) to = from;
}

void VectorWrapper::view(const Array& from, Array& to) {
  if (from.raw_data() != to.raw_data() || from.dtype() != to.dtype() ||
      from.shape() != to.shape()) {
    to = from;
  }
}

void VectorWrapper::copy_infos(const Info& from, Info& to) {
  if (from.empty()) {
    to.clear();
  } else {
    to = from;
  }
}

void VectorWrapper::forward(const VectorStepResult& inner, VectorStepResult& out) {
  view(inner.obs, out.obs);
  view(inner.rewards, out.rewards);
  view(inner.terminated, out.terminated);
  view(inner.truncated, out.truncated);
  copy_infos(inner.infos, out.infos);
}

}  // namespace pixelgym::vector
