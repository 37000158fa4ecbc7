#include "examples/trainer/torch_common/torch_state.h"

#include <sched.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "pixelgym/trainer/communicator.h"

namespace pixelgym::trainer {

std::string to_blob(const std::function<void(std::ostream&)>& save) {
  std::ostringstream out(std::ios::binary);
  save(out);
  return out.str();
}

const std::string& checkpoint_blob(const LoadedCheckpoint& checkpoint, const std::string& name) {
  const auto found = checkpoint.blobs.find(name);
  if (found == checkpoint.blobs.end()) {
    throw std::runtime_error(checkpoint.path.string() + ": the checkpoint has no \"" + name +
                             "\" entry");
  }
  return found->second;
}

std::string generator_blob(const at::Generator& generator) {
  return save_blob(generator.get_state());
}

void load_generator(const LoadedCheckpoint& checkpoint, const std::string& name,
                    at::Generator& generator) {
  torch::Tensor state;
  load_blob(checkpoint, name, state);
  generator.set_state(state);
}

std::uint64_t parameter_digest(const torch::nn::Module& module) {
  std::uint64_t digest = fnv1a(nullptr, 0);
  const auto add = [&digest](const torch::Tensor& tensor) {
    const torch::Tensor contiguous = tensor.detach().contiguous();
    digest = fnv1a(contiguous.data_ptr(), contiguous.nbytes(), digest);
  };
  for (const torch::Tensor& parameter : module.parameters()) add(parameter);
  for (const torch::Tensor& buffer : module.buffers()) add(buffer);
  return digest;
}

int set_torch_threads(int requested) {
  if (requested == 0 && std::getenv("OMP_NUM_THREADS") != nullptr) return torch::get_num_threads();
  int threads = requested;
  if (threads == 0) {
    cpu_set_t cpus;
    CPU_ZERO(&cpus);
    threads = sched_getaffinity(0, sizeof(cpus), &cpus) == 0 ? CPU_COUNT(&cpus) : 1;
  }
  torch::set_num_threads(std::max(threads, 1));
  return torch::get_num_threads();
}

}  // namespace pixelgym::trainer
