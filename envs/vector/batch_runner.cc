#include "pixelgym/envs/vector/batch_runner.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <utility>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/batch_space.h"

namespace pixelgym::vector {
namespace {

bool row_set(const Array& flags, int i) { return flags.data<bool>()[i]; }

// Adds env `i`'s `info` to the batched `infos` (Gymnasium's VectorEnv._add_info): each key an
// array with a leading `n` axis, zero where no env reported it, beside a "_key" bool mask.
void add_info(ValueDict& infos, const Info& info, int i, int n) {
  for (std::size_t k = 0; k < info.size(); ++k) {
    const std::string& key = info.keys()[k];
    const Value& value = info.values()[k];
    if (value.is_dict()) {
      if (!infos.contains(key)) infos.insert(key, ValueDict{});
      add_info(infos.at(key).dict(), value.dict(), i, n);
    } else if (value.is_array()) {
      const Array& entry = value.array();
      Shape shape{n};
      shape.insert(shape.end(), entry.shape().begin(), entry.shape().end());
      if (!infos.contains(key)) infos.insert(key, Array(entry.dtype(), shape));
      Array& batch = infos.at(key).array();
      if (batch.dtype() != entry.dtype() || batch.shape() != shape) {
        throw std::invalid_argument("info \"" + key + "\" of env " + std::to_string(i) + " is " +
                                    dtype_name(entry.dtype()) + " " +
                                    shape_to_string(entry.shape()) + ", another env's is " +
                                    batch.to_string());
      }
      batch.index(i).copy_from(entry);
    } else {
      throw std::invalid_argument("info \"" + key + "\" of env " + std::to_string(i) +
                                  ": a Tuple cannot be batched");
    }
    const std::string mask_key = "_" + key;
    if (!infos.contains(mask_key)) infos.insert(mask_key, Array(DType::kBool, {n}));
    infos.at(mask_key).array().data<bool>()[i] = true;
  }
}

// Rethrows `error` as the same standard type with `prefix` before its message.
[[noreturn]] void rethrow_with_context(const std::exception_ptr& error, const std::string& prefix) {
  try {
    std::rethrow_exception(error);
  } catch (const ResetNeeded& e) {
    throw ResetNeeded(prefix + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(prefix + e.what());
  } catch (const std::out_of_range& e) {
    throw std::out_of_range(prefix + e.what());
  } catch (const std::exception& e) {
    throw std::runtime_error(prefix + e.what());
  } catch (...) {
    throw std::runtime_error(prefix + "an exception of unknown type");
  }
}

}  // namespace

void check_reset_mask(const VectorEnv& envs, const Array& reset_mask, bool failed) {
  const int n = envs.num_envs();
  if (reset_mask.dtype() != DType::kBool || reset_mask.shape() != Shape{n}) {
    throw std::invalid_argument(envs.name() + ": reset() reset_mask must be bool (" +
                                std::to_string(n) + ",), got " + reset_mask.to_string());
  }
  const bool* mask = reset_mask.data<bool>();
  if (std::none_of(mask, mask + n, [](bool b) { return b; })) {
    throw std::invalid_argument(envs.name() + ": reset() reset_mask must have a true entry, got " +
                                reset_mask.to_string());
  }
  if (failed) {
    throw ResetNeeded(envs.name() +
                      ": reset() with a mask after a failed call; call reset() without a mask");
  }
}

void check_actions(const VectorEnv& envs, const Value& actions, const char* method) {
  const std::string reason = envs.action_space().layout_mismatch(actions);
  if (!reason.empty()) {
    throw std::invalid_argument(envs.name() + ": " + method + " actions must be laid out as " +
                                envs.action_space().to_string() + ", got " + actions.to_string() +
                                ": " + reason);
  }
}

void check_none_ended(const VectorEnv& envs, const std::vector<std::uint8_t>& ended,
                      const char* method) {
  if (envs.autoreset_mode() != AutoresetMode::kDisabled) return;
  for (std::size_t i = 0; i < ended.size(); ++i) {
    if (ended[i] == 0) continue;
    throw ResetNeeded(envs.name() + ": " + method + " env " + std::to_string(i) +
                      "'s episode ended at the previous step and autoreset is Disabled; reset "
                      "it first with reset(seed, options, reset_mask)");
  }
}

BatchRunner::BatchRunner(std::string type_name, int num_envs, AutoresetMode autoreset)
    : type_name_(std::move(type_name)), num_envs_(num_envs) {
  if (num_envs < 1) {
    throw std::invalid_argument(
        type_name_ + ": num_envs must be >= 1, got num_envs = " + std::to_string(num_envs));
  }
  metadata_.autoreset_mode = autoreset;
}

BatchRunner::~BatchRunner() = default;

std::string BatchRunner::name() const {
  std::string id;
  if (!envs_.empty() && envs_[0] != nullptr && envs_[0]->spec() != nullptr) {
    id = envs_[0]->spec()->id + ", ";
  }
  return type_name_ + "(" + id + "num_envs=" + std::to_string(num_envs_) + ")";
}

const Env& BatchRunner::env(int i) const {
  if (i < 0 || i >= num_envs_ || envs_[static_cast<std::size_t>(i)] == nullptr) {
    throw std::out_of_range(name() + ": no env " + std::to_string(i));
  }
  return *envs_[static_cast<std::size_t>(i)];
}

std::vector<Array> BatchRunner::render() {
  require_usable("render()");
  std::vector<Array> frames;
  frames.reserve(envs_.size());
  for (const std::unique_ptr<Env>& env : envs_) frames.push_back(env->render());
  return frames;
}

const Space& BatchRunner::single_observation_space() const { return envs_[0]->observation_space(); }
const Space& BatchRunner::single_action_space() const { return envs_[0]->action_space(); }

void BatchRunner::build(const EnvFactory& make_env, const BatchBuffers* buffers) {
  const auto n = static_cast<std::size_t>(num_envs_);
  envs_.resize(n);
  errors_.assign(n, nullptr);
  make_env_ = &make_env;
  run_phase(Phase::kBuild);
  make_env_ = nullptr;
  try {
    throw_first_error(false);
    for (std::size_t i = 0; i < n; ++i) {
      if (envs_[i] == nullptr) {
        throw std::invalid_argument(type_name_ + ": the factory returned no env for env " +
                                    std::to_string(i));
      }
    }
    const Env& first = *envs_[0];
    for (std::size_t i = 1; i < n; ++i) {
      const Env& other = *envs_[i];
      if (!other.observation_space().equals(first.observation_space()) ||
          !other.action_space().equals(first.action_space())) {
        throw std::invalid_argument(
            type_name_ + ": env " + std::to_string(i) +
            "'s spaces differ from env 0's: " + other.observation_space().to_string() + " / " +
            other.action_space().to_string() + " against " + first.observation_space().to_string() +
            " / " + first.action_space().to_string());
      }
    }
    observation_space_ = batch_space(first.observation_space(), num_envs_);
    action_space_ = batch_space(first.action_space(), num_envs_);
    if (buffers != nullptr) check_buffers(*buffers);
  } catch (...) {
    destroy_envs();
    throw;
  }
  const AutoresetMode mode = metadata_.autoreset_mode;
  static_cast<Metadata&>(metadata_) = envs_[0]->metadata();
  metadata_.autoreset_mode = mode;

  if (buffers != nullptr) {
    step_result_.obs = buffers->obs;
    step_result_.rewards = buffers->rewards;
    step_result_.terminated = buffers->terminated;
    step_result_.truncated = buffers->truncated;
  } else {
    step_result_.obs = observation_space_->zeros();
    step_result_.rewards = Array(DType::kFloat64, {num_envs_});
    step_result_.terminated = Array(DType::kBool, {num_envs_});
    step_result_.truncated = Array(DType::kBool, {num_envs_});
  }
  const Value obs = step_result_.obs;
  reset_result_.obs = obs;
  actions_ = action_space_->zeros();
  if (metadata_.autoreset_mode == AutoresetMode::kSameStep)
    final_obs_ = observation_space_->zeros();
  env_resets_.resize(n);
  env_steps_.resize(n);
  final_infos_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto index = static_cast<std::int64_t>(i);
    action_slots_.push_back(batch_slot(actions_, index));
    env_resets_[i].obs = batch_slot(obs, index);
    env_steps_[i].obs = env_resets_[i].obs;
    if (metadata_.autoreset_mode == AutoresetMode::kSameStep) {
      final_obs_slots_.push_back(batch_slot(final_obs_, index));
    }
  }
  env_infos_.assign(n, nullptr);
  autoreset_.assign(n, 0);
  final_.assign(n, 0);
}

void BatchRunner::check_buffers(const BatchBuffers& buffers) const {
  const std::string reason = observation_space_->layout_mismatch(buffers.obs);
  const Shape rows{num_envs_};
  const auto fits = [&rows](const Array& array, DType dtype) {
    return array.dtype() == dtype && array.shape() == rows;
  };
  if (!reason.empty() || !fits(buffers.rewards, DType::kFloat64) ||
      !fits(buffers.terminated, DType::kBool) || !fits(buffers.truncated, DType::kBool)) {
    throw std::invalid_argument(
        name() + ": the buffers given must be laid out as " + observation_space_->to_string() +
        " and float64 / bool / bool (" + std::to_string(num_envs_) + ",), got " +
        buffers.obs.to_string() + ", " + buffers.rewards.to_string() + ", " +
        buffers.terminated.to_string() + ", " + buffers.truncated.to_string() +
        (reason.empty() ? "" : ": " + reason));
  }
}

void BatchRunner::destroy_envs() noexcept {
  if (envs_.empty()) return;
  run_phase(Phase::kDestroy);
  for (auto& error : errors_) error = nullptr;
}

void BatchRunner::run_all() {
  start_all();
  wait_all();
}

void BatchRunner::run_phase(Phase phase) {
  phase_ = phase;
  run_all();
}

void BatchRunner::run_env(int i) noexcept {
  const auto index = static_cast<std::size_t>(i);
  try {
    switch (phase_) {
      case Phase::kBuild:
        envs_[index] = (*make_env_)(i);
        break;
      case Phase::kReset: {
        env_infos_[index] = nullptr;
        if (reset_mask_ != nullptr && !row_set(*reset_mask_, i)) break;
        std::optional<std::uint64_t> seed;
        if (seed_) seed = *seed_ + static_cast<std::uint64_t>(i);
        envs_[index]->reset_into(env_resets_[index], seed, *options_);
        env_infos_[index] = &env_resets_[index].info;
        autoreset_[index] = 0;
        break;
      }
      case Phase::kStep:
        step_env(i);
        break;
      case Phase::kClose:
        if (envs_[index] != nullptr) envs_[index]->close();
        break;
      case Phase::kDestroy:
        envs_[index].reset();
        break;
    }
  } catch (...) {
    errors_[index] = std::current_exception();
  }
}

void BatchRunner::step_env(int i) {
  const auto index = static_cast<std::size_t>(i);
  Env& env = *envs_[index];
  StepResult& out = env_steps_[index];
  env_infos_[index] = nullptr;
  final_[index] = 0;
  bool& terminated = step_result_.terminated.data<bool>()[i];
  bool& truncated = step_result_.truncated.data<bool>()[i];
  double& reward = step_result_.rewards.data<double>()[i];
  // Should the env throw, the flags say nothing ended.
  terminated = false;
  truncated = false;
  reward = 0.0;
  if (metadata_.autoreset_mode == AutoresetMode::kNextStep && autoreset_[index] != 0) {
    env.reset_into(env_resets_[index]);
    autoreset_[index] = 0;
    env_infos_[index] = &env_resets_[index].info;
    return;
  }
  env.step_into(action_slots_[index], out);
  reward = out.reward;
  terminated = out.terminated;
  truncated = out.truncated;
  const bool done = out.terminated || out.truncated;
  if (done && metadata_.autoreset_mode == AutoresetMode::kSameStep) {
    copy_value(out.obs, final_obs_slots_[index]);
    std::swap(final_infos_[index], out.info);
    final_[index] = 1;
    env.reset_into(env_resets_[index]);
    env_infos_[index] = &env_resets_[index].info;
    return;
  }
  autoreset_[index] = done ? 1 : 0;
  env_infos_[index] = &out.info;
}

void BatchRunner::throw_first_error(bool poison) {
  for (std::size_t i = 0; i < errors_.size(); ++i) {
    if (errors_[i] == nullptr) continue;
    const std::exception_ptr error = errors_[i];
    for (auto& other : errors_) other = nullptr;
    if (poison) failed_ = true;
    std::string env_name = envs_[i] != nullptr ? envs_[i]->name() : "not built";
    rethrow_with_context(error, name() + ": " + env_context(static_cast<int>(i), env_name) + ": ");
  }
}

std::string BatchRunner::env_context(int i, const std::string& env_name) const {
  return "env " + std::to_string(i) + " (" + env_name + ")";
}

void BatchRunner::require_usable(const char* method) const {
  if (closed_) throw ResetNeeded(name() + ": " + method + " called after close()");
  if (step_pending_) {
    throw ResetNeeded(name() + ": " + method +
                      " called while a step_async() is pending; call step_wait() first");
  }
}

const VectorResetResult& BatchRunner::do_reset(std::optional<std::uint64_t> seed,
                                               const Options& options, const Array* reset_mask) {
  if (reset_mask != nullptr) check_reset_mask(*this, *reset_mask, failed_);
  require_usable("reset()");
  seed_ = seed;
  options_ = &options;
  reset_mask_ = reset_mask;
  run_phase(Phase::kReset);
  options_ = nullptr;
  reset_mask_ = nullptr;
  throw_first_error(true);
  if (reset_mask == nullptr) {
    failed_ = false;
    has_reset_ = true;
  }
  for (int i = 0; i < num_envs_; ++i) {
    if (env_infos_[static_cast<std::size_t>(i)] == nullptr) continue;
    step_result_.terminated.data<bool>()[i] = false;
    step_result_.truncated.data<bool>()[i] = false;
  }
  final_.assign(final_.size(), 0);
  batch_infos(reset_result_.infos, false);
  return reset_result_;
}

const VectorStepResult& BatchRunner::do_step(const Value& actions) {
  begin_step(actions, "step()", true);
  return end_step("step()");
}

void BatchRunner::begin_step(const Value& actions, const char* method, bool wait) {
  require_usable(method);
  if (failed_) {
    throw ResetNeeded(name() + ": " + method + " after a failed call; call reset() first");
  }
  if (!has_reset_) throw ResetNeeded(name() + ": " + method + " called before reset()");
  check_actions(*this, actions, method);
  check_none_ended(*this, autoreset_, method);
  copy_value(actions, actions_);
  phase_ = Phase::kStep;
  step_pending_ = true;
  if (wait) {
    run_all();
    finished_ = true;
  } else {
    start_all();
  }
}

const VectorStepResult& BatchRunner::end_step(const char* method) {
  if (closed_) throw ResetNeeded(name() + ": " + method + " called after close()");
  if (!step_pending_) {
    throw ResetNeeded(name() + ": " + method + " called without a pending step_async()");
  }
  if (!finished_) wait_all();
  finished_ = false;
  step_pending_ = false;
  throw_first_error(true);
  const bool any_final = std::any_of(final_.begin(), final_.end(), [](auto f) { return f != 0; });
  if (any_final) {
    for (std::size_t i = 0; i < final_.size(); ++i) {
      if (final_[i] == 0) zero_value(final_obs_slots_[i]);
    }
  }
  batch_infos(step_result_.infos, any_final);
  return step_result_;
}

void BatchRunner::batch_infos(Info& infos, bool any_final) {
  infos.clear();
  const bool any_info = std::any_of(env_infos_.begin(), env_infos_.end(), [](const Info* info) {
    return info != nullptr && !info->empty();
  });
  if (!any_info && !any_final) return;
  try {
    for (int i = 0; i < num_envs_; ++i) {
      const auto index = static_cast<std::size_t>(i);
      if (final_[index] != 0) {
        if (!infos.contains("final_obs")) {
          infos.insert("final_obs", final_obs_);
          infos.insert("_final_obs", Array(DType::kBool, {num_envs_}));
          infos.insert("final_info", ValueDict{});
          infos.insert("_final_info", Array(DType::kBool, {num_envs_}));
        }
        infos.at("_final_obs").array().data<bool>()[i] = true;
        infos.at("_final_info").array().data<bool>()[i] = true;
        add_info(infos.at("final_info").dict(), final_infos_[index], i, num_envs_);
      }
      if (env_infos_[index] != nullptr) add_info(infos, *env_infos_[index], i, num_envs_);
    }
  } catch (const std::invalid_argument& e) {
    failed_ = true;
    throw std::invalid_argument(name() + ": " + e.what());
  }
}

void BatchRunner::close() {
  if (closed_) return;
  if (step_pending_) {
    wait_all();
    step_pending_ = false;
  }
  closed_ = true;
  run_phase(Phase::kClose);
  throw_first_error(false);
}

}  // namespace pixelgym::vector
