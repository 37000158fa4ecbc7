#include "pixelgym/wrappers/channel_first_observation.h"

#include <cstdint>
#include <utility>

namespace pixelgym::wrappers {

ChannelFirstObservation::ChannelFirstObservation(std::unique_ptr<Env> env, const std::string& key)
    : ObservationWrapper(std::move(env)) {
  const Space& inner = env_->observation_space();
  image_ = find_image(inner, key, "ChannelFirstObservation", ImageRequirement{{1, 3}});
  set_observation_space(replace_image(
      inner, image_, uint8_image_space({image_.channels(), image_.height(), image_.width()})));
}

void ChannelFirstObservation::observation(const Value& in, Value& out) {
  const std::uint8_t* source = image_of(in, image_).data<std::uint8_t>();
  std::uint8_t* target = image_of(out, image_).data<std::uint8_t>();
  const std::int64_t channels = image_.channels();
  const std::int64_t pixels = image_.height() * image_.width();
  for (std::int64_t c = 0; c < channels; ++c) {
    std::uint8_t* plane = target + c * pixels;
    for (std::int64_t p = 0; p < pixels; ++p) plane[p] = source[p * channels + c];
  }
  copy_other_entries(in, out, image_);
}

}  // namespace pixelgym::wrappers
