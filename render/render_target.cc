#include "pixelgym/render/render_target.h"

#include <stdexcept>
#include <string>

#include "pixelgym/render/transforms.h"

namespace pixelgym::render {

void check_framebuffer(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error(std::string("Renderer: ") + what + " framebuffer incomplete (status " +
                             std::to_string(status) + ")");
  }
}

ColorTarget::ColorTarget(int width, int height, int samples, bool resolvable, const char* what)
    : width_(width), height_(height), framebuffer_(make_framebuffer()) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
  color_ = make_renderbuffer(GL_RGBA8, width, height, samples);
  depth_ = make_renderbuffer(GL_DEPTH_COMPONENT24, width, height, samples);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.get());
  check_framebuffer(what);
  if (resolvable && samples > 0) {
    resolve_framebuffer_ = make_framebuffer();
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_framebuffer_.get());
    resolve_color_ = make_renderbuffer(GL_RGBA8, width, height, 0);
    resolve_depth_ = make_renderbuffer(GL_DEPTH_COMPONENT24, width, height, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              resolve_color_.get());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              resolve_depth_.get());
    check_framebuffer("resolve");
  }
}

void ColorTarget::resolve() const {
  if (!resolve_framebuffer_) return;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_framebuffer_.get());
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

SegmentationTarget::SegmentationTarget(int width, int height) : framebuffer_(make_framebuffer()) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
  ids_ = make_renderbuffer(GL_R32I, width, height, 0);
  depth_ = make_renderbuffer(GL_DEPTH_COMPONENT24, width, height, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, ids_.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.get());
  check_framebuffer("segmentation");
}

void read_rgb(int width, int height, std::vector<std::uint8_t>& rgba, std::uint8_t* rgb) {
  // RGBA is the renderbuffer's own layout: reading it and packing RGB here is faster than Mesa's
  // conversion.
  const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  rgba.resize(count * 4);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  const std::uint8_t* source = rgba.data();  // hoisted: stores to `rgb` may alias the vector
  for (std::size_t p = 0; p < count; ++p) {
    rgb[p * 3] = source[p * 4];
    rgb[p * 3 + 1] = source[p * 4 + 1];
    rgb[p * 3 + 2] = source[p * 4 + 2];
  }
}

void read_depth(int width, int height, float near_m, float far_m, float* depth) {
  glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, depth);
  const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  for (std::size_t p = 0; p < count; ++p) depth[p] = eye_depth_from_window(depth[p], near_m, far_m);
}

void read_segmentation(int width, int height, std::int32_t* ids) {
  glReadPixels(0, 0, width, height, GL_RED_INTEGER, GL_INT, ids);
}

}  // namespace pixelgym::render
