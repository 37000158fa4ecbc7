// Private to render/: framebuffers at an image size — what a frame is drawn into, the MSAA
// resolve, and reading pixels back.
#pragma once

#include <cstdint>
#include <vector>

#include "pixelgym/render/gl.h"
#include "pixelgym/render/gl_object.h"

namespace pixelgym::render {

/// Throws std::runtime_error naming `what` when the bound framebuffer is not complete.
void check_framebuffer(const char* what);

/// RGBA8 colour and 24-bit depth renderbuffers of one size and sample count in a framebuffer,
/// plus, when `resolvable` and multisampled, a single-sampled copy to read from.
class ColorTarget {
 public:
  /// Creates the buffers (a context must be current), leaving a framebuffer bound. `what` names
  /// the target in errors: std::runtime_error when a framebuffer is not complete.
  ColorTarget(int width, int height, int samples, bool resolvable, const char* what);

  /// What is drawn into (multisampled when samples > 0).
  GLuint framebuffer() const { return framebuffer_.get(); }
  /// Copies the drawn colour (averaging samples) and depth (one sample) into the single-sampled
  /// copy when multisampled; nothing otherwise.
  void resolve() const;
  /// The framebuffer to read pixels from after `resolve`.
  GLuint read_framebuffer() const {
    return resolve_framebuffer_ ? resolve_framebuffer_.get() : framebuffer_.get();
  }

 private:
  int width_;
  int height_;
  GlFramebuffer framebuffer_;
  GlRenderbuffer color_;
  GlRenderbuffer depth_;
  GlFramebuffer resolve_framebuffer_;  // empty when single-sampled or not resolvable
  GlRenderbuffer resolve_color_;
  GlRenderbuffer resolve_depth_;
};

/// A 32-bit integer id and a 24-bit depth renderbuffer of one size in a framebuffer.
class SegmentationTarget {
 public:
  /// Creates the buffers (a context must be current), leaving the framebuffer bound. Throws
  /// std::runtime_error when it is not complete.
  SegmentationTarget(int width, int height);
  /// What ids are drawn into.
  GLuint framebuffer() const { return framebuffer_.get(); }

 private:
  GlFramebuffer framebuffer_;
  GlRenderbuffer ids_;
  GlRenderbuffer depth_;
};

/// Reads the bound read framebuffer's colour as RGB, 3 bytes per pixel, into `rgb`; `rgba` is
/// scratch (resized to 4 bytes per pixel, so that later frames of the size allocate nothing).
void read_rgb(int width, int height, std::vector<std::uint8_t>& rgba, std::uint8_t* rgb);

/// Reads the bound read framebuffer's depth as the distance along the viewing axis in metres
/// (`far_m` where nothing was drawn), for a perspective projection with planes `near_m` and
/// `far_m`.
void read_depth(int width, int height, float near_m, float far_m, float* depth);

/// Reads the bound read framebuffer's integer ids into `ids` (width x height values).
void read_segmentation(int width, int height, std::int32_t* ids);

}  // namespace pixelgym::render
