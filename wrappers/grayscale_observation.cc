#include "pixelgym/wrappers/grayscale_observation.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

namespace pixelgym::wrappers {

GrayscaleObservation::GrayscaleObservation(std::unique_ptr<Env> env, bool keep_dim,
                                           const std::string& key)
    : ObservationWrapper(std::move(env)), keep_dim_(keep_dim) {
  const Space& inner = env_->observation_space();
  image_ = find_image(inner, key, "GrayscaleObservation", ImageRequirement{{3}});
  Shape shape = {image_.height(), image_.width()};
  if (keep_dim) shape.push_back(1);
  set_observation_space(replace_image(inner, image_, uint8_image_space(std::move(shape))));
}

void GrayscaleObservation::observation(const Value& in, Value& out) {
  const Array& rgb = image_of(in, image_);
  Array& gray = image_of(out, image_);
  const int height = static_cast<int>(image_.height());
  const int width = static_cast<int>(image_.width());
  const cv::Mat source(height, width, CV_8UC3, const_cast<void*>(rgb.raw_data()));
  cv::Mat target(height, width, CV_8UC1, gray.raw_data());
  const void* const memory = target.data;
  cv::cvtColor(source, target, cv::COLOR_RGB2GRAY);
  if (target.data != memory) {
    throw std::runtime_error("GrayscaleObservation: cv::cvtColor reallocated its target");
  }
  copy_other_entries(in, out, image_);
}

}  // namespace pixelgym::wrappers
