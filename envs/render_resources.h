// RenderResources and MakeOptions: what the owner of several envs creates once and hands each env
// it makes (make's options), instead of anything ambient.
#pragma once

#include <memory>

namespace pixelgym {

/// What the envs that one thread steps share to draw their frames. Whoever owns the envs creates
/// it (make_vec: one per worker thread, from EnvSpec::make_render_resources) and passes it to each
/// env at construction through MakeOptions. The protocol knows nothing of what it holds: a task
/// library derives its own (the pixel tasks: PixelRenderResources, a GL context group in one copy
/// of Mesa). An env given resources of a type it does not draw with throws
/// std::invalid_argument.
class RenderResources {
 public:
  virtual ~RenderResources();
  RenderResources(const RenderResources&) = delete;
  RenderResources& operator=(const RenderResources&) = delete;

 protected:
  RenderResources() = default;
};

/// make's settings beside the env's kwargs: what the caller shares between the envs it makes.
struct MakeOptions {
  /// Null: the env draws with resources of its own (a GL context of its own, for a pixel task).
  std::shared_ptr<RenderResources> render;
};

}  // namespace pixelgym
