// Renderer: draws a Scene from a Camera into RGB, depth and segmentation images.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "render/camera.h"
#include "render/context.h"
#include "render/scene.h"

namespace pixelgym::render {

/// Where `Renderer::render` writes, and the image size the buffers hold: `width` x `height`
/// pixels, row-major with row 0 at the top; it must equal the camera's. Each pointer may be null
/// to skip that output.
struct RenderTargets {
  /// Pixels per row of every buffer.
  int width = 0;
  /// Rows of every buffer.
  int height = 0;
  /// 3 bytes per pixel, RGB.
  std::uint8_t* rgb = nullptr;
  /// Distance along the camera's viewing axis (-z) in metres; camera.far_m where nothing is drawn.
  float* depth = nullptr;
  /// The Instance::segmentation_id of the surface seen; 0 for the sky, -1 for the floor.
  std::int32_t* segmentation = nullptr;
};

/// Turns scenes into pixels with its own OpenGL context. Meshes and textures are uploaded on first
/// use and kept for later frames (keyed by MeshData address, kept alive by the renderer, and by
/// texture path).
///
/// Threading: a Renderer is used by one thread at a time, any thread, one after the other (made,
/// drawn and destroyed on different threads if need be: its context is bound only during each
/// call, see Context); different renderers can draw concurrently in different threads. The same
/// scene and camera give identical bytes on one machine and one Mesa build.
class Renderer {
 public:
  /// Throws std::runtime_error when the GL context cannot be created or the shaders do not build.
  explicit Renderer(GlBackend backend = GlBackend::kOSMesa);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Draws `scene` as seen by `camera` into `targets`. Throws std::invalid_argument for an invalid
  /// camera, targets whose width and height differ from the camera's (naming both), more MSAA
  /// samples than the GL offers, or an instance without a mesh; std::runtime_error for a texture
  /// that cannot be read.
  void render(const Scene& scene, const Camera& camera, const RenderTargets& targets);

  /// The GL implementation in use.
  std::string description();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pixelgym::render
